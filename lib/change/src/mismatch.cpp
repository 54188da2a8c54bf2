// Per-pixel geometric mismatch against the occupancy map, and per-pixel depth reasoning for
// same-camera pairs.
#include "scenewatch/change/mismatch.h"

#include "scenewatch/change/dark_space.h"

#include "scenewatch/core/depth_validity.h"
#include "scenewatch/core/surface_incidence.h"
#include "scenewatch/io/rgbd.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

namespace scenewatch::change {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// Half the diagonal of a unit cube: a surface inside a voxel lies within this many voxel edges
// of its centre.
constexpr double kHalfDiagonal = 0.8660254;

// Whether a point in free space may claim a new surface for its camera. Not when the camera itself
// has seen a surface in that voxel before (another camera's rays freed it: its own surface, not a
// new one), nor when the first surface behind it along its ray is one only other cameras have seen
// and lies within `displaced_m`: near enough to be their version of the surface this camera sees,
// displaced. Farther behind, the others' surface is hidden by something new: a camera that joins
// after a cup was put down sees the cup in front of a table only the first camera saw.
bool claims_new_surface(const background::DenseGrid& grid, const Eigen::Vector3d& origin, const Eigen::Vector3d& p,
                        const SurfaceWitness& witness, std::uint32_t camera, double displaced_m) {
  if (witness.seen(p, camera) == SurfaceWitness::Seen::kBySelf) return false;
  const Eigen::Vector3d dir = (p - origin).normalized();
  const double step = 0.5 * grid.resolution;
  for (double s = step; s <= displaced_m; s += step) {
    const long idx = grid.index_of(p + s * dir);
    if (idx < 0) return true;  // left the grid: nothing behind to ask about
    if (grid.at(idx) != background::Occupancy::kOccupied) continue;
    return witness.seen(grid.center(idx), camera) != SurfaceWitness::Seen::kByOthersOnly;
  }
  return true;
}

// The farthest ring of voxels searched for a surface near a point: 7 x 7 x 7 voxels for the
// head-on tolerance, 11 x 11 x 11 for the noise along the ray at the surface's incidence.
constexpr int kHeadOnRing = 3;
constexpr int kMaxRing = 5;

// Whether a voxel that is not free (a surface, or space never seen: the far side of a thin leg
// whose silhouette rays grazed this voxel) has its centre within `reach` of w, in voxel idx,
// searching at most `max_ring` voxels each way.
bool surface_within(const background::DenseGrid& grid, long idx, const Eigen::Vector3d& w, double reach, int max_ring) {
  using background::Occupancy;
  const int ring = std::min(max_ring, static_cast<int>(std::ceil(reach / grid.resolution - 0.5)));
  const long sz = static_cast<long>(grid.nx) * grid.ny;
  const long i0 = idx % grid.nx, j0 = (idx / grid.nx) % grid.ny, k0 = idx / sz;
  const double reach2 = reach * reach;
  for (int dk = -ring; dk <= ring; ++dk) {
    const long k = k0 + dk;
    if (k < 0 || k >= grid.nz) continue;
    for (int dj = -ring; dj <= ring; ++dj) {
      const long j = j0 + dj;
      if (j < 0 || j >= grid.ny) continue;
      for (int di = -ring; di <= ring; ++di) {
        const long ii = i0 + di;
        if (ii < 0 || ii >= grid.nx) continue;
        const long n = k * sz + j * grid.nx + ii;
        if (grid.state[n] == static_cast<std::uint8_t>(Occupancy::kFree)) continue;
        if ((grid.center(n) - w).squaredNorm() < reach2) return true;
      }
    }
  }
  return false;
}

}  // namespace

Status validate(const Config& c) {
  if (auto st = scenewatch::validate(c.sensor); !st) return st;
  auto bad = [](const std::string& key, const std::string& why) { return invalid_argument("change." + key + ": " + why); };
  if (!(c.sigma_factor > 0 && c.sigma_factor <= 20)) return bad("sigma_factor", "must be in (0, 20]");
  if (!(c.min_tolerance_m >= 0 && c.min_tolerance_m <= 0.5)) return bad("min_tolerance_m", "must be in [0, 0.5] m");
  if (!(c.cluster_voxel_m >= 0.002 && c.cluster_voxel_m <= 0.2)) return bad("cluster_voxel_m", "must be in [0.002, 0.2] m");
  if (!(c.min_object_size_m >= 0 && c.min_object_size_m <= 2)) return bad("min_object_size_m", "must be in [0, 2] m");
  if (!(c.min_object_area_m2 >= 0 && c.min_object_area_m2 <= 1)) return bad("min_object_area_m2", "must be in [0, 1] m2");
  if (!(c.min_surface_probability >= 0.5 && c.min_surface_probability < 1)) return bad("min_surface_probability", "must be in [0.5, 1)");
  if (!(c.max_range_m > 0.1 && c.max_range_m <= 20)) return bad("max_range_m", "must be in (0.1, 20] m");
  if (c.min_cluster_points < 1) return bad("min_cluster_points", "must be >= 1");
  if (c.min_changed_neighbours < 0 || c.min_changed_neighbours > 8) return bad("min_changed_neighbours", "must be in [0, 8]");
  if (!(c.move_max_size_ratio >= 1)) return bad("move_max_size_ratio", "must be >= 1");
  if (!(c.move_max_color_distance >= 0)) return bad("move_max_color_distance", "must be >= 0");
  if (!(c.move_min_distance_m >= 0)) return bad("move_min_distance_m", "must be >= 0 m");
  if (!(c.completion_evidence_share > 0 && c.completion_evidence_share <= 1)) return bad("completion_evidence_share", "must be in (0, 1]");
  if (!(c.completion_object_share > 0 && c.completion_object_share <= 1)) return bad("completion_object_share", "must be in (0, 1]");
  if (c.completion_stride_px < 1 || c.completion_stride_px > 8) return bad("completion_stride_px", "must be in [1, 8]");
  if (c.persistence_frames < 1 || c.persistence_frames > 100) {
    return bad("persistence_frames", "must be in [1, 100], got " + std::to_string(c.persistence_frames));
  }
  if (!(c.persistence_match_m > 0 && c.persistence_match_m <= 1)) return bad("persistence_match_m", "must be in (0, 1] m");
  if (c.max_grid_voxels < 1000) return bad("max_grid_voxels", "must be >= 1000");
  return {};
}

double tolerance_m(const Config& c, double z) { return std::max(c.min_tolerance_m, c.sigma_factor * c.sensor.sigma_z(z)); }

double map_tolerance_m(const Config& c, double z, double pose_shift_m) {
  return map_tolerance_from_sigma(c, c.sensor.sigma_z(z), z, pose_shift_m);
}

double map_tolerance_from_sigma(const Config& c, double sensor_sigma_m, double z, double pose_shift_m) {
  const double pose = c.sensor.pose_sigma_at(z);
  return std::max(c.min_tolerance_m, c.sigma_factor * std::hypot(sensor_sigma_m, pose)) + pose_shift_m;
}

Result<Intrinsics> observation_camera(const Cloud& cloud, const std::optional<Intrinsics>& K) {
  if (K) {
    if (!K->valid()) return invalid_argument("intrinsics are invalid");
    return *K;
  }
  if (cloud.height > 1) return io::estimate_intrinsics(cloud);
  // A virtual pinhole, 640 pixels wide, whose field of view covers every point in front.
  double tx = 0, ty = 0;
  std::size_t n = 0;
  for (const auto& p : cloud.points) {
    if (!is_valid(p) || p.z <= 0) continue;
    tx = std::max(tx, std::abs(static_cast<double>(p.x / p.z)));
    ty = std::max(ty, std::abs(static_cast<double>(p.y / p.z)));
    ++n;
  }
  if (n == 0) return invalid_argument("no point lies in front of the camera (z > 0)");
  Intrinsics V;
  V.width = 640;
  const double t = std::max({tx, ty, 1e-3});
  V.fx = V.fy = (V.width / 2.0 - 1) / t;
  V.height = std::max(2, 2 * static_cast<int>(std::ceil(ty * V.fy + 1)));
  V.cx = V.width / 2.0 - 0.5;
  V.cy = V.height / 2.0 - 0.5;
  return V;
}

DepthView depth_view(const Cloud& cloud, const Intrinsics& K) {
  DepthView view;
  view.K = K;
  view.z.assign(static_cast<std::size_t>(K.width) * K.height, kNaN);
  float lo = std::numeric_limits<float>::infinity(), hi = 0.0f;
  if (cloud.height > 1 && static_cast<int>(cloud.width) == K.width && static_cast<int>(cloud.height) == K.height) {
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const PointT& p = cloud.points[i];
      if (!is_valid(p) || !(p.z > 0)) continue;
      view.z[i] = p.z;
      lo = std::min(lo, p.z);
      hi = std::max(hi, p.z);
    }
  } else {
    for (const auto& p : cloud.points) {
      if (!is_valid(p) || p.z <= 0) continue;
      const long u = std::lround(K.fx * p.x / p.z + K.cx), v = std::lround(K.fy * p.y / p.z + K.cy);
      if (u < 0 || v < 0 || u >= K.width || v >= K.height) continue;
      float& z = view.z[static_cast<std::size_t>(v) * K.width + u];
      if (!(z <= p.z)) z = p.z;  // NaN or farther: the nearer point wins
      lo = std::min(lo, p.z);
      hi = std::max(hi, p.z);
    }
  }
  if (hi > 0) view.min_z = lo, view.max_z = hi;
  return view;
}

namespace {
// Whether every sample of a voxel's footprint (centre uc, vc; half-width half_px) has trusted
// depth beyond `limit`; `nearest` is then the nearest of those depths.
template <typename TrustedAt>
bool footprint_behind(const DepthView& depth, const TrustedAt& trusted_at, double uc, double vc, double half_px, double limit,
                      float& nearest) {
  constexpr int kSteps = 3;  // (2 kSteps + 1)^2 samples over the footprint
  nearest = std::numeric_limits<float>::infinity();
  for (int a = -kSteps; a <= kSteps; ++a)
    for (int b = -kSteps; b <= kSteps; ++b) {
      const int u = static_cast<int>(std::lround(uc + half_px * a / kSteps));
      const int v = static_cast<int>(std::lround(vc + half_px * b / kSteps));
      const float z = depth.at(u, v);
      if (!(z > 0) || !trusted_at(u, v) || z <= limit) return false;
      nearest = std::min(nearest, z);
    }
  return true;
}

// Whether the frame sees through the voxel centred at c: its whole projected footprint shows
// trusted depth behind it by more than the tolerance. A footprint pixel at or in front of the
// voxel (the surface is still there, or something occludes it) vetoes; so does one without depth
// (a hole at a grazing edge may be the surface itself) or one the sensor model does not trust.
// The footprint is the voxel's, grown by the pose's uncertainty at that range: wherever the voxel
// may really project, the frame must see behind it. With `witness`, a surface only other cameras
// saw is not claimed, and one this session saw is placed within the noise of its nearest sighting.
template <typename TrustedAt>
std::optional<MissingVoxel> seen_through(const Eigen::Vector3d& c, const Eigen::Isometry3d& T_camera_world, const Intrinsics& K,
                                         const Config& config, const DepthView& depth, const TrustedAt& trusted_at,
                                         const PoseAgreement& measured_pose, double res, const SurfaceWitness* witness,
                                         std::uint32_t camera) {
  const Eigen::Vector3d q = T_camera_world * c;
  if (q.z() <= res || q.z() > config.max_range_m) return std::nullopt;
  const double uc = K.fx * q.x() / q.z() + K.cx, vc = K.fy * q.y() / q.z() + K.cy;
  const double shift = measured_pose.shift_at(c);
  const double half_px = K.fx * (kHalfDiagonal * res + config.sigma_factor * config.sensor.pose_sigma_at(q.z()) + shift) / q.z();
  if (uc - half_px < 0 || vc - half_px < 0 || uc + half_px > K.width - 1 || vc + half_px > K.height - 1) return std::nullopt;
  // A gap is measured between two noisy surfaces: the frame's at this depth, and the map's,
  // which lies within the noise of the nearest depth it was seen at (when this session saw it).
  // Most surfaces in view are still there and the frame's noise alone vetoes them; the witness
  // (a hash lookup) is asked only about the rest, whose limit its depth can only widen.
  const double frame_sigma = config.sensor.sigma_z(q.z());
  auto limit_for = [&](double sigma) { return q.z() + kHalfDiagonal * res + map_tolerance_from_sigma(config, sigma, q.z(), shift); };
  float nearest = 0.0f;
  if (!footprint_behind(depth, trusted_at, uc, vc, half_px, limit_for(frame_sigma), nearest)) return std::nullopt;
  if (witness != nullptr) {
    double seen_depth = 0.0;
    if (witness->seen(c, camera, &seen_depth) == SurfaceWitness::Seen::kByOthersOnly) return std::nullopt;
    // The whole footprint lies behind the frame's limit; the wider one holds when its nearest does.
    if (seen_depth > 0 && !(nearest > limit_for(std::hypot(frame_sigma, config.sensor.sigma_z(seen_depth))))) return std::nullopt;
  }
  MissingVoxel m;
  m.center_world = c;
  m.u = static_cast<int>(std::lround(uc));
  m.v = static_cast<int>(std::lround(vc));
  m.depth_gap_m = static_cast<float>(nearest - q.z());
  return m;
}

// Removed: occupied voxels the frame sees through (seen_through()).
template <typename TrustedAt>
std::vector<MissingVoxel> missing_surfaces(const background::DenseGrid& grid, const Pose& T, const Intrinsics& K,
                                           const Config& config, const DepthView& depth, const TrustedAt& trusted_at,
                                           const PoseAgreement& measured_pose, const SurfaceWitness* witness,
                                           std::uint32_t camera, double res) {
  std::vector<MissingVoxel> missing;
  const Eigen::Isometry3d T_camera_world = T.inverse();
  const auto min_probability = static_cast<std::uint8_t>(std::floor(255.0 * config.min_surface_probability));
  for (const background::DenseGrid::Surface& surface : grid.occupied) {
    if (surface.probability < min_probability) continue;
    const Eigen::Vector3d c = grid.center(static_cast<long>(surface.index));
    auto m = seen_through(c, T_camera_world, K, config, depth, trusted_at, measured_pose, res, witness, camera);
    if (!m) continue;
    m->rgb = surface.rgb;
    missing.push_back(*m);
  }
  return missing;
}

// Removed, unseen: dark voxels (dark_space.h) the frame sees through. Every recorded voxel the
// frame sees through is told so (one that goes dark again was never filled); the dark ones are
// evidence. No witness: a dark voxel is dark to the camera that asks (DarkSpace::in_grid).
template <typename TrustedAt>
void missing_dark(const background::DenseGrid& grid, const Pose& T, const Intrinsics& K, const Config& config,
                  const DepthView& depth, const TrustedAt& trusted_at, const PoseAgreement& measured_pose, DarkSpace& dark,
                  std::uint32_t camera, std::vector<MissingVoxel>& missing) {
  const Eigen::Isometry3d T_camera_world = T.inverse();
  for (const DarkSpace::Voxel& d : dark.in_grid(grid, camera, config.persistence_frames)) {
    auto m = seen_through(d.center_world, T_camera_world, K, config, depth, trusted_at, measured_pose, grid.resolution, nullptr, camera);
    if (!m) continue;
    dark.seen_through(d.key);
    if (!d.dark) continue;
    m->dark = true;
    missing.push_back(*m);
  }
}
}  // namespace

std::optional<Aabb> comparison_box(const Cloud& cloud, const Pose& T, const Config& config, double res) {
  const Eigen::Isometry3f Tf = T.cast<float>();
  Aabb box;
  box.min = box.max = T.translation();
  std::size_t valid = 0;
  for (const auto& p : cloud.points) {
    if (!is_valid(p) || p.z > config.max_range_m) continue;
    const Eigen::Vector3d w = (Tf * p.getVector3fMap()).cast<double>();
    box.min = box.min.cwiseMin(w);
    box.max = box.max.cwiseMax(w);
    ++valid;
  }
  if (valid == 0) return std::nullopt;
  box.min.array() -= 2 * res;
  box.max.array() += 2 * res;
  return box;
}

bool any_point_in_range(const Cloud& cloud, const Config& config) {
  return std::any_of(cloud.points.begin(), cloud.points.end(),
                     [&](const PointT& p) { return is_valid(p) && p.z <= config.max_range_m; });
}

Result<Mismatch> mismatch_against_map(const background::OccupancyMap& map, const Cloud& cloud, const Pose& T,
                                      const Intrinsics& K, const Config& config, background::DenseGrid* grid_scratch,
                                      const SurfaceWitness* witness, std::uint32_t camera, bool grid_filled,
                                      DarkSpace* dark) {
  if (!K.valid()) return invalid_argument("mismatch: intrinsics are invalid");
  Mismatch out;
  out.voxel_m = map.resolution();
  const auto t0 = Clock::now();
  const double res = map.resolution();
  const Eigen::Isometry3f Tf = T.cast<float>();
  // 1. A dense copy of the map over the frame's rays: the camera and every valid point.
  background::DenseGrid local;
  background::DenseGrid& grid = grid_scratch != nullptr ? *grid_scratch : local;
  if (!(grid_filled && grid_scratch != nullptr)) {  // a filled grid's caller found the box (and a point in range)
    const std::optional<Aabb> box = comparison_box(cloud, T, config, res);
    if (!box) return Mismatch{};  // nothing within range: nothing to claim
    if (auto filled = map.fill_dense_grid(*box, grid, config.max_grid_voxels); !filled) return filled.error();
  }
  out.grid_ms = ms_since(t0);

  // What the sensor model makes of each pixel (in range, off the border, away from depth edges and
  // holes; core/depth_validity.h).
  out.depth = std::make_shared<const DepthView>(depth_view(cloud, K));
  const DepthView& depth = *out.depth;
  const DepthValidity trusted = depth_validity(depth.z, K.width, K.height, std::min(K.fx, K.fy), config.sensor, config.sigma_factor);
  out.trusted_pixels = trusted.trusted;
  // How far this frame's pose is off the map: every tolerance below grows with it.
  if (config.measure_pose) out.pose = pose_agreement(grid, cloud, T, K, trusted, config.sensor);
  const PoseAgreement& measured_pose = out.pose;
  // Evidence comes from pixels with a depth in the sensor's range, off the image border. The bands
  // around depth edges and holes serve the pose measurement above, not the evidence: a new
  // object's silhouette lies in such a band, and its pixels there are as new as the rest.
  constexpr std::uint8_t kEvidence = DepthValidity::kInRange | DepthValidity::kInterior;
  auto trusted_at = [&](int u, int v) { return !config.trusted_pixels_only || trusted.has(u, v, kEvidence); };

  // 2. Added: points whose voxel the model holds free and whose distance to every occupied voxel
  //    centre exceeds half a voxel diagonal plus the tolerance at their depth (a surface inside an
  //    occupied voxel may lie anywhere in it). Only points in free voxels pay for the search.
  const auto t1 = Clock::now();
  const bool organized = cloud.height > 1 && static_cast<int>(cloud.width) == K.width;
  auto pixel_of = [&](std::size_t i, const PointT& p) {
    if (organized) return std::pair<int, int>(static_cast<int>(i % cloud.width), static_cast<int>(i / cloud.width));
    return std::pair<int, int>(static_cast<int>(std::lround(K.fx * p.x / p.z + K.cx)), static_cast<int>(std::lround(K.fy * p.y / p.z + K.cy)));
  };
  // The incidence of each 2 x 2 block of pixels, fitted once, at the first of its pixels asked
  // for: new objects come as regions of thousands of candidate pixels, and the plane under
  // neighbouring pixels is the same.
  std::vector<float> block_incidence;
  const int block_w = (K.width + 1) / 2;
  auto incidence_at = [&](int u, int v) {
    if (block_incidence.empty()) block_incidence.assign(static_cast<std::size_t>(block_w) * ((K.height + 1) / 2), -1.0f);
    if (u < 0 || v < 0 || u >= K.width || v >= K.height) return std::numeric_limits<double>::quiet_NaN();
    float& cached = block_incidence[static_cast<std::size_t>(v / 2) * block_w + u / 2];
    if (cached == -1.0f) cached = static_cast<float>(surface_incidence_rad(depth.z, K, u, v, config.sensor, config.sigma_factor));
    return static_cast<double>(cached);
  };
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const PointT& p = cloud.points[i];
    if (!is_valid(p) || p.z > config.max_range_m) continue;
    const auto [u, v] = pixel_of(i, p);
    if (!trusted_at(u, v)) continue;
    const Eigen::Vector3d w = (Tf * p.getVector3fMap()).cast<double>();
    const long idx = grid.index_of(w);
    if (grid.at(idx) != background::Occupancy::kFree) continue;
    const double shift = measured_pose.shift_at(w);
    const double gap = kHalfDiagonal * res + map_tolerance_m(config, p.z, shift);
    if (surface_within(grid, idx, w, gap, kHeadOnRing)) continue;
    if (config.incidence_aware) {
      // The depth of a surface seen at a grazing angle is known only coarsely along its ray, and
      // so is the free space that rays running along it carved: the claim must clear that too.
      const double incidence = incidence_at(u, v);
      if (std::isfinite(incidence)) {
        const double sigma = config.sensor.sigma_along_ray(p.z, incidence, std::min(K.fx, K.fy));
        const double reach = kHalfDiagonal * res + map_tolerance_from_sigma(config, sigma, p.z, shift);
        if (reach > (kMaxRing + 0.5) * res || surface_within(grid, idx, w, reach, kMaxRing)) continue;
      }
    }
    // Two cameras' versions of one surface lie within both their tolerances of each other, plus
    // what this frame's measured disagreement with the map (its robust RMS residual) explains.
    if (witness != nullptr &&
        !claims_new_surface(grid, T.translation(), w, *witness, camera, 2 * gap + config.sigma_factor * measured_pose.rms_residual_m))
      continue;
    out.added.push_back(static_cast<int>(i));
    out.added_gap_m.push_back(static_cast<float>(gap));
  }
  out.added_ms = ms_since(t1);

  // 3. Removed (missing_surfaces).
  const auto t2 = Clock::now();
  out.missing = missing_surfaces(grid, T, K, config, depth, trusted_at, measured_pose, witness, camera, res);
  if (dark != nullptr && config.see_through_dark) {
    missing_dark(grid, T, K, config, depth, trusted_at, measured_pose, *dark, camera, out.missing);
  }
  out.missing_ms = ms_since(t2);
  return out;
}

Result<Mismatch> mismatch_same_camera(const Cloud& before, const Cloud& after, const Config& config) {
  if (before.height <= 1 || after.height <= 1) return invalid_argument("same-camera diff: both clouds must be organized");
  if (before.width != after.width || before.height != after.height) {
    return invalid_argument("same-camera diff: BEFORE is " + std::to_string(before.width) + "x" + std::to_string(before.height) +
                            ", AFTER is " + std::to_string(after.width) + "x" + std::to_string(after.height));
  }
  const int w = static_cast<int>(after.width), h = static_cast<int>(after.height);
  // +1 added, -1 removed, 0 nothing; pixels without depth on either side claim nothing.
  std::vector<std::int8_t> change(static_cast<std::size_t>(w) * h, 0);
  std::vector<float> gap(change.size(), 0.f);
  for (std::size_t i = 0; i < change.size(); ++i) {
    const PointT &b = before.points[i], &a = after.points[i];
    if (!is_valid(a) || !is_valid(b) || a.z <= 0 || b.z <= 0) continue;
    if (a.z < b.z - tolerance_m(config, a.z)) {
      change[i] = 1;
      gap[i] = b.z - a.z;
    } else if (b.z < a.z - tolerance_m(config, b.z)) {
      change[i] = -1;
      gap[i] = a.z - b.z;
    }
  }
  Mismatch out;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      if (change[i] == 0) continue;
      int same = 0;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) {
          if ((du == 0 && dv == 0) || u + du < 0 || v + dv < 0 || u + du >= w || v + dv >= h) continue;
          same += change[static_cast<std::size_t>(v + dv) * w + (u + du)] == change[i] ? 1 : 0;
        }
      if (same < config.min_changed_neighbours) continue;
      if (change[i] > 0) {
        out.added.push_back(static_cast<int>(i));
        out.added_gap_m.push_back(gap[i]);
      } else {
        out.removed_points.push_back(static_cast<int>(i));
      }
    }
  return out;
}

}  // namespace scenewatch::change
