// The background map's part of a frame: change detection, then insertion (map_stage.h).
#include "map_stage.h"

#include <limits>

#include "frame_sampling.h"
#include "timing.h"
#include "scenewatch/change/objects.h"

namespace scenewatch::pipeline {

namespace {

// The frame without the points of unconfirmed change candidates: an added candidate's own points,
// and every pixel in the region where a removed candidate was seen through (a few pixels wider).
// Without this the insertion would erode a removed object's voxels frame by frame, and the
// candidate would change shape (and lose its move partner) before it is confirmed.
CloudConstPtr without_pending(const Cloud& cloud, const std::vector<change::ChangeCluster>& pending,
                              const Intrinsics& K) {
  auto masked = std::make_shared<Cloud>(cloud);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto blank = [&](std::size_t i) { masked->points[i].x = masked->points[i].y = masked->points[i].z = nan; };
  constexpr int kMarginPx = 3;
  for (const auto& c : pending) {
    if (c.kind == change::ChangeKind::kAdded) {
      for (int i : c.indices) blank(static_cast<std::size_t>(i));
      continue;
    }
    const int u0 = c.region.x - kMarginPx, v0 = c.region.y - kMarginPx;
    const int u1 = c.region.x + c.region.width + kMarginPx, v1 = c.region.y + c.region.height + kMarginPx;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const PointT& p = cloud.points[i];
      if (!is_valid(p) || p.z <= 0) continue;
      const bool organized = cloud.height > 1;
      const int u = organized ? static_cast<int>(i % cloud.width) : static_cast<int>(std::lround(K.fx * p.x / p.z + K.cx));
      const int v = organized ? static_cast<int>(i / cloud.width) : static_cast<int>(std::lround(K.fy * p.y / p.z + K.cy));
      if (u >= u0 && u <= u1 && v >= v0 && v <= v1) blank(i);
    }
  }
  return masked;
}

}  // namespace

MapStage::MapStage(const Config& c, std::shared_ptr<change::PendingIds> pending_ids)
    : map_(c.background), witness_(c.background.resolution_m), dark_(c.background.resolution_m),
      changes_(c.change, std::move(pending_ids)) {}

// Geometric change detection against the map as it stands before this frame. Candidates stay
// out of the map until the persistence filter confirms them, so the comparison keeps being made
// against the model that predates them (OctoMap's log-odds would absorb a new object, or erode
// a removed one, within a few frames). A frame whose region is too large for a dense grid is
// left without change detection.
ChangeOutcome MapStage::detect_changes(const Frame& frame, const Pose& T, const std::optional<Intrinsics>& K,
                                       const change::Config& config, std::uint32_t camera,
                                       std::shared_ptr<const change::DepthView>* dark_depth) {
  const bool prefilled = prefilled_.value_or(false);
  prefilled_.reset();
  ChangeOutcome out;
  if (!K) return out;
  out.K = *K;
  std::shared_lock<std::shared_mutex> read(mutex_);
  bool grid_filled = false;
  if (prefilled && T.matrix() == prefill_T_.matrix() && frame.cloud->size() == prefill_points_) {
    // The pose the copy was filled at, and the frame it was filled for, less what the foreground
    // blanked (the colour registration moves colours, the blanking sets points to NaN, nothing
    // moves a point): its box holds this frame's, when any point is left in range.
    grid_filled = change::any_point_in_range(*frame.cloud, config);
  } else if (prefilled) {
    const auto box = change::comparison_box(*frame.cloud, T, config, map_.resolution());
    const double eps = 1e-6 * map_.resolution();  // as the fill's key range: faces on a voxel boundary
    grid_filled = box && map_grid_.index_of(box->min.array() + eps) >= 0 && map_grid_.index_of(box->max.array() - eps) >= 0;
  }
  auto mismatch = change::mismatch_against_map(map_, *frame.cloud, T, *K, config, &map_grid_,
                                               config.witness_per_camera ? &witness_ : nullptr, camera, grid_filled, &dark_);
  if (!mismatch) return out;
  // The frame's own holes, against the same map (the copy stays as it is until the next frame's
  // fill): what it looked into and got nothing back from. Recorded with the witness, by whichever
  // thread is free first.
  if (dark_depth != nullptr && config.see_through_dark) *dark_depth = mismatch->depth;
  {
    std::lock_guard<std::mutex> lock(pose_mutex_);
    last_pose_[camera] = mismatch->pose;
  }
  change::ClusterInput input;
  input.after_camera = frame.cloud.get();
  input.T_world_after = T;
  input.K_after = *K;
  out.confirmed = changes_.update(change::cluster_mismatch(*mismatch, input, config), &out.pending, &out.absorbed, camera);
  return out;
}

void MapStage::prefill(const Frame& frame, const Pose& T, const change::Config& config) {
  prefill_T_ = T;
  prefill_points_ = frame.cloud ? frame.cloud->size() : 0;
  std::shared_lock<std::shared_mutex> read(mutex_);
  const auto box = frame.cloud ? change::comparison_box(*frame.cloud, T, config, map_.resolution()) : std::nullopt;
  prefilled_ = box && map_.fill_dense_grid(*box, map_grid_, config.max_grid_voxels).ok();
}

ChangeOutcome MapStage::update(const Frame& frame, const Pose& T, const std::optional<Intrinsics>& K, const Config& config,
                               bool detect, FrameResult& result, std::uint32_t camera, bool record_dark) {
  ChangeOutcome changed;
  std::shared_ptr<const change::DepthView> dark_depth;  // the frame's depth, for the dark space
  if (detect) {
    const auto t_change = Clock::now();
    changed = detect_changes(frame, T, K, config.change, camera, record_dark ? &dark_depth : nullptr);
    result.change_ms = ms_since(t_change);
    result.change_candidates = changes_.candidates();
  }
  CloudConstPtr to_insert = frame.cloud;
  if (!changed.pending.empty()) to_insert = without_pending(*frame.cloud, changed.pending, changed.K);
  const auto t_ins = Clock::now();
  const background::Config& b = config.background;
  const int stride = sample_stride(frame, K, b.resolution_m, b.max_range_m, b.insert_stride_px);
  // The witness and the octree are apart: the frame's surfaces are witnessed by whichever thread
  // is free first (witness_frame()), while the insertion runs or after it. Then the surfaces of
  // confirmed removals are forgotten, as they were after the witness before.
  {
    WitnessJob job{to_insert, T, camera, stride, config.change.witness_per_camera, {}, std::move(dark_depth), &config.change};
    for (const auto& c : changed.confirmed)
      if (c.before) job.forget.push_back(c.before->points_world);
    std::lock_guard<std::mutex> lock(witness_mutex_);
    witness_job_ = std::move(job);
  }
  std::unique_lock<std::shared_mutex> write(mutex_);
  result.insert_stats = map_.insert(*to_insert, T, stride);
  for (const auto& c : changed.confirmed) {
    if (c.before) map_.set_voxels(c.before->points_world, background::Occupancy::kFree);
    if (c.after) map_.set_voxels(c.after->points_world, background::Occupancy::kOccupied);
  }
  for (const auto& c : changed.absorbed) {
    map_.set_voxels(c.points_world, c.kind == change::ChangeKind::kAdded ? background::Occupancy::kOccupied
                                                                        : background::Occupancy::kFree);
  }
  result.insert_ms = ms_since(t_ins);
  return changed;
}

void MapStage::witness_frame() {
  std::lock_guard<std::mutex> lock(witness_mutex_);  // a second caller waits until the job is done
  if (!witness_job_) return;
  const WitnessJob job = std::move(*witness_job_);
  witness_job_.reset();
  if (job.record) witness_.witness(*job.cloud, job.T, job.camera, job.stride);
  if (job.dark_depth) dark_.record(map_grid_, *job.dark_depth, job.T, *job.change_config, job.camera);
  for (const auto& points : job.forget) {
    witness_.forget(points);
    dark_.forget(points);
  }
}

std::function<double(const std::vector<Eigen::Vector3d>&, const Eigen::Vector3d&)> MapStage::occupied_fraction(
    const change::Config& change_config, std::uint32_t camera_id) {
  change::PoseAgreement pose;
  {
    std::lock_guard<std::mutex> lock(pose_mutex_);
    if (auto it = last_pose_.find(camera_id); it != last_pose_.end()) pose = it->second;
  }
  return [this, change_config, pose](const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& camera) {
    std::shared_lock<std::shared_mutex> read(mutex_);
    const double step = 0.5 * map_.resolution();
    std::size_t n = 0;
    for (const auto& p : pts) {
      const Eigen::Vector3d ray = p - camera;
      const double range = ray.norm();
      const double reach = change::map_tolerance_m(change_config, range, pose.shift_at(p));
      bool on = map_.query(p) == background::Occupancy::kOccupied;
      for (double t = step; !on && range > 0 && t <= reach + 1e-9; t += step) {
        const Eigen::Vector3d d = (t / range) * ray;
        on = map_.query(p + d) == background::Occupancy::kOccupied || map_.query(p - d) == background::Occupancy::kOccupied;
      }
      n += on ? 1 : 0;
    }
    return pts.empty() ? 0.0 : static_cast<double>(n) / pts.size();
  };
}

void MapStage::reset() {
  prefilled_.reset();
  {
    std::lock_guard<std::mutex> lock(witness_mutex_);
    witness_job_.reset();
  }
  {
    std::unique_lock<std::shared_mutex> write(mutex_);
    map_.reset();
    witness_.reset();
    dark_.reset();
  }
  {
    std::lock_guard<std::mutex> lock(pose_mutex_);
    last_pose_.clear();
  }
  changes_.reset();
}

void MapStage::replace(background::OccupancyMap map) {
  prefilled_.reset();
  {
    std::lock_guard<std::mutex> lock(witness_mutex_);
    witness_job_.reset();
  }
  {
    std::unique_lock<std::shared_mutex> write(mutex_);
    map_ = std::move(map);
    witness_ = change::SurfaceWitness(map_.resolution());  // the loaded surfaces: seen by none of this session
    dark_ = change::DarkSpace(map_.resolution());
  }
  {
    std::lock_guard<std::mutex> lock(pose_mutex_);
    last_pose_.clear();
  }
  changes_.reset();
}

}  // namespace scenewatch::pipeline
