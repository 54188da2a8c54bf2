#include "endpoints.h"

#include <algorithm>

#include "bulk_update.h"

namespace scenewatch::background {

void Endpoints::clear() {
  sums_.clear();
  codes_.clear();
  sorted_.clear();
  cursor_ = 0;
}

void Endpoints::add(std::uint64_t packed, const ColorSum& run) {
  ColorSum& c = sums_[packed];
  c.r += run.r;
  c.g += run.g;
  c.b += run.b;
  c.n += run.n;
}

void Endpoints::sort_by_morton() {
  codes_.clear();
  for (const auto& [k, c] : sums_) codes_.push_back(morton_encode(unpack_key(k)));
  radix_sort(codes_, scratch_, 48);
  // One pass of independent lookups: the processor overlaps their cache misses.
  sorted_.resize(codes_.size());
  for (std::size_t i = 0; i < codes_.size(); ++i) sorted_[i] = sums_.find(pack_key(morton_decode(codes_[i])))->second;
  cursor_ = 0;
}

void Endpoints::merge(const Endpoints& other) {
  std::vector<std::uint64_t>& codes = merged_codes_;
  std::vector<ColorSum>& sums = merged_sums_;
  codes.clear();
  sums.clear();
  std::size_t i = 0, j = 0;
  while (i < codes_.size() || j < other.codes_.size()) {
    const bool mine = j == other.codes_.size() || (i < codes_.size() && codes_[i] <= other.codes_[j]);
    const bool theirs = i == codes_.size() || (j < other.codes_.size() && other.codes_[j] <= codes_[i]);
    ColorSum s;
    if (mine) s = sorted_[i];
    if (theirs) {
      const ColorSum& o = other.sorted_[j];
      s.r += o.r, s.g += o.g, s.b += o.b, s.n += o.n;
    }
    codes.push_back(mine ? codes_[i] : other.codes_[j]);
    sums.push_back(s);
    i += mine ? 1 : 0;
    j += theirs ? 1 : 0;
  }
  codes_.swap(codes);
  sorted_.swap(sums);
  cursor_ = 0;
}

void Endpoints::mean_color_in_order(const octomap::OcTreeKey& k, std::uint8_t rgb[3]) {
  const std::uint64_t code = morton_encode(k);
  if (cursor_ >= codes_.size() || codes_[cursor_] != code) {  // not the next one: search
    cursor_ = static_cast<std::size_t>(std::lower_bound(codes_.begin(), codes_.end(), code) - codes_.begin());
  }
  rgb[0] = rgb[1] = rgb[2] = 0;
  if (cursor_ >= codes_.size() || codes_[cursor_] != code) return;
  const ColorSum& c = sorted_[cursor_++];
  rgb[0] = static_cast<std::uint8_t>(c.r / c.n);
  rgb[1] = static_cast<std::uint8_t>(c.g / c.n);
  rgb[2] = static_cast<std::uint8_t>(c.b / c.n);
}

}  // namespace scenewatch::background
