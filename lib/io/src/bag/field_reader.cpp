#include "field_reader.h"

#include <cstdio>

namespace scenewatch::io::bag {

Result<FieldReader> FieldReader::open(const std::uint8_t* data, std::size_t size, WireFormat format) {
  ByteReader reader(data, size);
  if (format == WireFormat::kRos1) return FieldReader(reader, format, 0);
  // CDR encapsulation header: representation id (big-endian uint16) and two option bytes.
  auto head = reader.bytes(4, "CDR encapsulation header");
  if (!head) return head.error();
  const unsigned id = (unsigned{(*head)[0]} << 8) | (*head)[1];
  if (id != 0x0001) {
    const char* name = id == 0x0000 ? " (CDR big-endian)" : id == 0x0002 ? " (PL_CDR big-endian)" : id == 0x0003 ? " (PL_CDR little-endian)" : "";
    char hex[8];
    std::snprintf(hex, sizeof hex, "%04x", id);
    return invalid_argument(std::string("CDR encapsulation 0x") + hex + name +
                            " at byte 0 is not supported (only CDR little-endian, 0x0001, as ROS 2 writes it)");
  }
  return FieldReader(reader, format, 4);
}

Status FieldReader::align(std::size_t n, const char* field) {
  if (format_ == WireFormat::kRos1) return {};
  return reader_.align(n, origin_, std::string("field '") + field + "' (alignment)");
}

Result<std::uint8_t> FieldReader::u8(const char* field) { return reader_.read<std::uint8_t>(std::string("field '") + field + "'"); }

Result<std::uint32_t> FieldReader::u32(const char* field) {
  if (auto st = align(4, field); !st) return st.error();
  return reader_.read<std::uint32_t>(std::string("field '") + field + "'");
}

Result<double> FieldReader::f64(const char* field) {
  if (auto st = align(8, field); !st) return st.error();
  return reader_.read<double>(std::string("field '") + field + "'");
}

Status FieldReader::f64_array(double* out, std::size_t n, const char* field) {
  for (std::size_t i = 0; i < n; ++i) {
    auto v = f64(field);
    if (!v) return v.error();
    out[i] = *v;
  }
  return {};
}

Result<std::string> FieldReader::string(const char* field) {
  const std::uint64_t at = reader_.position();
  auto n = u32(field);
  if (!n) return n.error();
  auto text = reader_.string(*n, std::string("field '") + field + "' (a string of " + std::to_string(*n) + " bytes)");
  if (!text) return text.error();
  if (format_ == WireFormat::kCdr) {
    // CDR counts the terminating NUL (an empty string is length 1; Cyclone also writes 0).
    if (*n == 0) return std::string();
    if (text->back() != '\0') {
      return invalid_argument(std::string("field '") + field + "': the CDR string at byte " + std::to_string(at) +
                              " does not end in NUL (a wrong length?)");
    }
    text->pop_back();
  }
  return text;
}

Result<MessageHeader> FieldReader::header() {
  MessageHeader h;
  if (format_ == WireFormat::kRos1) {
    auto seq = u32("header.seq");
    if (!seq) return seq.error();
  }
  auto sec = u32("header.stamp.sec");  // int32 in ROS 2, uint32 in ROS 1: both 4 bytes
  if (!sec) return sec.error();
  auto nsec = u32("header.stamp.nanosec");
  if (!nsec) return nsec.error();
  const double sec_value = format_ == WireFormat::kCdr ? static_cast<double>(static_cast<std::int32_t>(*sec)) : static_cast<double>(*sec);
  h.stamp_s = sec_value + 1e-9 * static_cast<double>(*nsec);
  auto frame = string("header.frame_id");
  if (!frame) return frame.error();
  h.frame_id = std::move(*frame);
  return h;
}

Result<std::uint32_t> FieldReader::sequence_length(const char* field, std::size_t min_element_bytes) {
  auto n = u32(field);
  if (!n) return n.error();
  if (min_element_bytes > 0 && static_cast<std::uint64_t>(*n) * min_element_bytes > reader_.remaining()) {
    return invalid_argument(std::string("field '") + field + "': " + std::to_string(*n) + " elements of at least " +
                            std::to_string(min_element_bytes) + " bytes at byte " + std::to_string(reader_.position()) +
                            ", only " + std::to_string(reader_.remaining()) + " bytes left (truncated or a wrong length)");
  }
  return n;
}

Result<const std::uint8_t*> FieldReader::bytes(std::uint32_t n, const char* field) {
  return reader_.bytes(n, std::string("field '") + field + "'");
}

}  // namespace scenewatch::io::bag
