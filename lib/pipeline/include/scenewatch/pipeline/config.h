#pragma once
/// The pipeline's configuration: one struct that aggregates each stage's Config, loaded from YAML
/// by load_config() (config_loader.h) and checked by validate().
#include <cstddef>

#include "scenewatch/background/appearance.h"
#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/change/mismatch.h"
#include "scenewatch/core/result.h"
#include "scenewatch/core/sensor_model.h"
#include "scenewatch/foreground/foreground_tracker.h"
#include "scenewatch/localization/localizer.h"
#include "scenewatch/pipeline/event_fusion.h"
#include "scenewatch/pipeline/object_tracker.h"
#include "scenewatch/segmentation/tabletop.h"
#include "scenewatch/surprise/surprise_map.h"

namespace scenewatch::pipeline {

/// Everything the pipeline needs; loaded from YAML by load_config().
struct Config {
  /// The depth camera and the pose source (the `sensor:` section): every stage that weighs
  /// evidence takes it from here (WorkingMemory copies it into change.sensor).
  SensorModel sensor;
  /// Where each frame was taken: its given pose trusted, refined against the memory (default),
  /// or tracked without poses (the `localization:` section, issue 29).
  localization::Config localization;
  background::Config background;
  segmentation::Config segmentation;
  TrackingConfig tracking;
  /// Geometric change detection (OBJECT_ADDED / OBJECT_REMOVED / OBJECT_MOVED) against the map
  /// as it stood before each frame, with a persistence filter.
  bool change_enabled = true;
  change::Config change;
  background::AppearanceConfig appearance;  ///< keyframes and mesh (posed RGB-D frames only)
  surprise::SurpriseConfig surprise;        ///< image-based Bayesian surprise
  std::size_t max_event_log = 10000;  ///< events kept in memory for GetEvents
  FusionConfig fusion;                ///< one fact, one event (the `events:` section)
  foreground::ForegroundConfig foreground;  ///< hands, promotion, tracking, DoFs (issue 12)
  /// Frames whose camera or points lie farther than this from the world origin are refused, metres
  /// (the `workspace:` section's radius_m).
  double workspace_radius_m = 1000.0;
};

/// Every value in range; the error names the key (the YAML section and name) that is not.
Status validate(const Config& config);

}  // namespace scenewatch::pipeline
