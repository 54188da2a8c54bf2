#include "chunked_file.h"

namespace scenewatch::io::bag {

std::string ChunkedFile::locate(const MessageRef& m) const {
  if (m.where[0] == 0) return "byte " + std::to_string(m.where[1]);
  return "the chunk at byte " + std::to_string(chunk_record_at(m.where[0])) + ", byte " + std::to_string(m.where[1]) + " of its " +
         chunk_contents_;
}

std::uint32_t ChunkedFile::topic_index(const std::string& name, const std::string& type, WireFormat wire) {
  std::uint32_t index = 0;
  while (index < topics_.size() && topics_[index].name != name) ++index;
  if (index == topics_.size()) topics_.push_back({name, type, wire});
  return index;
}

Status ChunkedFile::open_file(const std::string& path) {
  file_.open(path, std::ios::binary);
  if (!file_) return io_error("cannot open the file");
  file_.seekg(0, std::ios::end);
  size_ = static_cast<std::uint64_t>(file_.tellg());
  return {};
}

Result<std::vector<std::uint8_t>> ChunkedFile::read_file(std::uint64_t at, std::uint64_t n, const std::string& what) {
  if (at > size_ || n > size_ - at) {
    return invalid_argument(what + ": needs " + std::to_string(n) + " bytes at byte " + std::to_string(at) + ", the file ends at byte " +
                            std::to_string(size_) + " (truncated, or a wrong length)");
  }
  std::vector<std::uint8_t> out(static_cast<std::size_t>(n));
  file_.clear();
  file_.seekg(static_cast<std::streamoff>(at));
  file_.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(n));
  if (!file_) return io_error(what + ": read failed at byte " + std::to_string(at));
  return out;
}

Result<std::vector<std::uint8_t>> ChunkedFile::read(const MessageRef& m) {
  const std::uint64_t chunk = m.where[0], offset = m.where[1], length = m.where[2];
  if (chunk == 0) return read_file(offset, length, "message data");
  if (cached_chunk_ != chunk) {
    auto data = chunk_data(chunk);
    if (!data) return data.error();
    cache_ = std::move(*data);
    cached_chunk_ = chunk;
  }
  if (offset + length > cache_.size()) return Error{ErrorCode::kInternal, "message outside its chunk"};
  return std::vector<std::uint8_t>(cache_.begin() + static_cast<std::ptrdiff_t>(offset),
                                   cache_.begin() + static_cast<std::ptrdiff_t>(offset + length));
}

}  // namespace scenewatch::io::bag
