#pragma once
/// The memory that unfinished frames of all clients may hold together (server.max_buffered_bytes).
/// A FrameParser books each buffer before it reserves it and gives it back when the buffer is
/// freed or handed on as a complete frame, so the total of the buffers allocated for unfinished
/// frames never exceeds the limit, however many clients grow theirs at once.
#include <atomic>
#include <cstddef>

namespace scenewatch::service {

/// Thread safe (one atomic counter); shared by the parsers of all sessions.
class FrameBudget {
 public:
  explicit FrameBudget(std::size_t limit_bytes) : limit_bytes_(limit_bytes) {}
  FrameBudget(const FrameBudget&) = delete;
  FrameBudget& operator=(const FrameBudget&) = delete;

  /// Books `bytes`; false, with nothing booked, when the total would exceed the limit.
  bool try_reserve(std::size_t bytes);
  /// Gives back bytes booked before.
  void release(std::size_t bytes);
  /// Bytes booked now.
  std::size_t reserved() const { return reserved_.load(); }
  std::size_t limit() const { return limit_bytes_; }

 private:
  const std::size_t limit_bytes_;
  std::atomic<std::size_t> reserved_{0};
};

}  // namespace scenewatch::service
