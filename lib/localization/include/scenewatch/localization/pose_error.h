#pragma once
/// Measuring localization against a recording's poses. Pose sources as a robot has them:
/// odometry that drifts, and poses with independent noise; both draw each error as a twist with
/// translation N(0, s_t^2 / 3) per axis (so its RMS is s_t) and rotation likewise, from `seed`.
/// And the error of an estimated trajectory against the true one.
#include <vector>

#include "scenewatch/core/geometry.h"

namespace scenewatch::localization {

/// Odometry: the true relative motions, each with a random error of RMS `step_m` and
/// `step_deg`, integrated from the first true pose (a random walk: the drift grows with sqrt(n)).
std::vector<Pose> with_drift(const std::vector<Pose>& truth, double step_m, double step_deg, unsigned seed);

/// Each true pose with its own random error of RMS `sigma_m` and `sigma_deg`, independent from
/// frame to frame (a motion-capture marker's jitter, a pose estimate's scatter).
std::vector<Pose> with_noise(const std::vector<Pose>& truth, double sigma_m, double sigma_deg, unsigned seed);

/// How far an estimated trajectory is from the true one: both taken relative to their own first
/// pose (tied at the first frame, as a tracker that starts at the identity must be scored), the
/// RMS of the differences of their positions. Equal lengths, frame by frame; 0 when empty.
double trajectory_rmse_m(const std::vector<Pose>& estimate, const std::vector<Pose>& truth);

}  // namespace scenewatch::localization
