// Two single observations: same-camera per-pixel reasoning, or BEFORE as a map and AFTER against it.
#include "scenewatch/change/diff.h"

#include "scenewatch/change/whole_objects.h"

#include <algorithm>
#include <chrono>
#include <future>

namespace scenewatch::change {
namespace {

Status validate_side(const Frame& f, const char* name) {
  const std::string where = std::string(name) + (f.source.empty() ? std::string() : " ('" + f.source + "')");
  if (!f.cloud || f.cloud->empty()) return invalid_argument(where + ": the cloud is empty");
  if (static_cast<std::size_t>(f.cloud->width) * f.cloud->height != f.cloud->size()) {
    return invalid_argument(where + ": width x height (" + std::to_string(f.cloud->width) + "x" +
                            std::to_string(f.cloud->height) + ") does not match its " + std::to_string(f.cloud->size()) +
                            " points");
  }
  if (count_valid(*f.cloud) == 0) return invalid_argument(where + ": no valid point (all NaN or non-finite)");
  if (f.T_world_camera) {
    if (auto st = validate_rigid(f.T_world_camera->matrix()); !st) return invalid_argument(where + ": pose: " + st.error().message);
  }
  if (f.intrinsics) {
    if (!f.intrinsics->valid()) return invalid_argument(where + ": intrinsics are invalid");
    if (f.cloud->height > 1 && (f.intrinsics->width != static_cast<int>(f.cloud->width) ||
                                f.intrinsics->height != static_cast<int>(f.cloud->height))) {
      return invalid_argument(where + ": intrinsics are for " + std::to_string(f.intrinsics->width) + "x" +
                              std::to_string(f.intrinsics->height) + ", the organized cloud is " +
                              std::to_string(f.cloud->width) + "x" + std::to_string(f.cloud->height));
    }
  }
  return {};
}

bool same_pose(const Frame& a, const Frame& b) {
  const Pose Ta = a.pose_or_identity(), Tb = b.pose_or_identity();
  return (Ta.matrix() - Tb.matrix()).cwiseAbs().maxCoeff() < 1e-6;
}

// Whole-object completion: each frame segmented in its own camera frame (the sensor at the
// origin), each cluster replaced by the objects it belongs to.
std::vector<ChangeCluster> complete(std::vector<ChangeCluster> clusters, const ClusterInput& in, const Intrinsics& K_before,
                                    const segmentation::Config& seg_config, const Config& config) {
  if (clusters.empty()) return clusters;  // nothing to complete: spare the segmentation
  // The frames are independent: BEFORE is segmented on a second thread meanwhile (as the
  // pipeline compares against map and memory at once).
  auto objects_of = [&](const Cloud& cloud) {
    ObjectLabels labels = segment_objects(cloud, seg_config, config.completion_stride_px);
    join_hidden_pieces(labels, cloud, config);
    return labels;
  };
  auto before_future = std::async(std::launch::async, [&] { return objects_of(*in.before_camera); });
  const ObjectLabels after = objects_of(*in.after_camera);
  const ObjectLabels before = before_future.get();
  const CompletionFrame fb{in.before_camera, in.T_world_before, &before, K_before};
  const CompletionFrame fa{in.after_camera, in.T_world_after, &after, in.K_after};
  return complete_clusters(std::move(clusters), fb, fa, config);
}

}  // namespace

const char* to_string(DiffMethod m) { return m == DiffMethod::kSameCamera ? "same-camera" : "map"; }

Result<DiffResult> diff(const Frame& before, const Frame& after, const DiffOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  if (auto st = validate_side(before, "BEFORE"); !st) return st.error();
  if (auto st = validate_side(after, "AFTER"); !st) return st.error();
  if (auto st = validate(options.change); !st) return st.error();
  if (auto st = background::validate(options.map); !st) return st.error();
  if (auto st = segmentation::validate(options.segmentation); !st) return st.error();
  const Cloud& b = *before.cloud;
  const Cloud& a = *after.cloud;
  const bool both_organized = b.height > 1 && a.height > 1;
  if (both_organized && same_pose(before, after) && (b.width != a.width || b.height != a.height) && !options.force_map) {
    return invalid_argument("BEFORE is " + std::to_string(b.width) + "x" + std::to_string(b.height) + " and AFTER is " +
                            std::to_string(a.width) + "x" + std::to_string(a.height) +
                            ": organized clouds from the same camera must have the same size");
  }
  DiffResult result;
  ClusterInput input;
  input.after_camera = &a;
  input.before_camera = &b;
  input.T_world_after = after.pose_or_identity();
  input.T_world_before = before.pose_or_identity();
  auto K = observation_camera(a, after.intrinsics);
  if (!K) return invalid_argument("AFTER: " + K.error().message);
  input.K_after = *K;

  // BEFORE's camera, for completion: AFTER's when it is the same camera (one pixel grid), else
  // its own, or AFTER's when none fits BEFORE (as for the evidence: only BEFORE's pixel regions
  // suffer, and the other-frame test needs an organized cloud anyway).
  Intrinsics K_before = *K;
  if (!(both_organized && same_pose(before, after))) {
    if (auto Kb = observation_camera(b, before.intrinsics)) K_before = *Kb;
  }

  if (both_organized && same_pose(before, after) && !options.force_map) {
    result.method = DiffMethod::kSameCamera;
    auto mm = mismatch_same_camera(b, a, options.change);
    if (!mm) return mm.error();
    result.mismatch = std::move(*mm);
  } else {
    result.method = DiffMethod::kMap;
    background::OccupancyMap map(options.map);
    map.insert(b, before.pose_or_identity());
    Config config = options.change;  // every surface of a one-frame map was hit once
    if (same_pose(before, after)) {  // one unmoved camera: the relative pose is exact
      config.sensor.pose_sigma_m = 0;
      config.sensor.pose_sigma_deg = 0;
      config.measure_pose = false;
    }
    config.min_surface_probability = std::min(config.min_surface_probability, options.map.prob_hit - 1e-3);
    auto mm = mismatch_against_map(map, a, after.pose_or_identity(), *K, config);
    if (!mm) return mm.error();
    result.mismatch = std::move(*mm);
  }
  std::vector<ChangeCluster> clusters = cluster_mismatch(result.mismatch, input, options.change);
  if (options.change.complete_objects) {
    const auto t1 = std::chrono::steady_clock::now();
    clusters = complete(std::move(clusters), input, K_before, options.segmentation, options.change);
    result.completion_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
  }
  result.changes = pair_changes(std::move(clusters), options.change);
  std::uint64_t id = 1;
  for (const auto& c : result.changes) {
    Event e = to_event(c);
    e.id = id++;
    e.stamp_s = after.stamp_s;
    result.events.push_back(std::move(e));
  }
  result.total_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace scenewatch::change
