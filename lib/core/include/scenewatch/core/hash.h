#pragma once
/// Hash for packed integer keys (voxel coordinates, OctoMap keys) in power-of-two hash tables.
#include <cstddef>
#include <cstdint>

namespace scenewatch {

/// Packed keys differ mostly in their low bits, and std::hash<uint64_t> is the identity in
/// libstdc++; the splitmix64 finaliser spreads every input bit over the output.
struct MixHash64 {
  std::size_t operator()(std::uint64_t x) const {
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ULL;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebULL;
    x ^= x >> 31;
    return static_cast<std::size_t>(x);
  }
};

}  // namespace scenewatch
