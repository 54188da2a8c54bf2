#include "scenewatch/planning/candidates.h"

#include <cmath>
#include <string>

namespace scenewatch::planning {

namespace {

constexpr double kGoldenAngle = M_PI * (3.0 - 2.23606797749979);  // pi (3 - sqrt 5)

// Points spread evenly over the band of the unit sphere with z in [z_min, 1] (equal areas per
// point: z uniform), in a frame whose z axis is `up`.
std::vector<Eigen::Vector3d> fibonacci_band(int count, double z_min, const Eigen::Vector3d& up) {
  const Eigen::Quaterniond to_up = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), up.normalized());
  std::vector<Eigen::Vector3d> out;
  out.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (1.0 - z_min) * (i + 0.5) / count;
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = kGoldenAngle * i;
    out.push_back(to_up * Eigen::Vector3d(rho * std::cos(phi), rho * std::sin(phi), z));
  }
  return out;
}

}  // namespace

const char* to_string(ConstraintKind kind) {
  switch (kind) {
    case ConstraintKind::kSphere: return "sphere";
    case ConstraintKind::kShell: return "shell";
    case ConstraintKind::kCap: return "cap";
    case ConstraintKind::kList: return "list";
  }
  return "sphere";
}

Status validate(const ViewConstraint& c) {
  auto bad = [](const std::string& field, const std::string& why) { return invalid_argument("constraint." + field + ": " + why); };
  if (!c.center_world.allFinite()) return bad("center", "must be finite");
  if (c.kind == ConstraintKind::kList) {
    if (c.poses.empty()) return bad("poses", "a list constraint needs at least one pose");
    for (std::size_t i = 0; i < c.poses.size(); ++i) {
      if (auto st = validate_rigid(c.poses[i].matrix()); !st) return bad("poses[" + std::to_string(i) + "]", st.error().message);
    }
    return {};
  }
  if (!(c.radius_max_m > 0.0 && c.radius_max_m <= 20.0)) return bad("radius_max_m", "must be in (0, 20] m");
  if (c.kind == ConstraintKind::kShell && !(c.radius_min_m > 0.0 && c.radius_min_m <= c.radius_max_m)) {
    return bad("radius_min_m", "must be in (0, radius_max_m]");
  }
  if (!(c.samples >= 1 && c.samples <= 100000)) return bad("samples", "must be in [1, 100000]");
  if (c.kind == ConstraintKind::kCap) {
    if (!(c.max_polar_deg > 0.0 && c.max_polar_deg <= 180.0)) return bad("max_polar_deg", "must be in (0, 180]");
    if (!(c.up_world.allFinite() && c.up_world.norm() > 1e-9)) return bad("up", "must be a finite non-zero vector");
  }
  return {};
}

std::vector<Eigen::Vector3d> fibonacci_directions(int count) { return fibonacci_band(count, -1.0, Eigen::Vector3d::UnitZ()); }

Result<std::vector<Pose>> candidate_poses(const ViewConstraint& c, const Eigen::Vector3d& target) {
  if (auto st = validate(c); !st) return st.error();
  if (c.kind == ConstraintKind::kList) return c.poses;
  const double z_min = c.kind == ConstraintKind::kCap ? std::cos(c.max_polar_deg * M_PI / 180.0) : -1.0;
  const Eigen::Vector3d up = c.kind == ConstraintKind::kCap ? c.up_world.normalized() : Eigen::Vector3d::UnitZ();
  std::vector<Pose> out;
  out.reserve(static_cast<std::size_t>(c.samples));
  const std::vector<Eigen::Vector3d> dirs = fibonacci_band(c.samples, z_min, up);
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    double r = c.radius_max_m;
    if (c.kind == ConstraintKind::kShell) {
      // Radii spread by the golden ratio's fractional parts, so neighbouring directions differ.
      const double u = std::fmod(0.5 + 0.6180339887498949 * static_cast<double>(i), 1.0);
      r = c.radius_min_m + (c.radius_max_m - c.radius_min_m) * u;
    }
    out.push_back(look_at(c.center_world + r * dirs[i], target, up));
  }
  return out;
}

}  // namespace scenewatch::planning
