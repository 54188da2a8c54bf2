#pragma once
// Reads the fields of one serialized ROS message in either of the two wire formats bags hold:
// ROS 1 serialization (little-endian, packed, uint32 length before strings and arrays, strings
// without NUL) and ROS 2's CDR (XCDR1, little-endian only: a 4-byte encapsulation header, then each
// primitive aligned to its size counted from the header's end; strings carry a length that counts a
// trailing NUL). Every read is bounds-checked; errors name the field and the byte. NOT thread safe.
#include <cstdint>
#include <string>

#include "byte_reader.h"
#include "scenewatch/io/bag/messages.h"

namespace scenewatch::io::bag {

/// How a bag's messages are serialized.
enum class WireFormat { kRos1, kCdr };

class FieldReader {
 public:
  /// Checks the CDR encapsulation header (CDR_LE only); ROS 1 messages have none.
  static Result<FieldReader> open(const std::uint8_t* data, std::size_t size, WireFormat format);

  Result<std::uint8_t> u8(const char* field);
  Result<std::uint32_t> u32(const char* field);
  Result<double> f64(const char* field);
  Result<std::string> string(const char* field);
  Result<MessageHeader> header();
  /// A sequence's length whose elements take at least `min_element_bytes` each: a count the
  /// remaining bytes cannot hold is an error here, before anything is allocated.
  Result<std::uint32_t> sequence_length(const char* field, std::size_t min_element_bytes);
  /// `n` raw bytes (a uint8[] payload) as a pointer into the message.
  Result<const std::uint8_t*> bytes(std::uint32_t n, const char* field);
  /// Fixed array of doubles (CameraInfo's K): no length on the wire.
  Status f64_array(double* out, std::size_t n, const char* field);

  std::size_t position() const { return reader_.position(); }

 private:
  FieldReader(ByteReader reader, WireFormat format, std::size_t origin) : reader_(reader), format_(format), origin_(origin) {}
  Status align(std::size_t n, const char* field);

  ByteReader reader_;
  WireFormat format_;
  std::size_t origin_;
};

}  // namespace scenewatch::io::bag
