#pragma once
// The part ROS 1 bags and MCAP files share: a file read at offsets with every length checked
// against its size, and messages that lie either in the file (chunk 0) or inside a compressed chunk
// (1-based), with the last decompressed chunk cached. MessageRef::where = {chunk, offset, length}.
// NOT thread safe.
#include <fstream>

#include "container.h"

namespace scenewatch::io::bag {

class ChunkedFile : public Container {
 public:
  Result<std::vector<std::uint8_t>> read(const MessageRef& m) override;

 protected:
  /// Opens the file and learns its size.
  Status open_file(const std::string& path);
  /// `n` bytes at `at`; an error names `what`, the byte and where the file ends.
  Result<std::vector<std::uint8_t>> read_file(std::uint64_t at, std::uint64_t n, const std::string& what);
  /// The decompressed data of chunk `number` (1-based).
  virtual Result<std::vector<std::uint8_t>> chunk_data(std::uint64_t number) = 0;

  std::uint64_t size_ = 0;

 private:
  std::ifstream file_;
  std::vector<std::uint8_t> cache_;
  std::uint64_t cached_chunk_ = 0;
};

}  // namespace scenewatch::io::bag
