#pragma once
// The part ROS 1 bags and MCAP files share: a file read at offsets with every length checked
// against its size, and messages that lie either in the file (chunk 0) or inside a compressed chunk
// (1-based), with the last decompressed chunk cached. MessageRef::where = {chunk, offset, length}.
// NOT thread safe.
#include <fstream>
#include <string>

#include "container.h"

namespace scenewatch::io::bag {

class ChunkedFile : public Container {
 public:
  Result<std::vector<std::uint8_t>> read(const MessageRef& m) override;
  const std::vector<Topic>& topics() const override { return topics_; }
  const std::vector<MessageRef>& messages() const override { return messages_; }
  /// "byte B", or "the chunk at byte C, byte B of its <chunk_contents>".
  std::string locate(const MessageRef& m) const override;

 protected:
  /// `chunk_contents` names what a message's offset inside a chunk counts in ("records", "data").
  explicit ChunkedFile(std::string chunk_contents) : chunk_contents_(std::move(chunk_contents)) {}
  /// Opens the file and learns its size.
  Status open_file(const std::string& path);
  /// `n` bytes at `at`; an error names `what`, the byte and where the file ends.
  Result<std::vector<std::uint8_t>> read_file(std::uint64_t at, std::uint64_t n, const std::string& what);
  /// The decompressed data of chunk `number` (1-based).
  virtual Result<std::vector<std::uint8_t>> chunk_data(std::uint64_t number) = 0;
  /// Where the record of chunk `number` (1-based) starts in the file.
  virtual std::uint64_t chunk_record_at(std::uint64_t number) const = 0;
  /// The index of the topic named `name` in topics_, added with this type and wire format when new.
  std::uint32_t topic_index(const std::string& name, const std::string& type, WireFormat wire);

  std::uint64_t size_ = 0;
  std::vector<Topic> topics_;
  std::vector<MessageRef> messages_;

 private:
  std::string chunk_contents_;
  std::ifstream file_;
  std::vector<std::uint8_t> cache_;
  std::uint64_t cached_chunk_ = 0;
};

}  // namespace scenewatch::io::bag
