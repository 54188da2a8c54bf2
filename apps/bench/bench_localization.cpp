// Localization (issue 29): the camera placed against the memory on the real 7-Scenes kitchen
// (redkitchen_long, 250 frames), in each mode, against the recording's own poses; then dense
// frame-to-frame alignment side by side with OpenCV's RgbdICPOdometry and PCL's GICP on the same
// pairs, on accuracy and time.
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>

#include <pcl/filters/voxel_grid.h>
#include <pcl/registration/gicp.h>

#ifdef SCENEWATCH_BENCH_HAS_OPENCV_RGBD
#include <opencv2/rgbd.hpp>
#endif

#include "bench.h"
#include "scenewatch/background/appearance.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/localization/localizer.h"
#include "scenewatch/localization/pose_error.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"

namespace scenewatch::bench {
namespace {


struct Errors {
  std::vector<double> m, deg;
};

void add_error(Errors& e, const Pose& estimate, const Pose& truth) {
  const auto d = background::view_distance(estimate, truth);
  e.m.push_back(d.translation_m);
  e.deg.push_back(d.rotation_deg);
}


struct Trajectory {
  std::vector<Pose> used;
  std::size_t lost = 0;
  std::vector<double> ms;
};

// Runs the localizer over the recording as the pipeline does: each placed frame may become a
// keyframe of the memory (AppearanceMemory's default spacing) at the pose it was placed at; a lost
// camera is relocalized against the keyframes.
using FrameLoader = std::function<Result<Frame>(std::size_t)>;

Trajectory run(const FrameLoader& load, const std::vector<std::optional<Pose>>& given, LocalizationMode mode,
               localization::Config lc = {}) {
  background::AppearanceMemory memory;
  localization::Localizer localizer(lc);
  Trajectory out;
  for (std::size_t i = 0; i < given.size(); ++i) {
    auto frame = load(i);
    if (!frame) {
      std::fprintf(stderr, "  %s\n", frame.error().message.c_str());
      out.used.push_back(Pose::Identity());
      continue;
    }
    frame->T_world_camera = given[i];
    frame->localization = mode;
    const auto r = localizer.localize(*frame, 0, [&](const Pose& p, std::size_t n) { return memory.nearest(p, n); },
                                      [&] { return memory.keyframes(); });
    out.used.push_back(r.T_world_camera);
    out.ms.push_back(r.ms);
    if (!r.placed()) {
      ++out.lost;
      continue;
    }
    frame->T_world_camera = r.T_world_camera;
    if (auto kf = background::keyframe_from_frame(*frame)) (void)memory.consider(std::move(*kf));
  }
  return out;
}

void print_errors(const char* what, const Errors& e, const Trajectory& t) {
  std::printf("  %-58s median %5.1f mm %5.2f deg | p95 %5.1f mm %5.2f deg | max %6.1f mm | lost %3zu | %5.1f ms/frame\n", what,
              1000 * median(e.m), median(e.deg), 1000 * quantile(e.m, 0.95), quantile(e.deg, 0.95),
              1000 * quantile(e.m, 1.0), t.lost, median(t.ms));
}

Trajectory run(const io::Sequence& seq, const std::vector<std::optional<Pose>>& given, LocalizationMode mode,
               localization::Config lc = {}) {
  return run([&](std::size_t i) { return io::load_sequence_frame(seq, i); }, given, mode, std::move(lc));
}


// The simulator, whose truth is exact (unlike a reconstruction's poses): the `clutter` table seen
// by a camera moving on half a circle, 90 frames at 640x480.
int run_simulated() {
  auto loaded = sim::load_scenario(std::filesystem::path(SCENEWATCH_SOURCE_DIR) / "sample_clouds/scenarios/clutter.yaml");
  if (!loaded) return std::fprintf(stderr, "localization: %s\n", loaded.error().message.c_str()), 1;
  const sim::Scenario scenario = sim::with_frames(sim::with_resolution(*loaded, 640, 480), 90);
  auto simulator = sim::Simulator::create(scenario);
  if (!simulator) return std::fprintf(stderr, "localization: %s\n", simulator.error().message.c_str()), 1;
  std::vector<Frame> frames;
  std::vector<Pose> truth;
  for (int f = 0; f < simulator->frame_count(0); ++f) {
    const sim::SimFrame rendered = simulator->render(0, f);
    auto frame = sim::as_frame(rendered, scenario.intrinsics, f / 30.0);
    if (!frame) return std::fprintf(stderr, "localization: %s\n", frame.error().message.c_str()), 1;
    frames.push_back(std::move(*frame));
    truth.push_back(rendered.truth.T_world_camera);
  }
  const FrameLoader load = [&](std::size_t i) -> Result<Frame> { return frames[i]; };
  const auto score = [&](const char* what, const std::vector<Pose>& given, std::optional<localization::Config> lc) {
    Errors e;
    Trajectory t{given, 0, {0.0}};
    if (lc) t = run(load, std::vector<std::optional<Pose>>(given.begin(), given.end()), LocalizationMode::kRefine, *lc);
    for (std::size_t i = 0; i < truth.size(); ++i) add_error(e, t.used[i], truth[i]);
    print_errors(what, e, t);
  };
  std::printf("\nlocalization: the simulator's clutter table, %zu frames at 640x480 on half a circle, errors against the exact truth\n",
              truth.size());
  score("refine, exact poses given (its correction)", truth, localization::Config{});
  localization::Config finest_geometric;
  finest_geometric.alignment.photometric_on_finest_level = false;
  score("refine, exact poses, finest level geometry only", truth, finest_geometric);
  localization::Config told_noise;
  told_noise.noise_m = 0.005;
  told_noise.noise_deg = 0.25;
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto noisy = localization::with_noise(truth, 0.005, 0.25, seed);
    const std::string label = "noise 5 mm + 0.25 deg per frame, seed " + std::to_string(seed);
    score(("given: " + label).c_str(), noisy, std::nullopt);
    score(("refine, default: " + label).c_str(), noisy, localization::Config{});
    score(("refine, noise configured: " + label).c_str(), noisy, told_noise);
  }
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto drifted = localization::with_drift(truth, 0.001, 0.05, seed);
    const std::string label = "drift 1 mm + 0.05 deg/frame, seed " + std::to_string(seed);
    score(("given: " + label).c_str(), drifted, std::nullopt);
    score(("refine, default: " + label).c_str(), drifted, localization::Config{});
  }
  return 0;
}

int run_trajectories(const io::Sequence& seq, const std::vector<Pose>& truth) {
  std::printf("\nlocalization: the 250 frames of redkitchen_long (every second frame of the recording), errors against its poses\n");
  {
    std::vector<std::optional<Pose>> given(truth.begin(), truth.end());
    const Trajectory t = run(seq, given, LocalizationMode::kRefine);
    Errors e;
    for (std::size_t i = 0; i < truth.size(); ++i) add_error(e, t.used[i], truth[i]);
    print_errors("refine, the recording's own poses (correction)", e, t);
    localization::Config finest_geometric;
    finest_geometric.alignment.photometric_on_finest_level = false;
    const Trajectory g = run(seq, given, LocalizationMode::kRefine, finest_geometric);
    Errors eg;
    for (std::size_t i = 0; i < truth.size(); ++i) add_error(eg, g.used[i], truth[i]);
    print_errors("  the same, finest level geometry only", eg, g);
    localization::Config every_pixel;
    every_pixel.alignment.strides = {1, 1, 1};
    const Trajectory a = run(seq, given, LocalizationMode::kRefine, every_pixel);
    Errors ea;
    for (std::size_t i = 0; i < truth.size(); ++i) add_error(ea, a.used[i], truth[i]);
    print_errors("  the same, every pixel on every level", ea, a);
  }
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto drifted = localization::with_drift(truth, 0.003, 0.15, seed);
    std::vector<std::optional<Pose>> given(drifted.begin(), drifted.end());
    Errors before;
    for (std::size_t i = 0; i < truth.size(); ++i) add_error(before, drifted[i], truth[i]);
    const Trajectory none{drifted, 0, {0.0}};
    const std::string label = "drift 3 mm + 0.15 deg/frame, seed " + std::to_string(seed);
    print_errors(("given: " + label).c_str(), before, none);
    for (const bool told : {false, true}) {
      localization::Config lc;
      if (told) {  // the odometry's drift rate, as a user who knows it would configure it
        lc.drift_m_per_frame = 0.003;
        lc.drift_deg_per_frame = 0.15;
      }
      const Trajectory t = run(seq, given, LocalizationMode::kRefine, lc);
      Errors e;
      for (std::size_t i = 0; i < truth.size(); ++i) add_error(e, t.used[i], truth[i]);
      print_errors(((told ? "refine, drift configured: " : "refine, default drift: ") + label).c_str(), e, t);
    }
  }
  struct TrackCase {
    const char* label;
    bool photometric_finest;
    std::vector<int> strides;
  };
  for (const TrackCase& c : {TrackCase{"track, no poses, from an empty memory", true, {1, 2, 2}},
                             TrackCase{"  the same, finest level geometry only", false, {1, 2, 2}},
                             TrackCase{"  the same, every second pixel on the finest level only", true, {1, 1, 2}},
                             TrackCase{"  the same, every pixel on every level", true, {1, 1, 1}}}) {
    std::vector<std::optional<Pose>> none(truth.size());
    localization::Config lc;
    lc.alignment.photometric_on_finest_level = c.photometric_finest;
    lc.alignment.strides = c.strides;
    const Trajectory t = run(seq, none, LocalizationMode::kTrack, lc);
    std::printf("  %-58s RMSE %5.1f mm over %zu frames (both relative to their first pose) | lost %3zu | %5.1f ms/frame\n",
                c.label, 1000 * localization::trajectory_rmse_m(t.used, truth), truth.size(), t.lost, median(t.ms));
  }
  return 0;
}

// ---- pairs: ours against OpenCV and PCL ----

struct PairResult {
  Errors errors;
  std::vector<double> ms;
  std::size_t failed = 0;
};

void print_pair(const char* what, const PairResult& r) {
  std::printf("  %-44s median %5.1f mm %5.2f deg | p95 %6.1f mm %5.2f deg | failed %2zu | median %6.1f ms\n", what,
              1000 * median(r.errors.m), median(r.errors.deg), 1000 * quantile(r.errors.m, 0.95), quantile(r.errors.deg, 0.95),
              r.failed, median(r.ms));
}

pcl::PointCloud<pcl::PointXYZ>::Ptr thinned(const Cloud& c, float leaf) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr xyz(new pcl::PointCloud<pcl::PointXYZ>);
  for (const auto& p : c.points)
    if (is_valid(p) && p.z > 0.4f && p.z < 4.5f) xyz->push_back({p.x, p.y, p.z});
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setLeafSize(leaf, leaf, leaf);
  grid.setInputCloud(xyz);
  pcl::PointCloud<pcl::PointXYZ>::Ptr out(new pcl::PointCloud<pcl::PointXYZ>);
  grid.filter(*out);
  return out;
}

#ifdef SCENEWATCH_BENCH_HAS_OPENCV_RGBD
struct CvImages {
  cv::Mat gray, depth, mask;
};
CvImages cv_images(const Cloud& c) {
  CvImages m{cv::Mat(c.height, c.width, CV_8UC1), cv::Mat(c.height, c.width, CV_32FC1), cv::Mat(c.height, c.width, CV_8UC1)};
  for (std::uint32_t v = 0; v < c.height; ++v)
    for (std::uint32_t u = 0; u < c.width; ++u) {
      const auto& p = c.at(u, v);
      m.gray.at<std::uint8_t>(v, u) = static_cast<std::uint8_t>((p.r + p.g + p.b) / 3);
      const bool ok = is_valid(p) && p.z > 0.4f && p.z < 4.5f;
      m.depth.at<float>(v, u) = ok ? p.z : std::numeric_limits<float>::quiet_NaN();
      m.mask.at<std::uint8_t>(v, u) = ok ? 255 : 0;
    }
  return m;
}
#endif

int run_pairs(const io::Sequence& seq, const std::vector<Pose>& truth) {
  // Pairs 3 list entries apart (6 frames of the 30 Hz recording, 0.2 s), every 5th entry.
  const std::size_t gap = 3;
  std::printf("\nlocalization: frame-to-frame alignment, %zu pairs 0.2 s apart, from the identity, errors against the recording's relative poses\n",
              (seq.frames.size() - gap + 4) / 5);
  PairResult ours, ours_finest_strided, ours_every_pixel, ours_coarse_photometric, ours_geometric, opencv, gicp, none;
  std::vector<double> reference_ms, current_ms;
  localization::AlignmentConfig geometric;
  geometric.photometric_weight = 0;
  const localization::Config defaults;
  localization::AlignmentConfig finest_geometric = defaults.alignment;
  finest_geometric.photometric_on_finest_level = false;
  localization::AlignmentConfig every_pixel = defaults.alignment;  // the default before 2026-12-02
  every_pixel.strides = {1, 1, 1};
  localization::AlignmentConfig finest_strided = defaults.alignment;  // the default before 2026-12-03
  finest_strided.strides = {1, 1, 2};
  const SensorModel sensor;
  for (std::size_t i = 0; i + gap < seq.frames.size(); i += 5) {
    auto a = io::load_sequence_frame(seq, i);
    auto b = io::load_sequence_frame(seq, i + gap);
    if (!a || !b) continue;
    const Pose truth_ab = truth[i].inverse() * truth[i + gap];  // T_a_b: b's camera in a's
    add_error(none.errors, Pose::Identity(), truth_ab);
    localization::RgbdPyramid ref, cur;
    reference_ms.push_back(
        time_ms([&] { ref = localization::build_pyramid(*a->cloud, *a->intrinsics, sensor, defaults.pyramid, true); }));
    current_ms.push_back(
        time_ms([&] { cur = localization::build_pyramid(*b->cloud, *b->intrinsics, sensor, defaults.pyramid, false); }));
    localization::Alignment r;
    ours.ms.push_back(current_ms.back() +
                      time_ms([&] { r = localization::align(ref, cur, Pose::Identity(), sensor, defaults.alignment); }));
    add_error(ours.errors, r.T_reference_current, truth_ab);
    ours_finest_strided.ms.push_back(current_ms.back() +
                                     time_ms([&] { r = localization::align(ref, cur, Pose::Identity(), sensor, finest_strided); }));
    add_error(ours_finest_strided.errors, r.T_reference_current, truth_ab);
    ours_every_pixel.ms.push_back(current_ms.back() +
                                  time_ms([&] { r = localization::align(ref, cur, Pose::Identity(), sensor, every_pixel); }));
    add_error(ours_every_pixel.errors, r.T_reference_current, truth_ab);
    ours_coarse_photometric.ms.push_back(
        current_ms.back() + time_ms([&] { r = localization::align(ref, cur, Pose::Identity(), sensor, finest_geometric); }));
    add_error(ours_coarse_photometric.errors, r.T_reference_current, truth_ab);
    ours_geometric.ms.push_back(current_ms.back() +
                                time_ms([&] { r = localization::align(ref, cur, Pose::Identity(), sensor, geometric); }));
    add_error(ours_geometric.errors, r.T_reference_current, truth_ab);
#ifdef SCENEWATCH_BENCH_HAS_OPENCV_RGBD
    {
      const CvImages ca = cv_images(*a->cloud), cb = cv_images(*b->cloud);
      const Intrinsics& K = *a->intrinsics;
      const cv::Mat camera = (cv::Mat_<float>(3, 3) << K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
      cv::Mat Rt;
      bool ok = false;
      opencv.ms.push_back(time_ms([&] {
        auto odometry = cv::rgbd::RgbdICPOdometry::create(camera);
        // src = b, dst = a: Rt maps b's points into a's frame, as T_a_b.
        ok = odometry->compute(cb.gray, cb.depth, cb.mask, ca.gray, ca.depth, ca.mask, Rt);
      }));
      if (!ok) {
        ++opencv.failed;
      } else {
        Eigen::Matrix4d m;
        for (int r0 = 0; r0 < 4; ++r0)
          for (int c0 = 0; c0 < 4; ++c0) m(r0, c0) = Rt.at<double>(r0, c0);
        add_error(opencv.errors, pose_from_matrix(m), truth_ab);
      }
    }
#endif
    {
      pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> g;
      pcl::PointCloud<pcl::PointXYZ> aligned;
      gicp.ms.push_back(time_ms([&] {
        g.setInputSource(thinned(*b->cloud, 0.02f));
        g.setInputTarget(thinned(*a->cloud, 0.02f));
        g.align(aligned);
      }));
      if (!g.hasConverged()) ++gicp.failed;
      add_error(gicp.errors, Pose(g.getFinalTransformation().cast<double>()), truth_ab);
    }
  }
  print_pair("no alignment (identity)", none);
  print_pair("scenewatch dense RGB-D (default)", ours);
  print_pair("scenewatch dense, every second pixel on the finest level only", ours_finest_strided);
  print_pair("scenewatch dense, every pixel on every level", ours_every_pixel);
  print_pair("scenewatch dense, finest level geometry only", ours_coarse_photometric);
  print_pair("scenewatch dense, geometry only", ours_geometric);
#ifdef SCENEWATCH_BENCH_HAS_OPENCV_RGBD
  print_pair("OpenCV rgbd::RgbdICPOdometry", opencv);
#else
  std::printf("  OpenCV rgbd::RgbdICPOdometry: not built (libopencv-contrib-dev missing)\n");
#endif
  print_pair("PCL GICP (2 cm voxels)", gicp);
  std::printf("  (ours: the current frame's pyramid (median %.1f ms) plus the alignment; the reference's pyramid, %.1f ms, is built once\n"
              "   per keyframe and kept; OpenCV: both frames' pyramids plus alignment; GICP: thinning both plus alignment; one thread each)\n",
              median(current_ms), median(reference_ms));
  return 0;
}

// Relocalization without a prior (issue 29 item 3): keyframes of files 0-248 at the recording's
// poses, each frame of files 250-498 placed from keyframe features, densely refined and verified.
int run_relocalization(const io::Sequence& seq, const std::vector<Pose>& truth) {
  const std::size_t half = seq.frames.size() / 2;
  background::AppearanceMemory memory;
  for (std::size_t i = 0; i < half; ++i)
    if (auto frame = io::load_sequence_frame(seq, i))
      if (auto kf = background::keyframe_from_frame(*frame)) (void)memory.consider(std::move(*kf));
  const auto keyframes = memory.keyframes();
  localization::Localizer localizer;
  Errors e;
  std::vector<double> ms;
  std::size_t placed = 0, within = 0;
  for (std::size_t i = half; i < seq.frames.size(); ++i) {
    auto frame = io::load_sequence_frame(seq, i);
    if (!frame) continue;
    frame->T_world_camera.reset();
    const auto r = localizer.relocalize(*frame, keyframes);
    ms.push_back(r.relocalization_ms);
    if (!r.placed()) continue;
    ++placed;
    add_error(e, r.T_world_camera, truth[i]);
    if (e.m.back() <= 0.05 && e.deg.back() <= 5.0) ++within;
  }
  const std::size_t n = seq.frames.size() - half;
  std::printf("\nrelocalization: %zu frames of files 250-498 against %zu keyframes of files 0-248, no prior\n", n, keyframes.size());
  std::printf("  placed %zu | within 5 cm / 5 deg %.1f %% | median %5.1f mm %5.2f deg | p95 %5.1f mm | median %5.1f ms, p95 %5.1f ms "
              "(features, matching, RANSAC, dense refinement; one thread)\n",
              placed, 100.0 * within / n, 1000 * median(e.m), median(e.deg), 1000 * quantile(e.m, 0.95), median(ms), quantile(ms, 0.95));
  return 0;
}

}  // namespace

int run_localization(const Options& o) {
  int rc = run_simulated();
  auto seq = io::open_sequence(o.data_dir / "redkitchen_long");
  if (!seq) {
    std::printf("\nlocalization: skipped (%s)\n", seq.error().message.c_str());
    return rc;
  }
  std::vector<Pose> truth;
  for (const auto& f : seq->frames) truth.push_back(f.T_world_camera.value_or(Pose::Identity()));
  rc |= run_pairs(*seq, truth);
  rc |= run_relocalization(*seq, truth);
  rc |= run_trajectories(*seq, truth);
  return rc;
}

}  // namespace scenewatch::bench
