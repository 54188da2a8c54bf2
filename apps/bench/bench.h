#pragma once
// Shared pieces of the benchmark app: timing and table printing.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace scenewatch::bench {

struct Options {
  std::filesystem::path data_dir;
  int repetitions = 7;
};

/// Median of a sample (copies).
inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// The q-quantile (0..1) of a sample, nearest rank.
inline double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(q * v.size()));
  return v[i];
}

/// Runs `f` once and returns its wall time in milliseconds.
inline double time_ms(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

int run_octomap(const Options& o);
int run_segmentation(const Options& o);
/// Issue 30: every labelled mOSD scene, as recorded and as an unorganized copy, tuning and held-out apart.
int run_clutter(const Options& o);
int run_latency(const Options& o);
int run_surprise(const Options& o);
int run_change(const Options& o);
int run_stream(const Options& o);
/// Issue 28: redkitchen_long tuned on one half, reported on the other, each remedy off in turn.
int run_sensor_model(const Options& o);
int run_pipeline(const Options& o);
int run_memory(const Options& o);
int run_fit(const Options& o);
int run_foreground(const Options& o);
/// Issue 29: the camera placed against the memory, each mode; dense alignment against OpenCV and PCL.
int run_localization(const Options& o);
/// Where to look next (issue 31): scoring speed against OctoMap, the seed's experiment, the closed loop.
int run_nbv(const Options& o);

}  // namespace scenewatch::bench
