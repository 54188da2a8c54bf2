#pragma once
// A bounds-checked cursor over bytes that are not ours (a bag's records, a message's fields).
// Every read checks the remaining length first; a failed read returns an error that names what
// was being read and the byte offset (relative to `base_offset`, so that nested buffers can report
// offsets in the file or in the message). Reads are little-endian. NOT thread safe.
#include <cstdint>
#include <cstring>
#include <string>

#include "scenewatch/core/result.h"

namespace scenewatch::io::bag {

class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size, std::uint64_t base_offset = 0)
      : data_(data), size_(size), base_(base_offset) {}

  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return size_ - pos_; }
  bool at_end() const { return pos_ == size_; }
  /// The offset of the cursor as reported in errors (base_offset + position).
  std::uint64_t offset() const { return base_ + pos_; }
  const std::uint8_t* cursor() const { return data_ + pos_; }

  /// Error "<what>: needs N bytes at byte X, only M left".
  Error short_read(const std::string& what, std::uint64_t needed) const {
    return invalid_argument(what + ": needs " + std::to_string(needed) + " bytes at byte " + std::to_string(offset()) +
                            ", only " + std::to_string(remaining()) + " left (truncated or a wrong length)");
  }

  /// Moves the cursor to a multiple of `alignment` bytes from `origin` (CDR aligns fields to
  /// their size, counted from the end of the encapsulation header).
  Status align(std::size_t alignment, std::size_t origin, const std::string& what) {
    const std::size_t rel = pos_ - origin;
    const std::size_t pad = (alignment - rel % alignment) % alignment;
    return skip(pad, what);
  }

  Status skip(std::uint64_t n, const std::string& what) {
    if (n > remaining()) return short_read(what, n);
    pos_ += static_cast<std::size_t>(n);
    return {};
  }

  template <typename T>
  Result<T> read(const std::string& what) {
    if (sizeof(T) > remaining()) return short_read(what, sizeof(T));
    T value;
    std::memcpy(&value, data_ + pos_, sizeof(T));  // little-endian hosts only (x86-64, arm64)
    pos_ += sizeof(T);
    return value;
  }

  /// `n` bytes as a pointer into the buffer (valid while the buffer lives).
  Result<const std::uint8_t*> bytes(std::uint64_t n, const std::string& what) {
    if (n > remaining()) return short_read(what, n);
    const std::uint8_t* p = data_ + pos_;
    pos_ += static_cast<std::size_t>(n);
    return p;
  }

  Result<std::string> string(std::uint64_t n, const std::string& what) {
    auto p = bytes(n, what);
    if (!p) return p.error();
    return std::string(reinterpret_cast<const char*>(*p), static_cast<std::size_t>(n));
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::uint64_t base_;
  std::size_t pos_ = 0;
};

}  // namespace scenewatch::io::bag
