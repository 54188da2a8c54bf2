#pragma once
/// One observation: a cloud in the camera frame, optionally with its pose and intrinsics.
#include <optional>
#include <string>

#include "scenewatch/core/cloud.h"
#include "scenewatch/core/geometry.h"

namespace scenewatch {

/// How a frame's pose is found (`localization.mode`, issue 29): trusted as given, the given pose
/// refined against the memory, or tracked against the memory with no pose given.
enum class LocalizationMode { kGiven, kRefine, kTrack };

struct Frame {
  CloudConstPtr cloud;                 ///< points_camera; organized when it came from RGB-D
  std::optional<Pose> T_world_camera;  ///< none: the camera frame is taken as the world frame
  std::optional<Intrinsics> intrinsics;
  double stamp_s = 0.0;
  bool has_color = true;               ///< false when the source had no colour field
  std::string source;                  ///< file path or "api", for messages
  /// Which camera took it: frames of one camera share what is kept per camera (remembered planes,
  /// hand memory, the persistence of change candidates); several cameras may feed one model,
  /// interleaved. Empty: the default camera.
  std::string camera;
  /// Overrides the configured localization mode for this frame.
  std::optional<LocalizationMode> localization;

  /// The pose used to place the frame in the world (identity when none was given).
  Pose pose_or_identity() const { return T_world_camera.value_or(Pose::Identity()); }
};

}  // namespace scenewatch
