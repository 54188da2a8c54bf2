#include "scenewatch/surprise/pixel_scoring.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace scenewatch::surprise {

double roc_auc(const std::vector<float>& scores, const std::vector<std::uint8_t>& positive) {
  std::vector<std::pair<float, std::uint8_t>> v;
  v.reserve(scores.size());
  for (std::size_t i = 0; i < scores.size() && i < positive.size(); ++i) {
    if (!std::isnan(scores[i])) v.emplace_back(scores[i], positive[i] ? 1 : 0);
  }
  std::sort(v.begin(), v.end());
  double pos = 0, neg = 0, rank_sum = 0;
  for (std::size_t i = 0; i < v.size();) {
    std::size_t j = i;
    while (j < v.size() && v[j].first == v[i].first) ++j;
    const double mid_rank = 0.5 * static_cast<double>(i + 1 + j);  // average 1-based rank of the tie group
    for (std::size_t k = i; k < j; ++k) {
      if (v[k].second) {
        rank_sum += mid_rank;
        ++pos;
      } else {
        ++neg;
      }
    }
    i = j;
  }
  if (pos == 0 || neg == 0) return std::numeric_limits<double>::quiet_NaN();
  return (rank_sum - pos * (pos + 1) / 2) / (pos * neg);
}

}  // namespace scenewatch::surprise
