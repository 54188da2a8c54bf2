#pragma once
/// Pixel-level evaluation of a surprise map against ground-truth changed pixels.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace scenewatch::surprise {

/// ROC area under the curve of scores against binary labels (Mann-Whitney U, ties counted half).
/// Entries with a NaN score are skipped. Returns NaN when either class is empty.
double roc_auc(const std::vector<float>& scores, const std::vector<std::uint8_t>& positive);

}  // namespace scenewatch::surprise
