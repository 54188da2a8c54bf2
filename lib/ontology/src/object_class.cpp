#include "scenewatch/ontology/object_class.h"

#include <algorithm>
#include <cmath>

namespace scenewatch::ontology {
namespace {

Error bad(const ObjectClass& c, const std::string& field, const std::string& what) {
  return invalid_argument("class '" + c.name + "': " + field + " " + what);
}

Status check_range(const ObjectClass& c, const std::string& field, const Range& r, double lo, double hi) {
  if (!std::isfinite(r.min) || !std::isfinite(r.max)) return bad(c, field, "must be finite");
  if (r.min > r.max) return bad(c, field, "min must be <= max");
  if (r.min < lo || r.max > hi) {
    return bad(c, field, "must lie in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return {};
}

}  // namespace

const char* to_string(ClassShape shape) {
  switch (shape) {
    case ClassShape::kCylinder: return "cylinder";
    case ClassShape::kFrustum: return "frustum";
    case ClassShape::kSphere: return "sphere";
    case ClassShape::kBox: return "box";
  }
  return "unknown";
}

const char* to_string(GraspKind kind) {
  switch (kind) {
    case GraspKind::kSide: return "side";
    case GraspKind::kRim: return "rim";
    case GraspKind::kTop: return "top";
  }
  return "unknown";
}

Status validate(const ObjectClass& c) {
  if (c.name.empty() || c.name.size() > 64) return invalid_argument("class name: must have 1 to 64 characters");
  for (const char ch : c.name) {
    if (!((ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_')) {
      return invalid_argument("class '" + c.name + "': name may only hold a-z, 0-9 and _");
    }
  }
  if (c.name == "unknown") return invalid_argument("class 'unknown': the name is reserved for unclassified objects");
  // Household objects: 5 mm .. 2 m.
  constexpr double kMinM = 0.005, kMaxM = 2.0;
  switch (c.shape) {
    case ClassShape::kFrustum:
      if (Status s = check_range(c, "taper_deg", c.taper_deg, -45, 45); !s) return s;
      [[fallthrough]];
    case ClassShape::kCylinder:
      if (Status s = check_range(c, "radius_m", c.radius_m, kMinM, kMaxM); !s) return s;
      if (Status s = check_range(c, "height_m", c.height_m, kMinM, kMaxM); !s) return s;
      break;
    case ClassShape::kSphere:
      if (Status s = check_range(c, "radius_m", c.radius_m, kMinM, kMaxM); !s) return s;
      break;
    case ClassShape::kBox:
      if (Status s = check_range(c, "height_m", c.height_m, kMinM, kMaxM); !s) return s;
      if (c.size_m.size() != 2) return bad(c, "size_m", "needs 2 ranges (shorter and longer horizontal edge)");
      for (std::size_t i = 0; i < 2; ++i) {
        if (Status s = check_range(c, "size_m[" + std::to_string(i) + "]", c.size_m[i], kMinM, kMaxM); !s) return s;
      }
      break;
  }
  if (c.shape != ClassShape::kBox && !c.size_m.empty()) return bad(c, "size_m", "is only for a box");
  if (!(c.axis_tolerance_deg >= 0 && c.axis_tolerance_deg <= 90)) return bad(c, "axis_tolerance_deg", "must be in [0, 90]");
  if (!(c.max_rms_m > 0 && c.max_rms_m <= 0.05)) return bad(c, "max_rms_m", "must be in (0, 0.05]");
  if (!(c.min_explained >= 0 && c.min_explained <= 1)) return bad(c, "min_explained", "must be in [0, 1]");
  if (!(c.min_coverage_deg >= 0 && c.min_coverage_deg <= 360)) return bad(c, "min_coverage_deg", "must be in [0, 360]");
  if (c.top != ClassTop::kAny && c.shape != ClassShape::kCylinder && c.shape != ClassShape::kFrustum) {
    return bad(c, "top", "is only for a cylinder or frustum");
  }
  for (std::size_t i = 0; i < c.grasps.size(); ++i) {
    const GraspDefinition& g = c.grasps[i];
    const std::string field = "grasps[" + std::to_string(i) + "]";
    if (g.name.empty()) return bad(c, field + ".name", "must not be empty");
    if (!(g.height_fraction >= 0 && g.height_fraction <= 1)) return bad(c, field + ".height_fraction", "must be in [0, 1]");
    if (g.kind == GraspKind::kRim && c.shape != ClassShape::kCylinder && c.shape != ClassShape::kFrustum) {
      return bad(c, field + ".kind", "rim needs a cylinder or frustum");
    }
    for (std::size_t j = 0; j < i; ++j)
      if (c.grasps[j].name == g.name) return bad(c, field + ".name", "'" + g.name + "' is used twice");
  }
  static const char* kDofs[] = {"x", "y", "z", "roll", "pitch", "yaw"};
  for (std::size_t i = 0; i < c.allowed_dofs.size(); ++i) {
    const std::string& d = c.allowed_dofs[i];
    if (std::find(std::begin(kDofs), std::end(kDofs), d) == std::end(kDofs)) {
      return bad(c, "allowed_dofs[" + std::to_string(i) + "]", "'" + d + "' is not one of x, y, z, roll, pitch, yaw");
    }
    for (std::size_t j = 0; j < i; ++j)
      if (c.allowed_dofs[j] == d) return bad(c, "allowed_dofs", "lists '" + d + "' twice");
  }
  return {};
}

}  // namespace scenewatch::ontology
