#include "live_frame.h"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/wire_format_lite.h>

namespace scenewatch::service {

namespace {

using google::protobuf::io::CodedInputStream;
using google::protobuf::internal::WireFormatLite;

// Field numbers of scenewatch.proto: Request.id, Request.token, Request.ingest_frame, IngestFrame.live.
constexpr int kRequestId = 1;
constexpr int kRequestToken = 2;
constexpr std::uint32_t kMaxTokenBytes = 1024;
constexpr int kRequestIngestFrame = 12;
constexpr int kIngestFrameLive = 6;

// Reads IngestFrame.live inside the current limit; false on a malformed message.
bool read_live(CodedInputStream& in, bool& live) {
  while (const std::uint32_t tag = in.ReadTag()) {
    if (WireFormatLite::GetTagFieldNumber(tag) == kIngestFrameLive &&
        WireFormatLite::GetTagWireType(tag) == WireFormatLite::WIRETYPE_VARINT) {
      std::uint64_t value = 0;
      if (!in.ReadVarint64(&value)) return false;
      live = value != 0;
    } else if (!WireFormatLite::SkipField(&in, tag)) {
      return false;
    }
  }
  return in.ConsumedEntireMessage();
}

}  // namespace

LiveFramePeek peek_live_frame(std::string_view payload) {
  CodedInputStream in(reinterpret_cast<const std::uint8_t*>(payload.data()), static_cast<int>(payload.size()));
  LiveFramePeek peek;
  bool is_frame = false, live = false;
  while (const std::uint32_t tag = in.ReadTag()) {
    const int field = WireFormatLite::GetTagFieldNumber(tag);
    const auto type = WireFormatLite::GetTagWireType(tag);
    if (field == kRequestId && type == WireFormatLite::WIRETYPE_VARINT) {
      if (!in.ReadVarint64(&peek.id)) return {};
    } else if (field == kRequestToken && type == WireFormatLite::WIRETYPE_LENGTH_DELIMITED) {
      std::uint32_t length = 0;
      if (!in.ReadVarint32(&length) || length > kMaxTokenBytes || !in.ReadString(&peek.token, static_cast<int>(length))) return {};
    } else if (field == kRequestIngestFrame && type == WireFormatLite::WIRETYPE_LENGTH_DELIMITED) {
      std::uint32_t length = 0;
      if (!in.ReadVarint32(&length)) return {};
      const auto limit = in.PushLimit(static_cast<int>(length));
      if (!read_live(in, live)) return {};
      in.PopLimit(limit);
      is_frame = true;
    } else if (!WireFormatLite::SkipField(&in, tag)) {
      return {};
    }
  }
  if (!in.ConsumedEntireMessage()) return {};
  peek.frame = is_frame;
  peek.live = is_frame && live;
  return peek;
}

}  // namespace scenewatch::service
