#pragma once
// Decompression of bag chunks through Debian's libbz2, liblz4 (frame format, as roslz4 and MCAP
// write it) and libzstd. The expected size comes from the container and is checked: a chunk that
// decompresses to more or fewer bytes is an error, never a larger buffer.
#include <cstdint>
#include <string>
#include <vector>

#include "scenewatch/core/result.h"

namespace scenewatch::io::bag {

/// Largest chunk accepted (a hostile size field must not allocate without bound).
inline constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 30;

/// `compression`: "none" or "" (copied), "bz2", "lz4", "zstd". Errors say which and why.
Result<std::vector<std::uint8_t>> decompress(const std::string& compression, const std::uint8_t* data, std::size_t size,
                                             std::uint64_t uncompressed_size);

/// CRC-32 (ISO-HDLC, as zlib and MCAP use it).
std::uint32_t crc32(const std::uint8_t* data, std::size_t size);

}  // namespace scenewatch::io::bag
