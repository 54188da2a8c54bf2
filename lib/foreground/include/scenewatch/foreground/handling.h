#pragma once
/// The seed's DoF constraints (section 3.3): "We start with all the 6 DoF frozen at the beginning
/// and allow motions in parameters that were observed during the human manipulation. A new allowed
/// motion in currently frozen degree of freedom represents a surprise for the system."
///
/// A handling runs from the first touch to the release. The first handling of an object is where
/// its free DoFs are learnt; in a later one, the first frame in which a frozen DoF's range exceeds
/// the noise level is a surprise (FROZEN_DOF_MOTION), and the DoF is free from then on.
#include "scenewatch/core/dof.h"
#include "scenewatch/core/scene.h"

namespace scenewatch::foreground {

/// The noise level of the pose a frame gives: ranges below it are not motion.
struct DofThresholds {
  double translation_m = 0.03;
  double rotation_deg = 15.0;
};

/// True when DoF k of `v` exceeds its threshold (|v[k]|).
bool exceeds(const DofVector& v, int k, const DofThresholds& thresholds);

/// One handling in progress: the range of each DoF since its start.
class HandlingRecorder {
 public:
  HandlingRecorder(const Pose& T_world_support, const Pose& T_world_start, double start_s);
  /// Adds the pose of a frame; returns the DoFs whose range exceeds the thresholds for the first time.
  DofFlags add(const Pose& T_world_object, const DofThresholds& thresholds);
  /// The handling as it stands (end_s = 0 while it goes on).
  Handling handling(double end_s, const DofThresholds& thresholds) const;
  const Pose& start() const { return T_start_; }

 private:
  Pose T_support_, T_start_;
  double start_s_;
  DofVector lo_{}, hi_{};
  DofFlags flagged_{};
};

}  // namespace scenewatch::foreground
