// A class's checks on the fitted primitive, each failure named with the measured value.
#include "scenewatch/ontology/classify.h"

#include <cstdio>

namespace scenewatch::ontology {
namespace {

std::string mm(double m) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", m * 1000);
  return b;
}

std::string outside(const char* what, double value_m, const Range& r) {
  return std::string(what) + " " + mm(value_m) + " mm outside [" + mm(r.min) + ", " + mm(r.max) + "] mm";
}

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

}  // namespace

ClassMatch match_class(const ObjectClass& c, const ShapeFit& fit, const std::vector<Eigen::Vector3d>& points,
                       const std::vector<Eigen::Vector3d>& normals) {
  ClassMatch m;
  m.class_name = c.name;
  m.fit = fit;
  m.score = explained_fraction(fit, points, normals, 2 * c.max_rms_m);
  auto refuse = [&](std::string why) {
    m.reason = std::move(why);
    return m;
  };
  if (c.axis == ClassAxis::kUpright && c.shape != ClassShape::kSphere && fit.axis_tilt_deg > c.axis_tolerance_deg) {
    return refuse("axis " + fmt(fit.axis_tilt_deg) + " deg from upright (tolerance " + fmt(c.axis_tolerance_deg) + ")");
  }
  switch (c.shape) {
    case ClassShape::kFrustum:
      if (!c.taper_deg.contains(fit.taper_deg)) {
        return refuse("taper " + fmt(fit.taper_deg) + " deg outside [" + fmt(c.taper_deg.min) + ", " + fmt(c.taper_deg.max) + "] deg");
      }
      [[fallthrough]];
    case ClassShape::kCylinder:
      if (!c.radius_m.contains(fit.radius_m)) return refuse(outside("radius", fit.radius_m, c.radius_m));
      if (!c.height_m.contains(fit.height_m)) return refuse(outside("height", fit.height_m, c.height_m));
      break;
    case ClassShape::kSphere:
      if (!c.radius_m.contains(fit.radius_m)) return refuse(outside("radius", fit.radius_m, c.radius_m));
      // A ball shows at least its upper half from any view above it: a flatter patch is the cap
      // of something else (a short can's rim and top).
      if (fit.height_m < fit.radius_m) {
        return refuse("points span " + mm(fit.height_m) + " mm vertically, less than the radius " + mm(fit.radius_m) + " mm");
      }
      break;
    case ClassShape::kBox:
      if (!c.height_m.contains(fit.height_m)) return refuse(outside("height", fit.height_m, c.height_m));
      if (!c.size_m[0].contains(fit.size_m.x())) return refuse(outside("shorter side", fit.size_m.x(), c.size_m[0]));
      if (!c.size_m[1].contains(fit.size_m.y())) return refuse(outside("longer side", fit.size_m.y(), c.size_m[1]));
      if (fit.side_alignment < kBoxMinSideAlignment) {
        return refuse("side normals align " + fmt(fit.side_alignment) + " with two perpendicular faces, below " + fmt(kBoxMinSideAlignment));
      }
      break;
  }
  if (fit.rms_m > c.max_rms_m) return refuse("rms " + mm(fit.rms_m) + " mm above " + mm(c.max_rms_m) + " mm");
  if (c.shape != ClassShape::kBox && fit.coverage_deg < c.min_coverage_deg) {
    return refuse("coverage " + fmt(fit.coverage_deg) + " deg below " + fmt(c.min_coverage_deg) + " deg");
  }
  const bool open = fit.inner_fraction >= kOpenTopMinInnerFraction;
  if (c.top == ClassTop::kOpen && !open) return refuse("top not seen open (inside wall " + fmt(fit.inner_fraction) + " of the points)");
  if (c.top == ClassTop::kClosed && open) return refuse("top open (inside wall " + fmt(fit.inner_fraction) + " of the points)");
  if (m.score < c.min_explained) return refuse("explains " + fmt(m.score) + " of the points, below " + fmt(c.min_explained));
  m.accepted = true;
  return m;
}

}  // namespace scenewatch::ontology
