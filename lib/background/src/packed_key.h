#pragma once
// An OctoMap key as one 64-bit integer (x in bits 32-47, y in 16-31, z in 0-15), for hash maps
// and sorted lists of voxels or of ray blocks.
// OcTreeKey.h uses uint16_t and size_t without including their headers.
#include <cstddef>
#include <cstdint>

#include <octomap/OcTreeKey.h>

namespace scenewatch::background {

inline std::uint64_t pack_key(const octomap::OcTreeKey& k) {
  return (static_cast<std::uint64_t>(k[0]) << 32) | (static_cast<std::uint64_t>(k[1]) << 16) | k[2];
}
inline octomap::OcTreeKey unpack_key(std::uint64_t v) {
  return octomap::OcTreeKey(static_cast<octomap::key_type>(v >> 32), static_cast<octomap::key_type>((v >> 16) & 0xffff),
                            static_cast<octomap::key_type>(v & 0xffff));
}

}  // namespace scenewatch::background
