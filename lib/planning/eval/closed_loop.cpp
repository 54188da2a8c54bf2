#include "closed_loop.h"

#include <cmath>
#include <limits>
#include <random>
#include <unordered_map>

#include "scenewatch/background/occupancy_map.h"
#include "scenewatch/ontology/describe.h"
#include "scenewatch/sim/simulator.h"

namespace scenewatch::planning::eval {

namespace {

// Hit points of the target objects, one kept per cell of `cell` metres: enough to answer "is
// there a hit within `cell` of p" by looking at the 27 cells around p.
class HitCells {
 public:
  explicit HitCells(double cell) : cell_(cell) {}
  /// True when `p` is the first hit of its cell.
  bool add(const Eigen::Vector3d& p) { return cells_.emplace(key(cell_of(p)), p.cast<float>()).second; }
  bool near(const Eigen::Vector3d& p) const {
    const Eigen::Vector3i c = cell_of(p);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = cells_.find(key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it != cells_.end() && (it->second.cast<double>() - p).norm() <= cell_) return true;
        }
    return false;
  }

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const { return (p / cell_).array().floor().cast<int>(); }
  static std::uint64_t key(const Eigen::Vector3i& c) {
    return (static_cast<std::uint64_t>(c.x() + (1 << 20)) << 42) | (static_cast<std::uint64_t>(c.y() + (1 << 20)) << 21) |
           static_cast<std::uint64_t>(c.z() + (1 << 20));
  }
  double cell_;
  std::unordered_map<std::uint64_t, Eigen::Vector3f> cells_;
};

// The exposed surface of one object: hits of rays shot at it from all around, less what lies on or
// under the table or inside another item (where no camera can see).
void sample_surface(const sim::SceneObject& object, const sim::RenderScene& scene, double table_top_z,
                    std::vector<Eigen::Vector3d>* out) {
  Eigen::Vector3d centre_local;
  double radius = 0.0;
  sim::bounding_sphere(object.shape, &centre_local, &radius);
  const std::vector<Eigen::Vector3d> from = fibonacci_directions(3000);
  const std::vector<Eigen::Vector3d> aim = fibonacci_directions(97);
  for (std::size_t i = 0; i < from.size(); ++i) {
    const Eigen::Vector3d origin = centre_local + 3.0 * radius * from[i];
    const Eigen::Vector3d towards = centre_local + 0.9 * radius * aim[(i * 31) % aim.size()];
    sim::ShapeHit hit;
    if (!sim::intersect(object.shape, origin, towards - origin, 0.0, 10.0, &hit)) continue;
    const Eigen::Vector3d p = object.T_world_object * (origin + hit.t * (towards - origin));
    if (p.z() < table_top_z + 0.003) continue;
    bool buried = false;
    for (const auto& item : scene.items) {
      if (item.label == object.label()) continue;
      if (sim::signed_distance(item.shape, item.T_world_item.inverse() * p) < 0.002) {
        buried = true;
        break;
      }
    }
    if (!buried) out->push_back(p);
  }
}

// What the planner aims at in one step (ClosedLoopSetup::planned_target), from the target's points
// seen so far; `curve` counts the steps a class fitted.
struct PlannedBox {
  Aabb box;
  std::vector<Eigen::Vector3d> surface;
};

PlannedBox planned_box(const ClosedLoopSetup& setup, const Aabb& truth, const std::vector<Eigen::Vector3d>& observed,
                       const Pose& camera, ClosedLoopCurve& curve) {
  if (setup.planned_target == PlannedTarget::kTruthBox || observed.empty()) return {truth, {}};
  Aabb seen{observed.front(), observed.front()};
  for (const auto& p : observed) seen = seen.united(Aabb{p, p});
  PlannedBox out{seen.grown(setup.resolution_m), {}};
  if (setup.planned_target != PlannedTarget::kCompletion || setup.classes == nullptr) return out;
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // the simulator's table is level
  auto d = ontology::describe(observed, up, *setup.classes, camera.translation());
  curve.last_class = d ? d->class_name : ontology::kUnknownClass;
  if (!d || d->completed_points.empty()) return out;
  std::vector<Eigen::Vector3d> surface = above_lowest_layer(d->completed_points, up, setup.resolution_m);
  if (surface.empty()) return out;
  const NextBestViewRequest r = complete_surface_request(seen, std::move(surface), setup.resolution_m);
  ++curve.completed_steps;
  return {r.target_world, r.target_surface_world};
}

}  // namespace

const char* to_string(PlannedTarget target) {
  switch (target) {
    case PlannedTarget::kTruthBox: return "true box";
    case PlannedTarget::kObservedBox: return "observed box";
    case PlannedTarget::kCompletion: return "completion";
  }
  return "true box";
}

Result<ClosedLoopCurve> run_closed_loop(const sim::Scenario& scenario_in, const ClosedLoopSetup& setup, std::uint64_t seed) {
  const sim::Scenario scenario = sim::with_resolution(scenario_in, setup.image_width, setup.image_height);
  auto simulator = sim::Simulator::create(scenario);
  if (!simulator) return simulator.error();
  const sim::RenderScene scene = simulator->render_scene(0, 0);
  const Intrinsics K = scenario.intrinsics;

  // The targets: their labels, box and true surface.
  std::vector<std::uint16_t> labels;
  std::vector<Eigen::Vector3d> surface;
  std::optional<Aabb> box;
  for (const auto& object : scenario.objects) {
    if (!setup.target_ids.empty() &&
        std::find(setup.target_ids.begin(), setup.target_ids.end(), object.id) == setup.target_ids.end()) {
      continue;
    }
    labels.push_back(object.label());
    Eigen::Vector3d lo, hi;
    sim::bounding_box(object.shape, &lo, &hi);
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
      const Eigen::Vector3d p = object.T_world_object * corner;
      box = box ? box->united(Aabb{p, p}) : Aabb{p, p};
    }
    sample_surface(object, scene, scenario.table.height_m, &surface);
  }
  if (labels.empty()) return invalid_argument("closed loop: no object of the scenario is a target");
  const Aabb target = box->grown(setup.resolution_m);

  background::Config map_config;
  map_config.resolution_m = setup.resolution_m;
  background::OccupancyMap map(map_config);
  sim::Raycaster raycaster;
  sim::IdealView view;
  HitCells hits(setup.surface_cell_m);
  // The target's points seen so far, one per 5 mm cell (what a robot knows of it).
  std::vector<Eigen::Vector3d> observed;
  HitCells observed_cells(0.005);
  auto keep_observed = [&](const Eigen::Vector3d& p) {
    if (observed_cells.add(p)) observed.push_back(p);
  };
  auto observe = [&](const Pose& T_world_camera) {
    raycaster.render(scene, T_world_camera, K, &view);
    Cloud cloud(static_cast<std::uint32_t>(K.width), static_cast<std::uint32_t>(K.height));
    cloud.is_dense = false;
    for (int v = 0; v < K.height; ++v)
      for (int u = 0; u < K.width; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * K.width + u;
        PointT& q = cloud.points[i];
        const double z = view.opaque_depth_m[i];
        if (!std::isfinite(z) || z > map_config.max_range_m) {
          q.x = q.y = q.z = std::numeric_limits<float>::quiet_NaN();
          continue;
        }
        const Eigen::Vector3d p_camera((u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z);
        q.x = static_cast<float>(p_camera.x());
        q.y = static_cast<float>(p_camera.y());
        q.z = static_cast<float>(p_camera.z());
        if (std::find(labels.begin(), labels.end(), view.labels[i]) != labels.end()) {
          hits.add(T_world_camera * p_camera);
          keep_observed(T_world_camera * p_camera);
        }
      }
    map.insert(cloud, T_world_camera);
  };
  auto coverage = [&] {
    std::size_t seen = 0;
    for (const auto& p : surface) seen += hits.near(p) ? 1 : 0;
    return surface.empty() ? 0.0 : static_cast<double>(seen) / static_cast<double>(surface.size());
  };

  NextBestViewRequest request;
  request.target_world = target;
  request.measure = setup.measure;
  request.n = 1;
  request.intrinsics = K;
  request.constraint.kind = ConstraintKind::kCap;
  request.constraint.center_world = target.center();
  request.constraint.radius_max_m = setup.cap_radius_m;
  request.constraint.max_polar_deg = setup.cap_polar_deg;
  request.constraint.samples = setup.candidates;
  auto candidates = candidate_poses(request.constraint, target.center());
  if (!candidates) return candidates.error();
  auto region = planning_region(request);
  if (!region) return region.error();

  // The first view: at random on the cap, the same for every strategy of this seed.
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double z = 1.0 - (1.0 - std::cos(setup.cap_polar_deg * M_PI / 180.0)) * unit(rng);
  const double phi = 2.0 * M_PI * unit(rng);
  const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
  Pose current = look_at(target.center() + setup.cap_radius_m * Eigen::Vector3d(rho * std::cos(phi), rho * std::sin(phi), z),
                         target.center());
  std::mt19937_64 choice_rng(seed * 7919 + 1);

  ClosedLoopCurve curve;
  curve.surface_samples = surface.size();
  observe(current);
  curve.coverage.push_back(coverage());
  background::DenseGrid grid;
  for (int step = 0; step < setup.views; ++step) {
    if (setup.random) {
      current = (*candidates)[std::uniform_int_distribution<std::size_t>(0, candidates->size() - 1)(choice_rng)];
    } else {
      if (auto st = map.fill_dense_grid(*region, grid, std::size_t{1} << 26, /*with_uncertain_free=*/true); !st) return st.error();
      request.current_T_world_camera = current;
      PlannedBox aim = planned_box(setup, target, observed, current, curve);
      request.target_world = aim.box;
      request.target_surface_world = std::move(aim.surface);
      auto answer = next_best_views(grid, request);
      if (!answer) return answer.error();
      current = answer->views.front().T_world_camera;
    }
    observe(current);
    curve.coverage.push_back(coverage());
  }
  return curve;
}

}  // namespace scenewatch::planning::eval
