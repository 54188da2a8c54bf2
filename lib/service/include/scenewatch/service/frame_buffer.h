#pragma once
/// The bytes of one frame being received. Beyond kHeapMaxBytes they live in an anonymous memory
/// mapping of their own, which grows in place (mremap: the pages move, nothing is copied) and
/// whose pages go back to the system the moment it is freed, however the allocator is tuned: the
/// daemon keeps freed frame-sized heap buffers for reuse (keep_frame_buffers_in_heap), and glibc's
/// malloc_trim cannot hand back the top of a thread's arena, where a burst of clients that vanish
/// mid-frame would leave their buffers. Smaller frames (most requests) stay on the heap: a
/// mapping per request would cost more than it saves.
#include <cstddef>
#include <string>

namespace scenewatch::service {

/// Movable, not copyable; NOT thread safe.
class FrameBuffer {
 public:
  FrameBuffer() = default;
  ~FrameBuffer();
  FrameBuffer(FrameBuffer&& other) noexcept;
  FrameBuffer& operator=(FrameBuffer&& other) noexcept;
  FrameBuffer(const FrameBuffer&) = delete;
  FrameBuffer& operator=(const FrameBuffer&) = delete;

  /// Frames up to this size are kept on the heap.
  static constexpr std::size_t kHeapMaxBytes = 64 * 1024;
  /// The capacity reserve(bytes) gives: `bytes` on the heap, whole pages in a mapping.
  static std::size_t capacity_for(std::size_t bytes);
  /// Grows the buffer to capacity_for(bytes) (never shrinks it); false when the system refuses.
  bool reserve(std::size_t bytes);
  /// Appends `n` bytes; they must fit in capacity().
  void append(const char* data, std::size_t n);
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return capacity_; }
  /// The bytes as a string (from a mapping: one copy, and the mapping is freed).
  std::string take();
  /// Frees the buffer.
  void clear();

 private:
  std::string heap_;        ///< the bytes while capacity_ <= kHeapMaxBytes
  char* data_ = nullptr;    ///< the mapping beyond it
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
};

}  // namespace scenewatch::service
