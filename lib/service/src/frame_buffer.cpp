#include "scenewatch/service/frame_buffer.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cassert>
#include <cstring>
#include <utility>

namespace scenewatch::service {

FrameBuffer::~FrameBuffer() { clear(); }

FrameBuffer::FrameBuffer(FrameBuffer&& other) noexcept
    : heap_(std::move(other.heap_)),
      data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      capacity_(std::exchange(other.capacity_, 0)) {
  other.heap_.clear();
}

FrameBuffer& FrameBuffer::operator=(FrameBuffer&& other) noexcept {
  if (this != &other) {
    clear();
    heap_ = std::move(other.heap_);
    other.heap_.clear();
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    capacity_ = std::exchange(other.capacity_, 0);
  }
  return *this;
}

std::size_t FrameBuffer::capacity_for(std::size_t bytes) {
  if (bytes <= kHeapMaxBytes) return bytes;
  static const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  return (bytes + page - 1) / page * page;
}

bool FrameBuffer::reserve(std::size_t bytes) {
  const std::size_t wanted = capacity_for(bytes);
  if (wanted <= capacity_) return true;
  if (wanted <= kHeapMaxBytes) {
    heap_.reserve(wanted);
    capacity_ = wanted;
    return true;
  }
  void* mapped = data_ == nullptr
                     ? ::mmap(nullptr, wanted, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0)
                     : ::mremap(data_, capacity_, wanted, MREMAP_MAYMOVE);
  if (mapped == MAP_FAILED) return false;
  if (data_ == nullptr) {  // from the heap to a mapping of its own
    std::memcpy(mapped, heap_.data(), size_);
    heap_ = std::string();
  }
  data_ = static_cast<char*>(mapped);
  capacity_ = wanted;
  return true;
}

void FrameBuffer::append(const char* data, std::size_t n) {
  assert(size_ + n <= capacity_);
  if (n == 0) return;
  if (data_ == nullptr) {
    heap_.append(data, n);
  } else {
    std::memcpy(data_ + size_, data, n);
  }
  size_ += n;
}

std::string FrameBuffer::take() {
  std::string bytes = data_ == nullptr ? std::move(heap_) : std::string(data_, size_);
  clear();
  return bytes;
}

void FrameBuffer::clear() {
  if (data_ != nullptr) ::munmap(data_, capacity_);
  data_ = nullptr;
  heap_ = std::string();
  size_ = 0;
  capacity_ = 0;
}

}  // namespace scenewatch::service
