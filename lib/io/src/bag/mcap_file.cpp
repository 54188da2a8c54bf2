// MCAP (https://mcap.dev/spec, major version 0), rosbag2's default storage since Iron:
//   <magic "\x89MCAP0\r\n"><records: opcode u8, length u64, content><magic>
// Read in order: Schema (0x03), Channel (0x04), Message (0x05) and Chunk (0x06; lz4 or zstd,
// its CRC-32 of the uncompressed records checked when not 0) holding the first three; the
// summary's copies of schemas and channels are deduplicated by id, everything else is skipped.
// Channels of message encoding "cdr" (ROS 2) and "ros1" are read; others are left out.
#include <cstdio>
#include <map>

#include "chunked_file.h"
#include "decompress.h"

namespace scenewatch::io::bag {
namespace {

constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr std::uint8_t kSchema = 0x03, kChannel = 0x04, kMessage = 0x05, kChunk = 0x06, kFooter = 0x02;

std::string hex(std::uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%08x", v);
  return b;
}

Result<std::string> str(ByteReader& r, const char* what) {
  auto n = r.read<std::uint32_t>(what);
  if (!n) return n.error();
  return r.string(*n, what);
}

class McapFile final : public ChunkedFile {
 public:
  McapFile() : ChunkedFile("records") {}

  Status open(const std::string& path) {
    if (auto st = open_file(path); !st) return st;
    auto magic = read_file(0, 8, "the MCAP magic");
    if (!magic) return magic.error();
    if (std::memcmp(magic->data(), kMagic, 8) != 0) return invalid_argument("not an MCAP file (no magic \\x89MCAP0\\r\\n at byte 0)");
    std::uint64_t pos = 8;
    while (true) {
      if (pos == size_) return invalid_argument("the file ends at byte " + std::to_string(pos) + " without a footer (truncated)");
      auto head = read_file(pos, 9, "record opcode and length");
      if (!head) return head.error();
      const std::uint8_t op = (*head)[0];
      std::uint64_t length;
      std::memcpy(&length, head->data() + 1, 8);
      if (length > size_ - pos - 9) {
        return invalid_argument("the record (opcode " + std::to_string(op) + ") at byte " + std::to_string(pos) + " says " +
                                std::to_string(length) + " bytes follow, the file has " + std::to_string(size_ - pos - 9) +
                                " (truncated, or a wrong length)");
      }
      if (op == kFooter) break;
      if (op == kSchema || op == kChannel || op == kChunk) {
        auto content = read_file(pos + 9, length, "record");
        if (!content) return content.error();
        if (auto st = record(op, *content, pos, 0); !st) return st;
      } else if (op == kMessage) {
        auto content = read_file(pos + 9, std::min<std::uint64_t>(length, 22), "message record");
        if (!content) return content.error();
        if (auto st = message(content->data(), length, pos + 9, 0); !st) return st;
      }
      pos += 9 + length;
    }
    return {};
  }

 protected:
  Result<std::vector<std::uint8_t>> chunk_data(std::uint64_t number) override { return load_chunk(chunks_[number - 1], false); }
  std::uint64_t chunk_record_at(std::uint64_t number) const override { return chunks_[number - 1].record_at; }

 private:
  struct Chunk {
    std::uint64_t record_at = 0, records_at = 0, records_size = 0, uncompressed_size = 0;
    std::uint32_t crc = 0;
    std::string compression;
  };



  Result<std::vector<std::uint8_t>> load_chunk(const Chunk& c, bool check_crc) {
    auto raw = read_file(c.records_at, c.records_size, "chunk records");
    if (!raw) return raw.error();
    auto data = decompress(c.compression, raw->data(), raw->size(), c.uncompressed_size);
    if (!data) return Error{data.error().code, "the chunk at byte " + std::to_string(c.record_at) + ": " + data.error().message};
    if (check_crc && c.crc != 0) {
      const std::uint32_t crc = crc32(data->data(), data->size());
      if (crc != c.crc) {
        return invalid_argument("the chunk at byte " + std::to_string(c.record_at) + ": the CRC-32 of its records is " + hex(crc) +
                                ", the chunk says " + hex(c.crc) + " (a lying CRC, or corrupt records)");
      }
    }
    return data;
  }

  // A Schema, Channel or Chunk record's content; `chunk`: the chunk it is in (0: none).
  Status record(std::uint8_t op, const std::vector<std::uint8_t>& content, std::uint64_t record_at, std::uint64_t chunk) {
    ByteReader r(content.data(), content.size(), record_at + 9);
    auto fail = [&](const Error& e) { return Error{e.code, std::string(op == kSchema ? "schema" : op == kChannel ? "channel" : "chunk") +
                                                               " record at byte " + std::to_string(record_at) + ": " + e.message}; };
    if (op == kSchema) {
      auto id = r.read<std::uint16_t>("schema id");
      if (!id) return fail(id.error());
      auto name = str(r, "schema name");
      if (!name) return fail(name.error());
      schema_name_[*id] = *name;
      return {};
    }
    if (op == kChannel) {
      auto id = r.read<std::uint16_t>("channel id");
      if (!id) return fail(id.error());
      auto schema = r.read<std::uint16_t>("channel schema id");
      if (!schema) return fail(schema.error());
      auto topic = str(r, "channel topic");
      if (!topic) return fail(topic.error());
      auto encoding = str(r, "channel message encoding");
      if (!encoding) return fail(encoding.error());
      if (channel_topic_.count(*id) || (*encoding != "cdr" && *encoding != "ros1")) return {};
      auto it = schema_name_.find(*schema);
      if (it == schema_name_.end()) {
        return fail(invalid_argument("channel " + *topic + " names schema " + std::to_string(*schema) + ", which no schema record before it declares"));
      }
      channel_topic_[*id] =
          topic_index(*topic, normalise_type(it->second), *encoding == "cdr" ? WireFormat::kCdr : WireFormat::kRos1);
      return {};
    }
    Chunk c;
    c.record_at = record_at;
    std::uint64_t times[2];
    for (auto& t : times) {
      auto v = r.read<std::uint64_t>("chunk message time");
      if (!v) return fail(v.error());
      t = *v;
    }
    auto size = r.read<std::uint64_t>("chunk uncompressed size");
    if (!size) return fail(size.error());
    auto crc = r.read<std::uint32_t>("chunk uncompressed crc");
    if (!crc) return fail(crc.error());
    auto compression = str(r, "chunk compression");
    if (!compression) return fail(compression.error());
    auto records_size = r.read<std::uint64_t>("chunk records length");
    if (!records_size) return fail(records_size.error());
    if (*records_size > r.remaining()) return fail(r.short_read("chunk records", *records_size));
    c.records_at = r.offset();
    c.records_size = *records_size;
    c.uncompressed_size = *size;
    c.crc = *crc;
    c.compression = *compression;
    chunks_.push_back(c);
    auto data = load_chunk(c, true);
    if (!data) return data.error();
    return chunk_records(*data, chunks_.size());
  }

  Status chunk_records(const std::vector<std::uint8_t>& data, std::size_t chunk_number) {
    const std::string where = "the chunk at byte " + std::to_string(chunks_[chunk_number - 1].record_at) + ", ";
    ByteReader r(data.data(), data.size());
    while (!r.at_end()) {
      const std::uint64_t at = r.position();
      auto op = r.read<std::uint8_t>("record opcode");
      if (!op) return Error{op.error().code, where + op.error().message + " of its records"};
      auto length = r.read<std::uint64_t>("record length");
      if (!length) return Error{length.error().code, where + length.error().message + " of its records"};
      auto content = r.bytes(*length, "record");
      if (!content) return Error{content.error().code, where + content.error().message + " of its records"};
      if (*op == kSchema || *op == kChannel) {
        const std::vector<std::uint8_t> copy(*content, *content + *length);
        if (auto st = record(*op, copy, at, chunk_number); !st) return Error{st.error().code, where + st.error().message + " of its records"};
      } else if (*op == kMessage) {
        if (auto st = message(*content, *length, at + 9, chunk_number); !st) return Error{st.error().code, where + st.error().message};
      }
    }
    return {};
  }

  // A Message record's content at `content_at` (in the file, or in the chunk's records).
  Status message(const std::uint8_t* content, std::uint64_t length, std::uint64_t content_at, std::uint64_t chunk) {
    if (length < 22) {
      return invalid_argument("the message record at byte " + std::to_string(content_at - 9) + " has " + std::to_string(length) +
                              " bytes, fewer than its 22 bytes of fields");
    }
    std::uint16_t channel;
    std::uint64_t log_time;
    std::memcpy(&channel, content, 2);
    std::memcpy(&log_time, content + 6, 8);
    auto it = channel_topic_.find(channel);
    if (it == channel_topic_.end()) return {};  // a channel of another encoding (or undeclared): not ours to read
    MessageRef m;
    m.topic = it->second;
    m.log_time_ns = static_cast<std::int64_t>(log_time);
    m.where[0] = chunk;
    m.where[1] = content_at + 22;
    m.where[2] = length - 22;
    messages_.push_back(m);
    return {};
  }

  std::vector<Chunk> chunks_;
  std::map<std::uint16_t, std::string> schema_name_;
  std::map<std::uint16_t, std::uint32_t> channel_topic_;
};

}  // namespace

Result<std::unique_ptr<Container>> open_mcap(const std::string& path) {
  auto file = std::make_unique<McapFile>();
  if (auto st = file->open(path); !st) return Error{st.error().code, path + ": " + st.error().message};
  return std::unique_ptr<Container>(std::move(file));
}

}  // namespace scenewatch::io::bag
