#pragma once
/// Length-prefixed framing of the wire protocol: each message is a 4-byte big-endian length N
/// followed by N bytes of payload (one serialized protobuf). Socket-free, so it is unit tested on
/// arbitrary byte splits.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "scenewatch/core/result.h"
#include "scenewatch/service/frame_budget.h"
#include "scenewatch/service/frame_buffer.h"

namespace scenewatch::service {

/// Bytes of the length prefix.
inline constexpr std::size_t kFrameHeaderBytes = 4;

/// The largest payload the 4-byte prefix can describe.
inline constexpr std::uint64_t kMaxEncodableFrameBytes = 0xFFFFFFFFull;

/// Writes the 4-byte big-endian length of a payload of `payload_bytes` at `out`.
void put_frame_header(std::uint32_t payload_bytes, char* out);

/// Prepends the 4-byte big-endian length to a payload. The payload must be 1..2^32-1 bytes.
std::string encode_frame(std::string_view payload);

/// Incremental decoder of length-prefixed frames. Feed it byte chunks of any size; it yields the
/// complete payloads in order. A declared length of zero or above the maximum is rejected as soon
/// as the 4 header bytes are known, before any payload memory is reserved; after an error the
/// parser stays failed (the stream cannot be resynchronised). The frame being received is held in
/// a FrameBuffer of its own that grows in doubling steps as its bytes arrive (a client that
/// announces a large frame and stalls holds little), each step booked in the FrameBudget, when one
/// is given, before it is mapped; a complete frame is handed out as a string (one copy) and its
/// buffer unmapped. NOT thread safe.
class FrameParser {
 public:
  /// `max_payload_bytes`: the largest accepted payload (at least 1). `budget`: shared by the
  /// parsers whose unfinished frames are held to one limit (null: none).
  explicit FrameParser(std::size_t max_payload_bytes, std::shared_ptr<FrameBudget> budget = nullptr);
  ~FrameParser();
  FrameParser(FrameParser&& other) noexcept;
  FrameParser& operator=(FrameParser&& other) noexcept;
  FrameParser(const FrameParser&) = delete;
  FrameParser& operator=(const FrameParser&) = delete;

  /// Appends bytes from the stream. Returns an error (and stays failed) on a broken framing
  /// (kInvalidArgument), or when the budget cannot hold the frame's next buffer step
  /// (kUnavailable: the unfinished frame is dropped).
  Status feed(std::string_view bytes);

  /// The next complete payload, if one has been received; call until it returns nothing.
  std::optional<std::string> next();

  /// True when bytes of an incomplete frame (header or payload) are buffered.
  bool has_partial() const;

  /// True after a framing error or a refusal of the budget.
  bool failed() const { return failed_; }

  /// Bytes held for the frame being received (header plus payload so far).
  std::size_t buffered_bytes() const { return header_fill_ + payload_.size(); }

  /// Bytes of memory mapped (and booked) for the frame being received.
  std::size_t reserved_bytes() const { return payload_.capacity(); }

  /// Frees the unfinished frame's buffer and gives its booking back; returns the bytes freed.
  /// Complete payloads not yet taken stay. The parser fails from then on.
  std::size_t drop_partial();

  /// The largest accepted payload.
  std::size_t max_payload_bytes() const { return max_payload_bytes_; }

 private:
  /// Makes room for `needed` payload bytes of the current frame (see the class comment).
  Status reserve_payload(std::size_t needed);
  /// Unmaps payload_ and gives back its booking.
  void release_payload();

  std::size_t max_payload_bytes_;
  std::shared_ptr<FrameBudget> budget_;
  unsigned char header_[kFrameHeaderBytes] = {};
  std::size_t header_fill_ = 0;   ///< header bytes received of the current frame
  std::size_t expected_ = 0;      ///< payload length of the current frame, once its header is complete
  FrameBuffer payload_;           ///< payload bytes received of the current frame (its capacity is booked in budget_)
  std::deque<std::string> ready_; ///< complete payloads not yet taken by next()
  bool failed_ = false;
};

}  // namespace scenewatch::service
