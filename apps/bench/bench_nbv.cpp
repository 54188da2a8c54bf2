// scenewatch-bench --only nbv (issue 31): where to look next.
//  1. Speed: one candidate view (80x60 rays) scored on a 2 cm map of the simulator's clutter table
//     through the dense grid, beside a plain OctoMap ray cast of the same rays (computeRayKeys,
//     then search() per key, stopped at occupied) in the same run; and the seed's solver.
//  2. The seed's experiment (Figs. 3.12, 3.13): trace and spectral norm, planned vs random.
//  3. The closed loop on the simulator: coverage after 1-10 views, each measure against random.
#include <octomap/OcTree.h>

#include <cmath>
#include <fstream>
#include <map>
#include <random>

#include "bench.h"
#include "closed_loop.h"
#include "nbv_plot.h"
#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/ontology/class_library.h"
#include "scenewatch/planning/covariance_planner.h"
#include "scenewatch/planning/next_best_view.h"
#include "scenewatch/planning/point_filter.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"

namespace scenewatch::bench {

namespace {

using namespace scenewatch::planning;

// The baseline: the same rays through the octree, one search() per voxel, stopped at an occupied
// node; the distinct unknown voxels inside the target counted.
std::size_t octomap_unknown_reached(const octomap::OcTree& tree, const Pose& T, const Intrinsics& K, const VolumetricConfig& cfg,
                                    const Aabb& target) {
  octomap::KeySet seen;
  octomap::KeyRay ray;
  const octomap::point3d origin(T.translation().x(), T.translation().y(), T.translation().z());
  for (int ry = 0; ry < cfg.rays_y; ++ry)
    for (int rx = 0; rx < cfg.rays_x; ++rx) {
      const double u = (rx + 0.5) * K.width / cfg.rays_x, v = (ry + 0.5) * K.height / cfg.rays_y;
      const Eigen::Vector3d d((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0);
      const Eigen::Vector3d end = T * (cfg.max_range_m * d);
      if (!tree.computeRayKeys(origin, octomap::point3d(end.x(), end.y(), end.z()), ray)) continue;
      for (const auto& key : ray) {
        const octomap::OcTreeNode* node = tree.search(key);
        if (node != nullptr && tree.isNodeOccupied(node)) break;
        if (node == nullptr) {
          const octomap::point3d c = tree.keyToCoord(key);
          if (target.contains(Eigen::Vector3d(c.x(), c.y(), c.z()))) seen.insert(key);
        }
      }
    }
  return seen.size();
}

int run_speed(const Options& o, const sim::Scenario& scenario_in) {
  const sim::Scenario scenario = sim::with_resolution(scenario_in, 640, 480);
  auto simulator = sim::Simulator::create(scenario);
  if (!simulator) return std::fprintf(stderr, "nbv: %s\n", simulator.error().message.c_str()), 1;
  background::OccupancyMap map;  // 2 cm
  for (int f : {0, 45}) {
    auto frame = sim::as_frame(simulator->render(0, f), scenario.intrinsics, f / 30.0);
    if (!frame) return 1;
    map.insert(*frame->cloud, frame->pose_or_identity(), 2);
  }
  const auto bt = std::filesystem::temp_directory_path() / "scenewatch-bench-nbv.bt";
  if (!map.save(bt)) return 1;
  octomap::OcTree tree(0.02);
  tree.readBinary(bt.string());
  std::filesystem::remove(bt);

  NextBestViewRequest r;
  r.target_world = Aabb{Eigen::Vector3d(-0.45, -0.35, 0.75), Eigen::Vector3d(0.45, 0.35, 1.05)};
  r.constraint.kind = ConstraintKind::kCap;
  r.constraint.center_world = r.target_world.center();
  r.constraint.radius_max_m = 0.9;
  r.intrinsics = scenario.intrinsics;
  auto region = planning_region(r);
  background::DenseGrid grid;
  std::vector<double> fill_ms, dense_ms, octomap_ms;
  for (int i = 0; i < o.repetitions; ++i) fill_ms.push_back(time_ms([&] { (void)map.fill_dense_grid(*region, grid, std::size_t{1} << 26, /*with_uncertain_free=*/true); }));
  // The scorer's own precompute (its block map for empty-space skipping), also once per request.
  std::vector<double> scorer_ms;
  for (int i = 0; i < o.repetitions; ++i) scorer_ms.push_back(time_ms([&] { ViewScorer(grid, r.target_world, r.volumetric); }));
  ViewScorer scorer(grid, r.target_world, r.volumetric);
  auto poses = candidate_poses(r.constraint, r.target_world.center());
  // A candidate on the side opposite the recorded views: much of it unknown.
  const Pose T = (*poses)[poses->size() / 2];
  ViewGain gain;
  std::size_t baseline_unknown = 0;
  const int reps = std::max(o.repetitions, 21);
  for (int i = 0; i < reps; ++i) {
    dense_ms.push_back(time_ms([&] { gain = scorer.score(T, r.intrinsics, Measure::kRearSideEntropy); }));
    octomap_ms.push_back(time_ms([&] { baseline_unknown = octomap_unknown_reached(tree, T, r.intrinsics, r.volumetric, r.target_world); }));
  }
  std::printf("\n== nbv: one candidate, 80x60 rays, 2 cm map of the clutter table (2 simulated 640x480 frames), %d runs ==\n", reps);
  std::printf("%-44s %10s %12s\n", "", "median ms", "unknown vox");
  std::printf("%-44s %10.3f %12zu\n", "dense grid (planning::ViewScorer)", median(dense_ms), gain.unknown_reached);
  std::printf("%-44s %10.3f %12zu\n", "OctoMap computeRayKeys + search (baseline)", median(octomap_ms), baseline_unknown);
  std::printf("ratio baseline / dense: %.1fx; the grid copy of the %.2f m^3 planning region (%zu voxels), once per request: %.2f ms\n",
              median(octomap_ms) / median(dense_ms), (region->max - region->min).prod(), grid.size(), median(fill_ms));
  std::printf("the scorer's block map (empty-space skipping), once per request: %.2f ms\n", median(scorer_ms));
  std::printf("voxels read by the dense caster: %zu; a request scores 64 candidates: about %.0f ms\n", gain.steps,
              median(fill_ms) + median(scorer_ms) + 64 * median(dense_ms));

  // The seed's solver, rule (3.23), 1000 points (uniform in a 0.3 m cube, covariances of one depth
  // view from 1 m by the structured-light model).
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  std::vector<Eigen::Vector3d> pts;
  std::vector<Eigen::Matrix3d> covs;
  const SensorModel sensor;
  for (int i = 0; i < 1000; ++i) {
    pts.emplace_back(u(rng), u(rng), u(rng));
    covs.push_back(depth_point_covariance(pts.back(), {Eigen::Vector3d(0, -1, 0)}, sensor, 525.0));
  }
  std::printf("\n== nbv: the seed's solver, 1000 points, sphere r 1 m ==\n%-16s %12s %10s\n", "rule", "median us", "bisection");
  for (WeightRule rule : {WeightRule::kMajorAxisUnit, WeightRule::kMajorAxisLambda, WeightRule::kAllAxesLambda}) {
    std::vector<double> us;
    CovarianceView v;
    for (int i = 0; i < 201; ++i) {
      us.push_back(1000.0 * time_ms([&] { v = plan_covariance_view(pts, covs, rule, Eigen::Vector3d::Zero(), 1.0); }));
    }
    std::printf("%-16s %12.1f %10d\n", to_string(rule), median(us), v.minimum.iterations);
  }
  return 0;
}

void run_reproduction() {
  const TwoCameraExperiment setup;  // the defaults: 100 points, 0.3 m cube, r 1 m, f 500, 1 px, 200 steps
  const int runs = 10;
  struct Row {
    const char* name;
    ViewStrategy strategy;
    std::vector<double> trace, norm;
  };
  std::vector<Row> rows{{"random", {true, WeightRule::kAllAxesLambda}, {}, {}},
                        {"rule 3.21", {false, WeightRule::kMajorAxisUnit}, {}, {}},
                        {"rule 3.22", {false, WeightRule::kMajorAxisLambda}, {}, {}},
                        {"rule 3.23", {false, WeightRule::kAllAxesLambda}, {}, {}}};
  for (auto& row : rows) {
    row.trace.assign(setup.steps, 0.0);
    row.norm.assign(setup.steps, 0.0);
    for (int run = 0; run < runs; ++run) {
      const ExperimentCurve c = run_two_camera_experiment(setup, row.strategy, 11, 100 + run);
      for (int s = 0; s < setup.steps; ++s) {
        row.trace[s] += c.trace[s] / runs;
        row.norm[s] += c.spectral_norm[s] / runs;
      }
    }
  }
  std::ofstream csv("nbv_reproduction.csv");
  csv << "step";
  for (const auto& row : rows) csv << "," << row.name << " trace," << row.name << " spectral_norm";
  csv << "\n";
  for (int s = 0; s < setup.steps; ++s) {
    csv << s + 1;
    for (const auto& row : rows) csv << "," << row.trace[s] << "," << row.norm[s];
    csv << "\n";
  }
  // The seed's Figs. 3.12 and 3.13 in one: the first 15 steps and the last 21 (180-200 in the seed).
  const int late_first = std::max(1, setup.steps - 20);
  std::vector<StepCurve> curves;
  for (const auto& row : rows) curves.push_back({row.name, row.trace});
  char title[160];
  std::snprintf(title, sizeof title, "Seed's experiment (Figs. 3.12, 3.13): covariance trace, %d points, mean of %d runs", setup.points, runs);
  const std::filesystem::path png = "nbv_reproduction.png";
  const bool plotted = write_step_plot(png, title, "trace, sum over the points (m^2)", curves,
                                       {{1, 15}, {late_first, setup.steps}});
  std::printf("\n== nbv: the seed's experiment (%d points in a %.1f m cube, cameras on a %.1f m sphere, f %.0f px, %.0f px noise, "
              "10 runs; CSV nbv_reproduction.csv) ==\n",
              setup.points, setup.cube_side_m, setup.sphere_radius_m, setup.focal_px, setup.sigma_px);
  std::printf("%5s %11s %11s %11s %11s %9s %9s\n", "step", "random", "rule 3.21", "rule 3.22", "rule 3.23", "3.23/rnd", "norm 3.23/rnd");
  auto print_step = [&](int s) {
    std::printf("%5d %11.4g %11.4g %11.4g %11.4g %9.3f %9.3f\n", s + 1, rows[0].trace[s], rows[1].trace[s], rows[2].trace[s],
                rows[3].trace[s], rows[3].trace[s] / rows[0].trace[s], rows[3].norm[s] / rows[0].norm[s]);
  };
  for (int s = 0; s < 15; ++s) print_step(s);
  std::printf("  ...\n");
  for (int s = 179; s < setup.steps; ++s) print_step(s);
  if (plotted) {
    std::printf("plot of the trace (steps 1-15 and %d-%d): %s\n", late_first, setup.steps,
                std::filesystem::absolute(png).c_str());
  } else {
    std::fprintf(stderr, "nbv: could not write %s\n", png.c_str());
  }
}

int run_closed_loops(const sim::Scenario& scenario) {
  struct Target {
    const char* name;
    std::vector<int> ids;
  };
  const int seeds = 10, views = 10;
  for (const Target& target : {Target{"the clutter table (all 12 objects)", {}}, Target{"one object (cereal box, id 1)", {1}}}) {
    std::printf("\n== nbv: closed loop on the simulator, %s: mean coverage of the true surface after the first view "
                "and 1-%d chosen views, %d seeds ==\n",
                target.name, views, seeds);
    std::printf("%-18s", "strategy");
    for (int v = 0; v <= views; ++v) std::printf(" %5d", v);
    std::printf("  views to 90%%\n");
    std::vector<double> random_curve;
    for (int k = 0; k < 6; ++k) {
      eval::ClosedLoopSetup setup;
      setup.target_ids = target.ids;
      setup.views = views;
      setup.random = k == 5;
      const Measure measures[5] = {Measure::kUnobserved, Measure::kRearSide, Measure::kRearSideEntropy, Measure::kOcclusionAware,
                                   Measure::kVisible};
      if (!setup.random) setup.measure = measures[k];
      std::vector<double> mean(views + 1, 0.0);
      for (int seed = 1; seed <= seeds; ++seed) {
        auto c = eval::run_closed_loop(scenario, setup, seed);
        if (!c) return std::fprintf(stderr, "nbv: %s\n", c.error().message.c_str()), 1;
        for (int v = 0; v <= views; ++v) mean[v] += c->coverage[v] / seeds;
      }
      std::printf("%-18s", setup.random ? "random" : to_string(setup.measure));
      int reach = -1;
      for (int v = 0; v <= views; ++v) {
        std::printf(" %5.3f", mean[v]);
        if (reach < 0 && mean[v] >= 0.9) reach = v;
      }
      if (reach < 0) {
        std::printf("  never\n");
      } else {
        std::printf("  %d\n", reach);
      }
    }
  }
  return 0;
}

// Issue 31 item 3: the view that completes one object, aimed at what a robot knows of it (the box
// of its points seen so far, or the ontology's completion of them) beside the true box (an oracle)
// and random, on the same candidates.
int run_completion_loops(const sim::Scenario& scenario) {
  auto classes = ontology::load_classes_file(std::filesystem::path(SCENEWATCH_SOURCE_DIR) / "config/ontology.yaml");
  if (!classes) return std::fprintf(stderr, "nbv: %s\n", classes.error().message.c_str()), 1;
  const int seeds = 10, views = 10;
  std::printf("\n== nbv: closed loop, one object, what the planner aims at (measure rear_side_entropy): mean coverage of its "
              "true surface after the first view and 1-%d chosen views, %d seeds ==\n",
              views, seeds);
  std::printf("%-28s %-13s", "object", "aim");
  for (int v = 0; v <= views; ++v) std::printf(" %5d", v);
  std::printf("  views to 90%%  classed\n");
  for (const auto& [id, name] : {std::pair{1, "cereal box (id 1)"}, std::pair{2, "mug (id 2)"}, std::pair{3, "can (id 3)"},
                                 std::pair{11, "small can (id 11)"}}) {
    for (int k = 0; k < 4; ++k) {
      eval::ClosedLoopSetup setup;
      setup.target_ids = {id};
      setup.views = views;
      setup.classes = &*classes;
      setup.random = k == 3;
      if (!setup.random) setup.planned_target = static_cast<eval::PlannedTarget>(k);
      std::vector<double> mean(views + 1, 0.0);
      int completed = 0;
      std::map<std::string, int> classed;
      for (int seed = 1; seed <= seeds; ++seed) {
        auto c = eval::run_closed_loop(scenario, setup, seed);
        if (!c) return std::fprintf(stderr, "nbv: %s\n", c.error().message.c_str()), 1;
        for (int v = 0; v <= views; ++v) mean[v] += c->coverage[v] / seeds;
        completed += c->completed_steps;
        if (!c->last_class.empty()) ++classed[c->last_class];
      }
      std::printf("%-28s %-13s", k == 0 ? name : "", setup.random ? "random" : eval::to_string(setup.planned_target));
      int reach = -1;
      for (int v = 0; v <= views; ++v) {
        std::printf(" %5.3f", mean[v]);
        if (reach < 0 && mean[v] >= 0.9) reach = v;
      }
      std::printf("  %-13s", reach < 0 ? "never" : std::to_string(reach).c_str());
      if (setup.planned_target == eval::PlannedTarget::kCompletion && !setup.random) {
        std::printf("  %d of %d steps;", completed, seeds * views);
        for (const auto& [cls, n] : classed) std::printf(" %s %d", cls.c_str(), n);
      }
      std::printf("\n");
    }
  }
  return 0;
}

}  // namespace

int run_nbv(const Options& o) {
  auto scenario = sim::load_scenario(std::filesystem::path(SCENEWATCH_SOURCE_DIR) / "sample_clouds/scenarios/clutter.yaml");
  if (!scenario) return std::fprintf(stderr, "nbv: %s\n", scenario.error().message.c_str()), 1;
  int rc = run_speed(o, *scenario);
  run_reproduction();
  rc |= run_closed_loops(*scenario);
  rc |= run_completion_loops(*scenario);
  return rc;
}

}  // namespace scenewatch::bench
