#pragma once
/// The bytes of one frame being received, in an anonymous memory mapping of its own. It grows in
/// place (mremap: the pages move, nothing is copied), and its pages go back to the system the
/// moment it is freed, however the allocator is tuned: the daemon keeps freed frame-sized heap
/// buffers for reuse (keep_frame_buffers_in_heap), and glibc's malloc_trim cannot hand back the top
/// of a thread's arena, where a burst of clients that vanish mid-frame would leave their buffers.
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

  /// The mapping's size for `bytes`: whole pages.
  static std::size_t capacity_for(std::size_t bytes);
  /// Grows the mapping to capacity_for(bytes) (never shrinks it); false when the system refuses.
  bool reserve(std::size_t bytes);
  /// Appends `n` bytes; they must fit in capacity().
  void append(const char* data, std::size_t n);
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return capacity_; }
  /// The bytes as a string (one copy); the mapping is freed.
  std::string take();
  /// Frees the mapping.
  void clear();

 private:
  char* data_ = nullptr;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
};

}  // namespace scenewatch::service
