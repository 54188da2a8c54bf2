#include "scenewatch/planning/next_best_view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace scenewatch::planning {

Status validate(const NextBestViewRequest& r) {
  if (!r.target_world.valid()) return invalid_argument("target: the box is empty or not finite");
  if (auto st = validate(r.constraint); !st) return st;
  if (auto st = validate(r.volumetric); !st) return st;
  if (r.n < 1 || r.n > 1000) return invalid_argument("n: must be in [1, 1000], got " + std::to_string(r.n));
  if (!r.intrinsics.valid()) return invalid_argument("intrinsics: focal lengths and image size must be positive");
  if (!(r.motion_cost_per_m >= 0.0 && std::isfinite(r.motion_cost_per_m))) return invalid_argument("motion_cost_per_m: must be >= 0");
  for (const Eigen::Vector3d& p : r.target_surface_world) {
    if (!p.allFinite()) return invalid_argument("target surface: a point is not finite");
  }
  if (!r.target_surface_world.empty() && std::none_of(r.target_surface_world.begin(), r.target_surface_world.end(),
                                                      [&](const Eigen::Vector3d& p) { return r.target_world.contains(p); })) {
    return invalid_argument("target surface: none of its " + std::to_string(r.target_surface_world.size()) +
                            " points lies in the target box");
  }
  if (r.current_T_world_camera) {
    if (auto st = validate_rigid(r.current_T_world_camera->matrix()); !st) return invalid_argument("current pose: " + st.error().message);
  }
  return {};
}

Result<Aabb> planning_region(const NextBestViewRequest& r) {
  if (auto st = validate(r); !st) return st.error();
  auto poses = candidate_poses(r.constraint, r.target_world.center());
  if (!poses) return poses.error();
  Aabb region = r.target_world;
  for (const Pose& T : *poses) {
    const Eigen::Vector3d p = T.translation();
    region = region.united(Aabb{p, p});
  }
  return region.grown(0.1);
}

Result<NextBestViewAnswer> next_best_views(const background::DenseGrid& grid, const NextBestViewRequest& r) {
  if (auto st = validate(r); !st) return st.error();
  auto poses = candidate_poses(r.constraint, r.target_world.center());
  if (!poses) return poses.error();
  ViewScorer scorer(grid, r.target_world, r.volumetric, r.target_surface_world);
  NextBestViewAnswer answer;
  answer.measure = r.measure;
  answer.candidates = poses->size();
  answer.target_voxels = scorer.target_voxels();
  answer.coverage_now = scorer.coverage();
  std::vector<RankedView> views;
  views.reserve(poses->size());
  const std::size_t target_unknown = scorer.target_voxels() - scorer.target_known();
  for (const Pose& T : *poses) {
    RankedView v;
    v.T_world_camera = T;
    v.gain = scorer.score(T, r.intrinsics, r.measure);
    if (r.current_T_world_camera) v.motion_m = (T.translation() - r.current_T_world_camera->translation()).norm();
    v.score = v.gain.gain * std::exp(-r.motion_cost_per_m * v.motion_m);
    char why[256];
    std::snprintf(why, sizeof why,
                  "%s %.1f: reaches %zu of the target's %zu unknown voxels, %zu behind seen surfaces, %zu target voxels in "
                  "all; coverage %.2f -> %.2f; %.2f m to move",
                  to_string(r.measure), v.gain.gain, v.gain.unknown_reached, target_unknown, v.gain.rear_side,
                  v.gain.target_reached, answer.coverage_now, v.gain.expected_coverage, v.motion_m);
    v.why = why;
    views.push_back(std::move(v));
  }
  // Best first; ties (often zero gain) keep the candidates' order, so answers are deterministic.
  std::stable_sort(views.begin(), views.end(), [](const RankedView& a, const RankedView& b) { return a.score > b.score; });
  views.resize(std::min<std::size_t>(views.size(), static_cast<std::size_t>(r.n)));
  answer.views = std::move(views);
  // A surface whose voxels no candidate can still learn about (all known, or hidden from every
  // candidate) leaves every gain 0 and the ranking to the candidates' order: plan for its box.
  if (!r.target_surface_world.empty() && (answer.views.empty() || answer.views.front().gain.gain <= 0.0)) {
    NextBestViewRequest box = r;
    box.target_surface_world.clear();
    auto for_box = next_best_views(grid, box);
    if (!for_box) return for_box.error();
    for_box->surface_voxels = answer.target_voxels;
    for_box->surface_coverage = answer.coverage_now;
    for_box->planned_for_box = true;
    return for_box;
  }
  return answer;
}

namespace {

NextBestViewRequest around(const Aabb& box, Measure measure) {
  NextBestViewRequest r;
  r.target_world = box;
  r.measure = measure;
  r.constraint.kind = ConstraintKind::kCap;  // from above the table, not through it
  r.constraint.center_world = box.center();
  r.constraint.max_polar_deg = 75.0;
  return r;
}

}  // namespace

NextBestViewRequest confirm_event_request(const Aabb& event_box_world, double margin_m) {
  return around(event_box_world.grown(margin_m), Measure::kVisible);
}

NextBestViewRequest complete_object_request(const Aabb& object_box_world, double margin_m) {
  return around(object_box_world.grown(margin_m), Measure::kRearSideEntropy);
}

std::vector<Eigen::Vector3d> above_lowest_layer(const std::vector<Eigen::Vector3d>& surface, const Eigen::Vector3d& up,
                                                double layer_m) {
  double lowest = std::numeric_limits<double>::infinity();
  for (const auto& p : surface) lowest = std::min(lowest, p.dot(up));
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(surface.size());
  for (const auto& p : surface) {
    if (p.dot(up) >= lowest + layer_m) kept.push_back(p);
  }
  return kept;
}

NextBestViewRequest complete_surface_request(const Aabb& object_box_world, std::vector<Eigen::Vector3d> surface_world,
                                             double margin_m) {
  Aabb box = object_box_world;
  for (const Eigen::Vector3d& p : surface_world) box = box.united(Aabb{p, p});
  NextBestViewRequest r = around(box.grown(margin_m), Measure::kRearSideEntropy);
  r.constraint.center_world = object_box_world.center();
  r.target_surface_world = std::move(surface_world);
  return r;
}

}  // namespace scenewatch::planning
