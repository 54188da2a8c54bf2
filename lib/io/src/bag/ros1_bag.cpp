// ROS 1 bag, format 2.0 (http://wiki.ros.org/Bags/Format/2.0): "#ROSBAG V2.0\n", then records of
//   <header_len u32><header: fields <len u32>name=value><data_len u32><data>
// op 0x03 bag header, 0x05 chunk (compression, size) whose data holds 0x07 connection and
// 0x02 message data records, 0x04 index data and 0x06 chunk info (skipped: the file is read in
// order, so a bag whose index was never written, as after a crash of the recorder, reads too).
#include <map>
#include <optional>

#include "chunked_file.h"
#include "decompress.h"

namespace scenewatch::io::bag {
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::uint8_t kOpMessage = 0x02, kOpBagHeader = 0x03, kOpChunk = 0x05, kOpConnection = 0x07;

using Fields = std::map<std::string, std::string>;

// A record header's fields; errors name the byte.
Result<Fields> parse_fields(const std::uint8_t* data, std::size_t size, std::uint64_t base) {
  ByteReader r(data, size, base);
  Fields fields;
  while (!r.at_end()) {
    const std::uint64_t at = r.offset();
    auto n = r.read<std::uint32_t>("record header field length");
    if (!n) return n.error();
    auto text = r.string(*n, "record header field");
    if (!text) return text.error();
    const auto eq = text->find('=');
    if (eq == std::string::npos) return invalid_argument("record header field at byte " + std::to_string(at) + " has no '='");
    fields[text->substr(0, eq)] = text->substr(eq + 1);
  }
  return fields;
}

template <typename T>
Result<T> field(const Fields& f, const std::string& name, std::uint64_t record_at) {
  auto it = f.find(name);
  if (it == f.end() || it->second.size() != sizeof(T)) {
    return invalid_argument("the record at byte " + std::to_string(record_at) + " has no " + std::to_string(sizeof(T)) +
                            "-byte field '" + name + "'");
  }
  T v;
  std::memcpy(&v, it->second.data(), sizeof(T));
  return v;
}

Result<std::string> text_field(const Fields& f, const std::string& name, std::uint64_t record_at) {
  auto it = f.find(name);
  if (it == f.end()) return invalid_argument("the record at byte " + std::to_string(record_at) + " has no field '" + name + "'");
  return it->second;
}

class Ros1Bag final : public ChunkedFile {
 public:
  Ros1Bag() : ChunkedFile("data") {}

  Status open(const std::string& path) {
    if (auto st = open_file(path); !st) return st;
    auto magic = read_file(0, sizeof kMagic - 1, "the magic line '#ROSBAG V2.0'");
    if (!magic) return magic.error();
    if (std::string(magic->begin(), magic->end()) != kMagic) {
      return invalid_argument("not a ROS 1 bag of format 2.0 (it does not start with '#ROSBAG V2.0')");
    }
    std::uint64_t pos = sizeof kMagic - 1;
    bool saw_header = false;
    while (pos < size_) {
      auto next = top_level_record(pos, saw_header);
      if (!next) return next.error();
      pos = *next;
    }
    if (!saw_header) {
      return invalid_argument("no bag header record (op 0x03) after the magic line; the file ends at byte " + std::to_string(size_) +
                              " (truncated?)");
    }
    return {};
  }

 protected:
  Result<std::vector<std::uint8_t>> chunk_data(std::uint64_t number) override { return load_chunk(chunks_[number - 1]); }
  std::uint64_t chunk_record_at(std::uint64_t number) const override { return chunks_[number - 1].record_at; }

 private:
  struct Chunk {
    std::uint64_t record_at = 0, data_at = 0, data_size = 0, uncompressed_size = 0;
    std::string compression;
  };



  Result<std::uint32_t> read_u32(std::uint64_t at, const std::string& what) {
    auto b = read_file(at, 4, what);
    if (!b) return b.error();
    std::uint32_t v;
    std::memcpy(&v, b->data(), 4);
    return v;
  }

  Result<std::vector<std::uint8_t>> load_chunk(const Chunk& c) {
    auto raw = read_file(c.data_at, c.data_size, "chunk data");
    if (!raw) return raw.error();
    auto data = decompress(c.compression, raw->data(), raw->size(), c.uncompressed_size);
    if (!data) return Error{data.error().code, "the chunk at byte " + std::to_string(c.record_at) + ": " + data.error().message};
    return data;
  }

  // One record at `pos` of the file; returns where the next begins.
  Result<std::uint64_t> top_level_record(std::uint64_t pos, bool& saw_header) {
    const std::uint64_t record_at = pos;
    auto header_len = read_u32(pos, "record header length");
    if (!header_len) return header_len.error();
    auto header = read_file(pos + 4, *header_len, "record header");
    if (!header) return header.error();
    auto fields = parse_fields(header->data(), header->size(), pos + 4);
    if (!fields) return fields.error();
    pos += 4 + *header_len;
    auto data_len = read_u32(pos, "record data length");
    if (!data_len) return data_len.error();
    const std::uint64_t data_at = pos + 4;
    if (data_at + *data_len > size_) {
      return invalid_argument("the record at byte " + std::to_string(record_at) + " says " + std::to_string(*data_len) +
                              " bytes of data follow, the file ends after " + std::to_string(size_ - data_at) +
                              " (truncated, or a wrong length)");
    }
    auto op = field<std::uint8_t>(*fields, "op", record_at);
    if (!op) return op.error();
    if (*op == kOpBagHeader) {
      saw_header = true;
    } else if (*op == kOpChunk) {
      Chunk c;
      c.record_at = record_at;
      c.data_at = data_at;
      c.data_size = *data_len;
      auto compression = text_field(*fields, "compression", record_at);
      if (!compression) return compression.error();
      auto size = field<std::uint32_t>(*fields, "size", record_at);
      if (!size) return size.error();
      c.compression = *compression;
      c.uncompressed_size = *size;
      chunks_.push_back(c);
      auto data = load_chunk(c);
      if (!data) return data.error();
      if (auto st = chunk_records(*data, chunks_.size()); !st) return st.error();
    } else if (*op == kOpConnection) {
      auto data = read_file(data_at, *data_len, "connection data");
      if (!data) return data.error();
      if (auto st = connection(*fields, *data, record_at, data_at); !st) return st.error();
    } else if (*op == kOpMessage) {
      if (auto st = message(*fields, record_at, 0, data_at, *data_len); !st) return st.error();
    }
    return data_at + *data_len;
  }

  // The records inside a decompressed chunk.
  Status chunk_records(const std::vector<std::uint8_t>& data, std::size_t chunk_number) {
    const Chunk& c = chunks_[chunk_number - 1];
    const std::string where = "the chunk at byte " + std::to_string(c.record_at) + ", ";
    ByteReader r(data.data(), data.size());
    while (!r.at_end()) {
      const std::uint64_t record_at = r.position();
      auto header_len = r.read<std::uint32_t>("record header length");
      if (!header_len) return Error{header_len.error().code, where + header_len.error().message + " of its data"};
      auto header = r.bytes(*header_len, "record header");
      if (!header) return Error{header.error().code, where + header.error().message + " of its data"};
      auto fields = parse_fields(*header, *header_len, record_at + 4);
      if (!fields) return Error{fields.error().code, where + fields.error().message + " of its data"};
      auto data_len = r.read<std::uint32_t>("record data length");
      if (!data_len) return Error{data_len.error().code, where + data_len.error().message + " of its data"};
      const std::uint64_t data_at = r.position();
      auto body = r.bytes(*data_len, "record data");
      if (!body) return Error{body.error().code, where + body.error().message + " of its data"};
      auto op = field<std::uint8_t>(*fields, "op", record_at);
      if (!op) return Error{op.error().code, where + op.error().message + " of its data"};
      if (*op == kOpConnection) {
        std::vector<std::uint8_t> conn(*body, *body + *data_len);
        if (auto st = connection(*fields, conn, record_at, data_at); !st) return Error{st.error().code, where + st.error().message};
      } else if (*op == kOpMessage) {
        if (auto st = message(*fields, record_at, chunk_number, data_at, *data_len); !st) return Error{st.error().code, where + st.error().message};
      }
    }
    return {};
  }

  Status connection(const Fields& header, const std::vector<std::uint8_t>& data, std::uint64_t record_at, std::uint64_t data_at) {
    auto id = field<std::uint32_t>(header, "conn", record_at);
    if (!id) return id.error();
    if (connection_topic_.count(*id)) return {};  // connections are repeated in the index section
    auto topic = text_field(header, "topic", record_at);
    if (!topic) return topic.error();
    auto info = parse_fields(data.data(), data.size(), data_at);
    if (!info) return info.error();
    auto type = text_field(*info, "type", record_at);
    if (!type) return type.error();
    connection_topic_[*id] = topic_index(*topic, normalise_type(*type), WireFormat::kRos1);
    return {};
  }

  Status message(const Fields& header, std::uint64_t record_at, std::uint64_t chunk, std::uint64_t data_at, std::uint64_t size) {
    auto id = field<std::uint32_t>(header, "conn", record_at);
    if (!id) return id.error();
    auto time = field<std::uint64_t>(header, "time", record_at);
    if (!time) return time.error();
    auto it = connection_topic_.find(*id);
    if (it == connection_topic_.end()) {
      return invalid_argument("the message record at byte " + std::to_string(record_at) + " names connection " + std::to_string(*id) +
                              ", which no connection record before it declares");
    }
    MessageRef m;
    m.topic = it->second;
    const std::uint64_t sec = *time & 0xFFFFFFFFu, nsec = *time >> 32;
    m.log_time_ns = static_cast<std::int64_t>(sec * 1000000000ull + nsec);
    m.where[0] = chunk;
    m.where[1] = data_at;
    m.where[2] = size;
    messages_.push_back(m);
    return {};
  }

  std::vector<Chunk> chunks_;
  std::map<std::uint32_t, std::uint32_t> connection_topic_;
};

}  // namespace

std::string normalise_type(const std::string& type) {
  const auto at = type.find("/msg/");
  return at == std::string::npos ? type : type.substr(0, at) + "/" + type.substr(at + 5);
}

Result<std::unique_ptr<Container>> open_ros1_bag(const std::string& path) {
  auto bag = std::make_unique<Ros1Bag>();
  if (auto st = bag->open(path); !st) return Error{st.error().code, path + ": " + st.error().message};
  return std::unique_ptr<Container>(std::move(bag));
}

}  // namespace scenewatch::io::bag
