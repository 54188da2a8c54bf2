#include "decompress.h"

#include <array>

#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

namespace scenewatch::io::bag {
namespace {

Error wrong_size(const std::string& what, std::uint64_t got, std::uint64_t expected) {
  return invalid_argument(what + " chunk decompresses to " + std::to_string(got) + " bytes, its record says " +
                          std::to_string(expected));
}

Result<std::vector<std::uint8_t>> lz4_frame(const std::uint8_t* data, std::size_t size, std::vector<std::uint8_t> out) {
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) return Error{ErrorCode::kInternal, "lz4: no context"};
  std::size_t in_pos = 0, out_pos = 0;
  std::size_t hint = 1;
  while (in_pos < size && hint != 0) {
    std::size_t in_n = size - in_pos, out_n = out.size() - out_pos;
    hint = LZ4F_decompress(ctx, out.data() + out_pos, &out_n, data + in_pos, &in_n, nullptr);
    if (LZ4F_isError(hint)) {
      const std::string why = LZ4F_getErrorName(hint);
      LZ4F_freeDecompressionContext(ctx);
      return invalid_argument("lz4 chunk: " + why + " at byte " + std::to_string(in_pos) + " of the chunk's data");
    }
    in_pos += in_n;
    out_pos += out_n;
    if (in_n == 0 && out_n == 0) break;  // no progress: output full (more data than declared)
  }
  LZ4F_freeDecompressionContext(ctx);
  if (hint != 0) return invalid_argument("lz4 chunk: the data ends inside a frame, or decompresses to more than its record says (" +
                                         std::to_string(out.size()) + " bytes)");
  if (out_pos != out.size()) return wrong_size("lz4", out_pos, out.size());
  return out;
}

}  // namespace

Result<std::vector<std::uint8_t>> decompress(const std::string& compression, const std::uint8_t* data, std::size_t size,
                                             std::uint64_t uncompressed_size) {
  if (uncompressed_size > kMaxChunkBytes) {
    return invalid_argument("a chunk of " + std::to_string(uncompressed_size) + " bytes (uncompressed) is larger than " +
                            std::to_string(kMaxChunkBytes) + ": a wrong length?");
  }
  if (compression.empty() || compression == "none") {
    if (size != uncompressed_size) return wrong_size("an uncompressed", size, uncompressed_size);
    return std::vector<std::uint8_t>(data, data + size);
  }
  std::vector<std::uint8_t> out(static_cast<std::size_t>(uncompressed_size));
  if (compression == "bz2") {
    unsigned int n = static_cast<unsigned int>(out.size());
    const int rc = BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(out.data()), &n,
                                              const_cast<char*>(reinterpret_cast<const char*>(data)), static_cast<unsigned int>(size), 0, 0);
    if (rc == BZ_OUTBUFF_FULL) return invalid_argument("bz2 chunk decompresses to more than its record says (" + std::to_string(out.size()) + " bytes)");
    if (rc != BZ_OK) return invalid_argument("bz2 chunk: corrupt or truncated data (libbz2 error " + std::to_string(rc) + ")");
    if (n != out.size()) return wrong_size("bz2", n, out.size());
    return out;
  }
  if (compression == "lz4") return lz4_frame(data, size, std::move(out));
  if (compression == "zstd") {
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), data, size);
    if (ZSTD_isError(n)) return invalid_argument(std::string("zstd chunk: ") + ZSTD_getErrorName(n));
    if (n != out.size()) return wrong_size("zstd", n, out.size());
    return out;
  }
  return invalid_argument("unknown chunk compression '" + compression + "' (known: none, bz2, lz4, zstd)");
}

std::uint32_t crc32(const std::uint8_t* data, std::size_t size) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) c = table[(c ^ data[i]) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

}  // namespace scenewatch::io::bag
