#include "scenewatch/service/frame_parser.h"

#include <algorithm>
#include <cassert>

namespace scenewatch::service {
namespace {
constexpr std::size_t kInitialReserveBytes = 64 * 1024;
}  // namespace

std::string encode_frame(std::string_view payload) {
  assert(!payload.empty() && payload.size() <= kMaxEncodableFrameBytes);
  const auto n = static_cast<std::uint32_t>(payload.size());
  std::string out;
  out.reserve(kFrameHeaderBytes + payload.size());
  out.push_back(static_cast<char>((n >> 24) & 0xFF));
  out.push_back(static_cast<char>((n >> 16) & 0xFF));
  out.push_back(static_cast<char>((n >> 8) & 0xFF));
  out.push_back(static_cast<char>(n & 0xFF));
  out.append(payload);
  return out;
}

FrameParser::FrameParser(std::size_t max_payload_bytes)
    : max_payload_bytes_(std::max<std::size_t>(1, max_payload_bytes)) {}

Status FrameParser::feed(std::string_view bytes) {
  if (failed_) return invalid_argument("framing already broken; no further data is accepted");
  while (!bytes.empty()) {
    if (header_fill_ < kFrameHeaderBytes) {
      while (header_fill_ < kFrameHeaderBytes && !bytes.empty()) {
        header_[header_fill_++] = static_cast<unsigned char>(bytes.front());
        bytes.remove_prefix(1);
      }
      if (header_fill_ < kFrameHeaderBytes) break;
      const std::uint64_t declared = (std::uint64_t{header_[0]} << 24) | (std::uint64_t{header_[1]} << 16) |
                                     (std::uint64_t{header_[2]} << 8) | std::uint64_t{header_[3]};
      // Checked before anything is reserved for the payload: a hostile length costs nothing.
      if (declared == 0) {
        failed_ = true;
        return invalid_argument("frame declares a length of 0 bytes; a message must not be empty");
      }
      if (declared > max_payload_bytes_) {
        failed_ = true;
        return invalid_argument("frame declares a length of " + std::to_string(declared) +
                                " bytes, above the maximum of " + std::to_string(max_payload_bytes_) +
                                " bytes");
      }
      expected_ = static_cast<std::size_t>(declared);
      payload_.clear();
      // Memory follows the bytes actually received, not the declared length, so a client that
      // announces a large frame and stalls holds little.
      payload_.reserve(std::min<std::size_t>(expected_, kInitialReserveBytes));
    }
    const std::size_t take = std::min(expected_ - payload_.size(), bytes.size());
    payload_.append(bytes.data(), take);
    bytes.remove_prefix(take);
    if (payload_.size() == expected_) {
      ready_.push_back(std::move(payload_));
      payload_ = std::string();
      header_fill_ = 0;
      expected_ = 0;
    }
  }
  return {};
}

std::optional<std::string> FrameParser::next() {
  if (ready_.empty()) return std::nullopt;
  std::string out = std::move(ready_.front());
  ready_.pop_front();
  return out;
}

bool FrameParser::has_partial() const { return !failed_ && header_fill_ > 0; }

}  // namespace scenewatch::service
