#pragma once
/// Length-prefixed framing of the wire protocol: each message is a 4-byte big-endian length N
/// followed by N bytes of payload (one serialized protobuf). Socket-free, so it is unit tested on
/// arbitrary byte splits.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>

#include "scenewatch/core/result.h"

namespace scenewatch::service {

/// Bytes of the length prefix.
inline constexpr std::size_t kFrameHeaderBytes = 4;

/// The largest payload the 4-byte prefix can describe.
inline constexpr std::uint64_t kMaxEncodableFrameBytes = 0xFFFFFFFFull;

/// Prepends the 4-byte big-endian length to a payload. The payload must be 1..2^32-1 bytes.
std::string encode_frame(std::string_view payload);

/// Incremental decoder of length-prefixed frames. Feed it byte chunks of any size; it yields the
/// complete payloads in order. A declared length of zero or above the maximum is rejected as soon
/// as the 4 header bytes are known, before any payload memory is reserved; after an error the
/// parser stays failed (the stream cannot be resynchronised). NOT thread safe.
class FrameParser {
 public:
  /// `max_payload_bytes`: the largest accepted payload (at least 1).
  explicit FrameParser(std::size_t max_payload_bytes);

  /// Appends bytes from the stream. Returns an error (and stays failed) on a broken framing.
  Status feed(std::string_view bytes);

  /// The next complete payload, if one has been received; call until it returns nothing.
  std::optional<std::string> next();

  /// True when bytes of an incomplete frame (header or payload) are buffered.
  bool has_partial() const;

  /// True after a framing error.
  bool failed() const { return failed_; }

  /// Bytes held for the frame being received (header plus payload so far).
  std::size_t buffered_bytes() const { return header_fill_ + payload_.size(); }

  /// The largest accepted payload.
  std::size_t max_payload_bytes() const { return max_payload_bytes_; }

 private:
  std::size_t max_payload_bytes_;
  unsigned char header_[kFrameHeaderBytes] = {};
  std::size_t header_fill_ = 0;   ///< header bytes received of the current frame
  std::size_t expected_ = 0;      ///< payload length of the current frame, once its header is complete
  std::string payload_;           ///< payload bytes received of the current frame
  std::deque<std::string> ready_; ///< complete payloads not yet taken by next()
  bool failed_ = false;
};

}  // namespace scenewatch::service
