#include "bridge_stats.h"

#include <algorithm>
#include <cstdio>

namespace scenewatch::ros {

std::string seconds(double t) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6f", t);
  return b;
}

std::uint64_t BridgeStats::count(const std::string& name, std::uint64_t n) {
  std::lock_guard<std::mutex> lock(mutex_);
  return counters_[name] += n;
}

void BridgeStats::sample_ms(const std::string& name, double ms) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto& s = series_[name];
  if (s.size() < 100000) s.push_back(ms);  // bounded: a week-long run keeps its first samples
}

std::string BridgeStats::line() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::string out = "stats:";
  for (const auto& [name, n] : counters_) out += " " + name + "=" + std::to_string(n);
  for (const auto& [name, samples] : series_) {
    if (samples.empty()) continue;
    std::vector<double> s = samples;
    std::sort(s.begin(), s.end());
    const auto at = [&](double q) { return s[std::min(s.size() - 1, static_cast<std::size_t>(q * (s.size() - 1) + 0.5))]; };
    char b[200];
    std::snprintf(b, sizeof b, " %s_ms={n=%zu median=%.3f p95=%.3f max=%.3f}", name.c_str(), s.size(), at(0.5), at(0.95), s.back());
    out += b;
  }
  return out;
}

}  // namespace scenewatch::ros
