// The dense-grid ray caster against a slow reference (fine ray marching through index_of), and the
// measures on a grid with a known front and an unknown back.
#include <gtest/gtest.h>

#include <set>

#include "scenewatch/planning/next_best_view.h"
#include "scenewatch/planning/volumetric.h"

namespace scenewatch::planning {
namespace {

using background::DenseGrid;
using background::Occupancy;

const Intrinsics kIntrinsics{131.25, 131.25, 79.5, 59.5, 160, 120};

// A 1.6 m cube of 2 cm voxels, free, holding an object box [-0.1, 0.1]^3 whose -x face (one
// voxel deep) is occupied and whose inside is unknown: seen from -x only.
DenseGrid front_seen_object() {
  DenseGrid g;
  g.resolution = 0.02;
  g.nx = g.ny = g.nz = 80;
  g.origin = Eigen::Vector3d::Constant(-0.8);
  g.state.assign(g.nx * g.ny * g.nz, static_cast<std::uint8_t>(Occupancy::kFree));
  for (std::size_t i = 0; i < g.size(); ++i) {
    const Eigen::Vector3d c = g.center(static_cast<long>(i));
    if ((c.array().abs() < 0.1).all()) {
      const bool face = c.x() < -0.08;
      g.state[i] = static_cast<std::uint8_t>(face ? Occupancy::kOccupied : Occupancy::kUnknown);
      if (face) g.occupied.push_back({i, 0, 240});
    }
  }
  return g;
}

const Aabb kObject{Eigen::Vector3d::Constant(-0.1), Eigen::Vector3d::Constant(0.1)};

// The reference: march each ray in steps of 1/200 voxel, stop at an occupied voxel; the distinct
// unknown target voxels met.
std::size_t reference_unknown_reached(const DenseGrid& g, const Aabb& target, const Pose& T, const Intrinsics& K,
                                      const VolumetricConfig& cfg) {
  std::set<long> seen;
  for (int ry = 0; ry < cfg.rays_y; ++ry)
    for (int rx = 0; rx < cfg.rays_x; ++rx) {
      const double u = (rx + 0.5) * K.width / cfg.rays_x, v = (ry + 0.5) * K.height / cfg.rays_y;
      const Eigen::Vector3d d((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const double t_max = cfg.max_range_m * d.norm();
      const Eigen::Vector3d dir = T.linear() * d.normalized();
      for (double t = 0.0; t < t_max; t += g.resolution / 200) {
        const Eigen::Vector3d p = T.translation() + t * dir;
        const long i = g.index_of(p);
        if (i < 0) continue;
        if (g.at(i) == Occupancy::kOccupied) break;
        if (g.at(i) == Occupancy::kUnknown && target.contains(g.center(i))) seen.insert(i);
      }
    }
  return seen.size();
}

TEST(ViewScorer, AgreesWithFineRayMarching) {
  const DenseGrid g = front_seen_object();
  VolumetricConfig cfg;
  cfg.rays_x = 40;
  cfg.rays_y = 30;
  ViewScorer scorer(g, kObject, cfg);
  for (const Eigen::Vector3d& eye : {Eigen::Vector3d(0.6, 0.1, 0.2), Eigen::Vector3d(-0.6, 0.0, 0.1), Eigen::Vector3d(0.1, 0.5, 0.4)}) {
    const Pose T = look_at(eye, Eigen::Vector3d::Zero());
    const ViewGain gain = scorer.score(T, kIntrinsics, Measure::kUnobserved);
    const std::size_t reference = reference_unknown_reached(g, kObject, T, kIntrinsics, cfg);
    // Marching can step over the corner of a voxel that the exact traversal enters: a few per mille.
    EXPECT_NEAR(static_cast<double>(gain.unknown_reached), static_cast<double>(reference), 0.01 * reference + 2)
        << eye.transpose();
  }
}

TEST(ViewScorer, RearSideMeasuresSeeTheBackFromBehindOnly) {
  const DenseGrid g = front_seen_object();
  ViewScorer scorer(g, kObject);
  const Pose front = look_at(Eigen::Vector3d(-0.6, 0, 0), Eigen::Vector3d::Zero());
  const Pose back = look_at(Eigen::Vector3d(0.6, 0, 0), Eigen::Vector3d::Zero());
  const ViewGain f = scorer.score(front, kIntrinsics, Measure::kRearSideEntropy);
  const ViewGain b = scorer.score(back, kIntrinsics, Measure::kRearSideEntropy);
  EXPECT_EQ(f.unknown_reached, 0u);  // the occupied face stops every ray
  EXPECT_EQ(f.rear_side, 0u);
  EXPECT_EQ(f.gain, 0.0);
  // From behind, rays cross the unknown inside and end on the face from its back: at most the
  // 10 x 10 unknown voxels just behind the face, most of them reached by 80 x 60 rays.
  EXPECT_GT(b.rear_side, 60u);
  EXPECT_LE(b.rear_side, 100u);
  EXPECT_GT(b.gain, static_cast<double>(b.rear_side));
  EXPECT_EQ(scorer.target_voxels(), 1000u);
  EXPECT_EQ(scorer.target_known(), 100u);
  EXPECT_NEAR(b.expected_coverage, (100.0 + b.unknown_reached) / 1000.0, 1e-12);
  // Repeated calls give the same answer (the stamps do not leak between calls).
  const ViewGain again = scorer.score(back, kIntrinsics, Measure::kRearSideEntropy);
  EXPECT_EQ(again.rear_side, b.rear_side);
  EXPECT_EQ(again.gain, b.gain);
}

TEST(NextBestView, RanksTheBackFirstAndDiscountsMotion) {
  const DenseGrid g = front_seen_object();
  NextBestViewRequest r;
  r.target_world = kObject;
  r.constraint.center_world = Eigen::Vector3d::Zero();
  r.constraint.radius_max_m = 0.6;
  r.constraint.samples = 32;
  r.n = 3;
  r.intrinsics = kIntrinsics;
  for (Measure m : {Measure::kUnobserved, Measure::kRearSide, Measure::kRearSideEntropy, Measure::kOcclusionAware}) {
    r.measure = m;
    auto a = next_best_views(g, r);
    ASSERT_TRUE(a) << a.error().message;
    ASSERT_EQ(a->views.size(), 3u);
    EXPECT_EQ(a->candidates, 32u);
    EXPECT_GT(a->views[0].score, 0.0) << to_string(m);
    EXPECT_GE(a->views[0].score, a->views[1].score);
    // Best views look from the unseen +x half (for unobserved, side views reach all 900 unknown
    // voxels too and tie with views from behind).
    EXPECT_GT(a->views[0].T_world_camera.translation().x(), 0.1) << to_string(m) << ": " << a->views[0].why;
    EXPECT_FALSE(a->views[0].why.empty());
  }
  // With a steep motion cost and the camera at the front, a view nearer the front wins.
  r.measure = Measure::kUnobserved;
  r.current_T_world_camera = look_at(Eigen::Vector3d(-0.6, 0, 0), Eigen::Vector3d::Zero());
  r.motion_cost_per_m = 0.0;
  const double x_free = next_best_views(g, r)->views[0].T_world_camera.translation().x();
  r.motion_cost_per_m = 8.0;
  const auto costly = next_best_views(g, r);
  EXPECT_LT(costly->views[0].T_world_camera.translation().x(), x_free);
  EXPECT_GT(costly->views[0].motion_m, 0.0);
  // Bad requests are errors naming the field.
  r.n = 0;
  EXPECT_NE(next_best_views(g, r).error().message.find("n:"), std::string::npos);
}

TEST(NextBestView, ParsesMeasures) {
  for (Measure m : {Measure::kUnobserved, Measure::kRearSide, Measure::kRearSideEntropy, Measure::kOcclusionAware, Measure::kVisible}) {
    EXPECT_EQ(*parse_measure(to_string(m)), m);
  }
  EXPECT_FALSE(parse_measure("entropy"));
}

}  // namespace
}  // namespace scenewatch::planning
