// The pipeline's configuration checked key by key (config.h).
#include "scenewatch/pipeline/config.h"

#include <sstream>
#include <string>

namespace scenewatch::pipeline {

namespace {

std::string metres(double m) {
  std::ostringstream os;
  os << m << " m";
  return os.str();
}

}  // namespace

Status validate(const Config& c) {
  if (auto st = scenewatch::validate(c.sensor); !st) return st;
  if (auto st = background::validate(c.background); !st) return st;
  if (auto st = segmentation::validate(c.segmentation); !st) return st;
  if (!(c.tracking.match_distance_m > 0 && c.tracking.match_distance_m < 5)) return invalid_argument("tracking.match_distance_m: must be in (0, 5) m");
  if (!(c.tracking.gone_free_fraction > 0 && c.tracking.gone_free_fraction <= 1)) return invalid_argument("tracking.gone_free_fraction: must be in (0, 1]");
  if (c.tracking.confirm_frames < 1 || c.tracking.confirm_frames > 100) return invalid_argument("tracking.confirm_frames: must be in [1, 100]");
  if (!(c.tracking.min_extent_cells >= 0 && c.tracking.min_extent_cells <= 100))
    return invalid_argument("tracking.min_extent_cells: must be in [0, 100]");
  if (c.tracking.gone_frames < 1 || c.tracking.gone_frames > 100) return invalid_argument("tracking.gone_frames: must be in [1, 100]");
  if (!(c.tracking.max_range_m > 0 && c.tracking.max_range_m <= 20)) return invalid_argument("tracking.max_range_m: must be in (0, 20] m");
  if (c.tracking.segmentation_stride_px < 1 || c.tracking.segmentation_stride_px > 8)
    return invalid_argument("tracking.segmentation_stride_px: must be in [1, 8]");
  if (c.max_event_log < 1) return invalid_argument("events.max_log: must be >= 1");
  if (c.fusion.persistence_frames < 1 || c.fusion.persistence_frames > 100) return invalid_argument("events.appearance_persistence_frames: must be in [1, 100]");
  if (!(c.fusion.match_m > 0 && c.fusion.match_m <= 1)) return invalid_argument("events.appearance_match_m: must be in (0, 1] m");
  if (!(c.fusion.margin_m >= 0 && c.fusion.margin_m <= 1)) return invalid_argument("events.merge_margin_m: must be in [0, 1] m");
  if (c.fusion.zone_frames < 0 || c.fusion.zone_frames > 100000) return invalid_argument("events.silence_frames: must be in [0, 100000]");
  if (!(c.workspace_radius_m > 0 && c.workspace_radius_m <= 100000))
    return invalid_argument("workspace.radius_m: must be in (0, 100000] m, got " + metres(c.workspace_radius_m));
  if (auto st = background::validate(c.appearance); !st) return st;
  if (auto st = surprise::validate(c.surprise); !st) return st;
  if (auto st = change::validate(c.change); !st) return st;
  if (auto st = foreground::validate(c.foreground); !st) return st;
  if (auto st = localization::validate(c.localization); !st) return st;
  return {};
}

}  // namespace scenewatch::pipeline
