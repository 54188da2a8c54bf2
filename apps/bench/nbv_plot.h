#pragma once
// A PNG line plot of per-step curves (issue 31: the seed's Figs. 3.12 and 3.13), drawn with OpenCV.
#include <filesystem>
#include <string>
#include <vector>

namespace scenewatch::bench {

/// One curve for the legend: the value after each step, step s + 1 at index s.
struct StepCurve {
  std::string name;
  std::vector<double> values;
};

/// One panel: steps first..last (1-based, both included; clipped to the curves' length).
struct StepRange {
  int first = 1;
  int last = 1;
};

/// Writes panels side by side (one colour per curve, the same in every panel), 1000x450 px for two
/// panels, white background. A panel's y axis is logarithmic when its values span more than a
/// decade. Returns false when the file cannot be written.
bool write_step_plot(const std::filesystem::path& png, const std::string& title, const std::string& y_label,
                     const std::vector<StepCurve>& curves, const std::vector<StepRange>& panels);

}  // namespace scenewatch::bench
