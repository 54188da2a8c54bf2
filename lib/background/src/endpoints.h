#pragma once
// The voxels a frame's rays end in, each with the sum of the colours of the pixels that end there.
//
// Filled in image order (neighbouring pixels mostly end in one voxel, so their colours are summed
// in a run that goes into the hash map once). The tree update asks for the hits' colours in Morton
// order, one per hit: sorted that way once, the colours are read by a cursor that only moves
// forward, not by a hash lookup (a cache miss) per hit inside the tree walk; and two parts of a
// frame traced apart merge their sorted lists in one pass.
// OcTreeKey.h uses uint16_t and size_t without including their headers.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <octomap/OcTreeKey.h>
#include <tsl/robin_map.h>

#include "packed_key.h"
#include "scenewatch/core/hash.h"

namespace scenewatch::background {

struct ColorSum {
  std::uint32_t r = 0, g = 0, b = 0, n = 0;
};

class Endpoints {
 public:
  /// Forgets the last frame's endpoints (keeping the memory).
  void clear();
  /// Adds a run of pixels ending in voxel `packed` (pack_key).
  void add(std::uint64_t packed, const ColorSum& run);
  /// Calls f(key) for every endpoint voxel, in the hash map's order. That order is a good one to
  /// cast their rays in: it scatters them over the image, so that every ray soon meets voxels
  /// its neighbours freed (ray_cast.h); image order would walk about 70 % more steps.
  template <typename F>
  void for_each(F&& f) const {
    for (const auto& [k, c] : sums_) f(unpack_key(k));
  }
  /// Prepares mean_color_in_order().
  void sort_by_morton();
  /// Adds the endpoints of `other`; both sorted by Morton code. Only the sorted list is merged:
  /// for_each() still lists this frame part's own endpoints.
  void merge(const Endpoints& other);
  /// The mean colour of endpoint voxel k, from the sorted list. Asked for in increasing Morton
  /// order it costs no search; any other order still gets the right colour; black for a voxel
  /// that is not an endpoint.
  void mean_color_in_order(const octomap::OcTreeKey& k, std::uint8_t rgb[3]);

 private:
  tsl::robin_map<std::uint64_t, ColorSum, MixHash64> sums_;
  std::vector<std::uint64_t> codes_, scratch_;  // Morton codes, sorted
  std::vector<ColorSum> sorted_;                // their colour sums
  std::vector<std::uint64_t> merged_codes_;     // merge()'s output, swapped in; kept to reuse
  std::vector<ColorSum> merged_sums_;
  std::size_t cursor_ = 0;
};

}  // namespace scenewatch::background
