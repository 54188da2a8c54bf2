// The dense-grid ray caster against a slow reference (fine ray marching through index_of), and the
// measures on a grid with a known front and an unknown back.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "scenewatch/planning/next_best_view.h"
#include "scenewatch/planning/volumetric.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"

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

// The voxel centres of the object box's outer layer (a completed box primitive: 488 of its 1000 voxels).
std::vector<Eigen::Vector3d> object_shell() {
  std::vector<Eigen::Vector3d> shell;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 10; ++k) {
        if (i % 9 && j % 9 && k % 9) continue;
        shell.push_back(Eigen::Vector3d(i, j, k) * 0.02 - Eigen::Vector3d::Constant(0.09));
      }
  return shell;
}

// A surface narrows the target to its voxels: the object's inside is unknown but not the object's
// surface, so it counts for nothing, yet rays still cross it to the face seen from the front.
TEST(ViewScorer, ASurfaceNarrowsTheTargetToItsVoxels) {
  const DenseGrid g = front_seen_object();
  ViewScorer box(g, kObject), surface(g, kObject, {}, object_shell());
  EXPECT_EQ(surface.target_voxels(), 488u);
  EXPECT_EQ(surface.target_known(), 100u);  // the -x face, seen
  const Pose front = look_at(Eigen::Vector3d(-0.6, 0, 0), Eigen::Vector3d::Zero());
  const Pose back = look_at(Eigen::Vector3d(0.6, 0, 0), Eigen::Vector3d::Zero());
  EXPECT_EQ(surface.score(front, kIntrinsics, Measure::kRearSideEntropy).gain, 0.0);
  const ViewGain b_box = box.score(back, kIntrinsics, Measure::kRearSideEntropy);
  const ViewGain b = surface.score(back, kIntrinsics, Measure::kRearSideEntropy);
  // From behind, each ray crosses the +x face, then the unknown inside, and ends on the -x face:
  // the last surface voxels before it are the rear side now (measured: 72, the +x face's 8 x 8
  // inner voxels and a few of the sides'), not the inside's 100 just behind the -x face. Every
  // unknown surface voxel is reached (488 - 100); the rear-side entropy counts 255 of them, the
  // box's 767 (the inside's voxels too).
  EXPECT_GE(b.rear_side, 64u);
  EXPECT_LE(b.rear_side, 100u);
  EXPECT_EQ(b.unknown_reached, 388u);
  EXPECT_EQ(b_box.unknown_reached, 900u);
  EXPECT_GT(b.gain, 240.0);
  EXPECT_LT(b.gain, 0.4 * b_box.gain);
  EXPECT_NEAR(b.expected_coverage, (100.0 + b.unknown_reached) / 488.0, 1e-12);
  // Points outside the box are left out; none in it leaves no target.
  ViewScorer none(g, kObject, {}, {Eigen::Vector3d(0.5, 0.5, 0.5)});
  EXPECT_EQ(none.target_voxels(), 0u);
  EXPECT_EQ(none.score(back, kIntrinsics, Measure::kRearSideEntropy).gain, 0.0);
}

// A free voxel seen free too few times to be settled carries its entropy, and may hide what lies
// behind it; a settled one carries none. The object box of front_seen_object() seen from +x, its
// two layers nearest the camera free (the rest stays as it was: unknown inside, an occupied -x face).
TEST(ViewScorer, UncertainFreeVoxelsCarryTheirEntropyAndDimWhatIsBehind) {
  DenseGrid settled = front_seen_object();
  for (std::size_t i = 0; i < settled.size(); ++i) {
    const Eigen::Vector3d c = settled.center(static_cast<long>(i));
    if ((c.array().abs() < 0.1).all() && c.x() > 0.06) settled.state[i] = static_cast<std::uint8_t>(Occupancy::kFree);
  }
  DenseGrid uncertain = settled;
  constexpr std::uint8_t kP = 102;  // p = 0.4: seen free once (OctoMap's miss, log-odds -0.4)
  std::size_t listed = 0;
  for (std::size_t i = 0; i < uncertain.size(); ++i) {
    const Eigen::Vector3d c = uncertain.center(static_cast<long>(i));
    if ((c.array().abs() < 0.1).all() && c.x() > 0.06) {
      uncertain.uncertain_free.push_back({i, 0, kP});
      ++listed;
    }
  }
  ASSERT_EQ(listed, 200u);
  const Pose back = look_at(Eigen::Vector3d(0.6, 0.0, 0.0), Eigen::Vector3d::Zero());
  ViewScorer settled_scorer(settled, kObject), uncertain_scorer(uncertain, kObject);
  const ViewGain s = settled_scorer.score(back, kIntrinsics, Measure::kOcclusionAware);
  const ViewGain u = uncertain_scorer.score(back, kIntrinsics, Measure::kOcclusionAware);
  // The same voxels reached and counted as unknown: an uncertain voxel is free.
  EXPECT_EQ(u.unknown_reached, s.unknown_reached);
  EXPECT_EQ(u.target_reached, s.target_reached);
  EXPECT_GT(s.unknown_reached, 100u);
  // Settled free voxels carry no entropy: only the unknown ones, one bit each, and the occupied
  // face's voxels reached through them from behind, H(240/255) each.
  const double q = 240.0 / 255.0, h_face = -(q * std::log2(q) + (1 - q) * std::log2(1 - q));
  const double faces = (s.entropy_bits - static_cast<double>(s.unknown_reached)) / h_face;
  EXPECT_NEAR(faces, std::round(faces), 1e-6);
  EXPECT_LE(faces, 100.0 + 1e-6);
  // Each uncertain voxel reached adds H(0.4) = 0.971 bits; most of the 200 are reached.
  const double p = kP / 255.0, h = -(p * std::log2(p) + (1 - p) * std::log2(1 - p));
  const double uncertain_reached = (u.entropy_bits - s.entropy_bits) / h;
  EXPECT_NEAR(uncertain_reached, std::round(uncertain_reached), 1e-6);
  EXPECT_GT(uncertain_reached, 150.0);
  EXPECT_LE(uncertain_reached, 200.0 + 1e-6);
  // Every ray enters the box through the two uncertain layers (or three, slanting): the unknown
  // inside weighs at most 0.6^2 = 0.36 of what it weighs behind settled free space, and at least
  // 0.6^3; the uncertain voxels add at most their own entropy each.
  EXPECT_LE(u.gain, uncertain_reached * h + 0.36 * s.gain + 1e-9);
  EXPECT_GE(u.gain, 0.216 * s.gain);
  std::printf("from behind: %zu unknown voxels, %.0f uncertain free; occlusion-aware %.1f settled, %.1f uncertain\n",
              s.unknown_reached, uncertain_reached, s.gain, u.gain);
}

// The 2 cm map of the simulator's clutter table from two 640x480 frames (scenewatch-bench's speed
// case), over the planning region of a request for the whole table.
DenseGrid clutter_table_grid(NextBestViewRequest& r) {
  auto scenario = sim::load_scenario(std::string(SCENEWATCH_SOURCE_DIR) + "/sample_clouds/scenarios/clutter.yaml");
  EXPECT_TRUE(scenario) << scenario.error().message;
  const sim::Scenario vga = sim::with_resolution(*scenario, 640, 480);
  auto simulator = sim::Simulator::create(vga);
  EXPECT_TRUE(simulator) << simulator.error().message;
  background::OccupancyMap map;
  for (int f : {0, 45}) {
    auto frame = sim::as_frame(simulator->render(0, f), vga.intrinsics, f / 30.0);
    EXPECT_TRUE(frame);
    map.insert(*frame->cloud, frame->pose_or_identity(), 2);
  }
  r.target_world = Aabb{Eigen::Vector3d(-0.45, -0.35, 0.75), Eigen::Vector3d(0.45, 0.35, 1.05)};
  r.constraint.kind = ConstraintKind::kCap;
  r.constraint.center_world = r.target_world.center();
  r.constraint.radius_max_m = 0.9;
  r.intrinsics = vga.intrinsics;
  DenseGrid g;
  EXPECT_TRUE(map.fill_dense_grid(*planning_region(r), g, std::size_t{1} << 26, /*with_uncertain_free=*/true));
  EXPECT_GT(g.uncertain_free.size(), 1000u) << "two frames leave much of the space they freed unsettled";
  return g;
}

// Every field of score() equals the reference walk's, for every measure; the sums (entropy,
// occlusion-aware) to within their summation order. Returns how many views reached the target.
int expect_same_as_reference(ViewScorer& scorer, const std::vector<Pose>& poses, const Intrinsics& K) {
  int reaching = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    for (Measure m : {Measure::kUnobserved, Measure::kRearSide, Measure::kRearSideEntropy, Measure::kOcclusionAware, Measure::kVisible}) {
      const ViewGain fast = scorer.score(poses[i], K, m);
      const ViewGain ref = scorer.score_reference(poses[i], K, m);
      SCOPED_TRACE(testing::Message() << "view " << i << " at " << poses[i].translation().transpose() << ", " << to_string(m));
      EXPECT_EQ(fast.unknown_reached, ref.unknown_reached);
      EXPECT_EQ(fast.rear_side, ref.rear_side);
      EXPECT_EQ(fast.target_reached, ref.target_reached);
      EXPECT_NEAR(fast.gain, ref.gain, 1e-12 * std::max(1.0, std::abs(ref.gain)));
      EXPECT_NEAR(fast.entropy_bits, ref.entropy_bits, 1e-12 * std::max(1.0, ref.entropy_bits));
      EXPECT_EQ(fast.expected_coverage, ref.expected_coverage);
      EXPECT_LE(fast.steps, ref.steps);
      if (m == Measure::kVisible && ref.target_reached > 0) ++reaching;
    }
  }
  return reaching;
}

TEST(ViewScorer, GivesTheReferenceWalksGainsOnTheClutterTable) {
  NextBestViewRequest r;
  const DenseGrid g = clutter_table_grid(r);
  ViewScorer scorer(g, r.target_world, r.volumetric);
  std::vector<Pose> poses = candidate_poses(r.constraint, r.target_world.center()).value();  // the 64 of the cap
  ViewConstraint sphere;  // all round, some from below the table, some outside the grid
  sphere.center_world = r.target_world.center();
  for (const auto& [radius, samples] : {std::pair{0.6, 48}, std::pair{1.6, 16}}) {
    sphere.radius_max_m = radius;
    sphere.samples = samples;
    const std::vector<Pose> more = candidate_poses(sphere, sphere.center_world).value();
    poses.insert(poses.end(), more.begin(), more.end());
  }
  // Cameras inside the target box, looking along the axes and askew.
  for (const Eigen::Vector3d& at : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(1, 1, 1)}) {
    poses.push_back(look_at(r.target_world.center(), r.target_world.center() + at));
  }
  EXPECT_GT(expect_same_as_reference(scorer, poses, r.intrinsics), 100);
}

TEST(ViewScorer, GivesTheReferenceWalksGainsOnAMixedGrid) {
  // Free, unknown and occupied voxels, in uniform and mixed patches, around the object, which sits at the grid's
  // side so that the target box is clipped by the grid; a second scorer with a target entirely
  // outside the grid counts nothing.
  DenseGrid g = front_seen_object();
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  g.occupied.clear();
  // Cells of 5 voxels a side (across the scorer's blocks): all free, all unknown or mixed.
  std::vector<double> cell(16 * 16 * 16);
  for (double& c : cell) c = u(rng);
  for (std::size_t i = 0; i < g.size(); ++i) {
    const long x_cell = static_cast<long>(i % 80) / 5, y_cell = static_cast<long>(i / 80 % 80) / 5, z_cell = static_cast<long>(i / 6400) / 5;
    const double c = cell[static_cast<std::size_t>((z_cell * 16 + y_cell) * 16 + x_cell)];
    const double x = c < 0.4 ? 0.5 : c < 0.7 ? 0.1 : u(rng);
    const Occupancy s = x < 0.015 ? Occupancy::kOccupied : x < 0.2 ? Occupancy::kUnknown : Occupancy::kFree;
    if (g.center(static_cast<long>(i)).norm() > 0.2) g.state[i] = static_cast<std::uint8_t>(s);
    if (g.at(static_cast<long>(i)) == Occupancy::kOccupied) g.occupied.push_back({i, 0, static_cast<std::uint8_t>(128 + i % 127)});
  }
  const Aabb target{Eigen::Vector3d(-0.13, -0.71, -0.1), Eigen::Vector3d(0.3, 0.1, 0.17)};
  ViewScorer scorer(g, target);
  ViewConstraint sphere;
  sphere.center_world = target.center();
  sphere.samples = 40;
  std::vector<Pose> poses;
  for (double radius : {0.3, 0.7}) {
    sphere.radius_max_m = radius;
    const std::vector<Pose> more = candidate_poses(sphere, target.center()).value();
    poses.insert(poses.end(), more.begin(), more.end());
  }
  EXPECT_GT(expect_same_as_reference(scorer, poses, kIntrinsics), 60);
  // A surface of scattered points in the box: the voxels between them pass rays on.
  std::vector<Eigen::Vector3d> surface(1500);
  for (auto& p : surface) p = target.min + (target.max - target.min).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
  ViewScorer sparse(g, target, {}, surface);
  EXPECT_GT(sparse.target_voxels(), 500u);
  EXPECT_LT(sparse.target_voxels(), scorer.target_voxels() / 2);
  EXPECT_GT(expect_same_as_reference(sparse, poses, kIntrinsics), 60);
  ViewScorer outside(g, Aabb{Eigen::Vector3d(2, 2, 2), Eigen::Vector3d(2.5, 2.5, 2.5)});
  EXPECT_EQ(expect_same_as_reference(outside, poses, kIntrinsics), 0);
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
  // A surface that is all known (the -x face) gives no candidate anything: the box is planned for.
  r.measure = Measure::kRearSideEntropy;
  r.current_T_world_camera.reset();
  for (const Eigen::Vector3d& p : object_shell()) {
    if (p.x() < -0.08) r.target_surface_world.push_back(p);
  }
  const auto known = next_best_views(g, r);
  ASSERT_TRUE(known) << known.error().message;
  EXPECT_TRUE(known->planned_for_box);
  EXPECT_EQ(known->surface_voxels, 100u);
  EXPECT_EQ(known->surface_coverage, 1.0);
  EXPECT_EQ(known->target_voxels, 1000u);
  EXPECT_GT(known->views[0].T_world_camera.translation().x(), 0.1) << known->views[0].why;
  // The unseen +x face gives the views from behind, and no fallback.
  r.target_surface_world.clear();
  for (const Eigen::Vector3d& p : object_shell()) {
    if (p.x() > 0.08) r.target_surface_world.push_back(p);
  }
  const auto back = next_best_views(g, r);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_FALSE(back->planned_for_box);
  EXPECT_EQ(back->target_voxels, 100u);
  EXPECT_EQ(back->coverage_now, 0.0);
  EXPECT_GT(back->views[0].T_world_camera.translation().x(), 0.1) << back->views[0].why;
  // Bad requests are errors naming the field.
  r.target_surface_world = {Eigen::Vector3d(0.5, 0.5, 0.5)};
  EXPECT_NE(next_best_views(g, r).error().message.find("target surface: none of its 1 points"), std::string::npos);
  r.target_surface_world = {Eigen::Vector3d(0.0, std::nan(""), 0.0)};
  EXPECT_NE(next_best_views(g, r).error().message.find("target surface: a point is not finite"), std::string::npos);
  r.target_surface_world.clear();
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
