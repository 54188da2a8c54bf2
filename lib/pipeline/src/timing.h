#pragma once
// Stage timings of the pipeline.
#include <chrono>

namespace scenewatch::pipeline {

using Clock = std::chrono::steady_clock;

/// Milliseconds since t0.
inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace scenewatch::pipeline
