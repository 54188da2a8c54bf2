// The hand detector against the simulator's exact labels, against two real recordings (hrt1)
// labelled by eye, and against real scenes without anyone in them (mOSD, 7-Scenes).
#include "scenewatch/foreground/hand_detector.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "scenewatch/io/image_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::foreground {
namespace {

/// When SCENEWATCH_HAND_DUMP names a folder, the tests write each frame with its labels painted
/// over it there (hand red, arm yellow, person blue): for looking, not for checking.
void dump(const Cloud& cloud, const HandDetection& d, const std::string& name) {
  const char* dir = std::getenv("SCENEWATCH_HAND_DUMP");
  if (dir == nullptr || d.labels.empty()) return;
  ColorImage image;
  image.width = d.width;
  image.height = d.height;
  image.rgb.resize(3 * cloud.size());
  const std::uint8_t paint[4][3] = {{0, 0, 0}, {255, 0, 0}, {255, 255, 0}, {0, 80, 255}};
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const std::uint8_t rgb[3] = {cloud.points[i].r, cloud.points[i].g, cloud.points[i].b};
    const int label = static_cast<int>(d.labels[i]);
    for (int c = 0; c < 3; ++c) {
      image.rgb[3 * i + c] = label == 0 ? rgb[c] : static_cast<std::uint8_t>((rgb[c] + 2 * paint[label][c]) / 3);
    }
  }
  (void)io::write_color_png(std::filesystem::path(dir) / (name + ".png"), image);
}

std::string describe(const HandDetection& d) {
  std::string s;
  char text[200];
  for (const Hand& h : d.hands) {
    std::snprintf(text, sizeof text, " [hand %.2f %s %d,%d %dx%d, %zu px, tip %zu px, %.3f m2, elong %.1f, %.2f x %.3f m]", h.score,
                  h.enters_from_border ? "border" : "free", h.region.x, h.region.y, h.region.width, h.region.height,
                  h.indices.size(), h.tip_indices.size(), h.area_m2, h.elongation, h.length_m, h.width_m);
    s += text;
  }
  std::snprintf(text, sizeof text, " person %zu px, %.2f ms", d.person_indices.size(), d.ms);
  return s + text;
}

/// The detector's CPU time, all threads: on a shared machine wall-clock time measures the load.
double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

HandDetection timed_detect(const Cloud& cloud, std::vector<double>* cpu_ms) {
  const double t0 = process_cpu_ms();
  HandDetection d = detect_hands(cloud, HandConfig{});
  cpu_ms->push_back(process_cpu_ms() - t0);
  return d;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// ---------------------------------------------------------------------------------------------
// Simulator: exact hand labels (kLabelHand covers hand and forearm).

struct PixelScore {
  std::size_t true_positive = 0, detected = 0, truth = 0;
  double precision() const { return detected ? static_cast<double>(true_positive) / detected : 1.0; }
  double recall() const { return truth ? static_cast<double>(true_positive) / truth : 1.0; }
};

TEST(HandDetector, SimulatedHandPixels) {
  auto scenario = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios/hand_picks_cup_upright.yaml");
  ASSERT_TRUE(scenario.ok()) << scenario.error().message;
  auto simulator = sim::Simulator::create(*scenario);
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  PixelScore total;
  int frames = 0, found = 0;
  std::vector<double> ms, cpu_ms;
  for (int f = 0; f < simulator->frame_count(0); f += 4) {
    const sim::SimFrame rendered = simulator->render(0, f);
    auto cloud = io::rgbd_to_cloud(rendered.color, rendered.depth, simulator->scenario().intrinsics);
    ASSERT_TRUE(cloud.ok());
    const HandDetection d = timed_detect(**cloud, &cpu_ms);
    ASSERT_EQ(d.labels.size(), (*cloud)->size());
    PixelScore frame;
    for (std::size_t i = 0; i < (*cloud)->size(); ++i) {
      const bool truth = rendered.labels.labels[i] == sim::kLabelHand && is_valid((*cloud)->points[i]);
      const bool detected = d.labels[i] == AgentLabel::kHand || d.labels[i] == AgentLabel::kArm;
      frame.truth += truth, frame.detected += detected, frame.true_positive += truth && detected;
    }
    // The simulator has no person: nothing may be grown into a body.
    EXPECT_TRUE(d.person_indices.empty()) << "frame " << f;
    std::printf("sim %03d: truth %zu px, detected %zu, precision %.3f recall %.3f%s\n", f, frame.truth, frame.detected,
                frame.precision(), frame.recall(), describe(d).c_str());
    dump(**cloud, d, "sim_" + std::to_string(f));
    total.truth += frame.truth, total.detected += frame.detected, total.true_positive += frame.true_positive;
    ++frames;
    found += !d.hands.empty();
    ms.push_back(d.ms);
  }
  std::printf("sim: hand found in %d of %d frames; pixels precision %.3f recall %.3f; median per %dx%d frame %.2f ms CPU, "
              "%.2f ms wall-clock\n", found, frames, total.precision(), total.recall(), scenario->intrinsics.width,
              scenario->intrinsics.height, median(cpu_ms), median(ms));
  // Measured: 29 of 31 (the first two frames show only fingers, no forearm), precision 0.93,
  // recall 0.89 (fingers behind the held cup are cut off from the arm and left out).
  EXPECT_GE(found, 28);
  EXPECT_GE(total.precision(), 0.90);
  EXPECT_GE(total.recall(), 0.85);
}

/// The grid step trades speed for detail; the hand is found at every step.
TEST(HandDetector, SimulatedHandAtOtherGridSteps) {
  auto scenario = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios/hand_picks_cup_upright.yaml");
  ASSERT_TRUE(scenario.ok()) << scenario.error().message;
  auto simulator = sim::Simulator::create(*scenario);
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  const sim::SimFrame rendered = simulator->render(0, 60);
  auto cloud = io::rgbd_to_cloud(rendered.color, rendered.depth, simulator->scenario().intrinsics);
  ASSERT_TRUE(cloud.ok());
  for (int step : {1, 2, 3, 4}) {
    HandConfig config;
    config.grid_step = step;
    const HandDetection d = detect_hands(**cloud, config);
    PixelScore score;
    for (std::size_t i = 0; i < (*cloud)->size(); ++i) {
      const bool truth = rendered.labels.labels[i] == sim::kLabelHand && is_valid((*cloud)->points[i]);
      const bool detected = d.labels[i] == AgentLabel::kHand || d.labels[i] == AgentLabel::kArm;
      score.truth += truth, score.detected += detected, score.true_positive += truth && detected;
    }
    std::printf("grid step %d: precision %.3f recall %.3f,%s\n", step, score.precision(), score.recall(), describe(d).c_str());
    ASSERT_EQ(d.hands.size(), 1u) << "step " << step;
    EXPECT_GE(score.precision(), 0.8) << "step " << step;
    EXPECT_GE(score.recall(), 0.75) << "step " << step;
  }
}

/// A skin-coloured box and a skin-coloured bar lying on the table, away from the border, and no
/// hand: neither is a hand.
TEST(HandDetector, SkinColouredObjectsOnTheTableAreNotHands) {
  auto scenario = sim::parse_scenario(R"(
name: skin_objects
seed: 5
objects:
  - {id: 1, name: skin_box, shape: box, size_m: [0.12, 0.08, 0.06], color: [222, 172, 142], position: [0.0, 0.0]}
  - {id: 2, name: skin_bar, shape: box, size_m: [0.3, 0.05, 0.05], color: [205, 150, 122], position: [0.1, 0.25], yaw_deg: 30}
  - {id: 3, name: cup, shape: cylinder, radius_m: 0.04, height_m: 0.1, color: [230, 230, 225], position: [-0.2, -0.15]}
frames: 3
camera: {type: static, position: [-0.75, -0.3, 1.45], target: [0.05, 0.0, 0.8]}
)");
  ASSERT_TRUE(scenario.ok()) << scenario.error().message;
  auto simulator = sim::Simulator::create(*scenario);
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  for (int f = 0; f < simulator->frame_count(0); ++f) {
    const sim::SimFrame rendered = simulator->render(0, f);
    auto cloud = io::rgbd_to_cloud(rendered.color, rendered.depth, simulator->scenario().intrinsics);
    ASSERT_TRUE(cloud.ok());
    const HandDetection d = detect_hands(**cloud, HandConfig{});
    std::printf("skin objects %d:%s\n", f, describe(d).c_str());
    dump(**cloud, d, "skin_objects_" + std::to_string(f));
    EXPECT_TRUE(d.hands.empty()) << "frame " << f << describe(d);
    EXPECT_TRUE(d.person_indices.empty()) << "frame " << f;
  }
}

// ---------------------------------------------------------------------------------------------
// hrt1: a real person picks a toy off a table. Rough rectangles of the hand proper (fingers and
// palm), x0 y0 x1 y1 in pixels, labelled by eye by this test's author on a grid overlay of every
// colour frame (not from the detector). The hand is in view in every frame of both recordings.

struct HandBox {
  int frame;
  bool in_view;
  int x0, y0, x1, y1;
};

// Centres read off the frames, boxes +-50 px across and +-45 px down.
#define BOX(f, cx, cy) HandBox{f, true, (cx) - 50, (cy) - 45, (cx) + 50, (cy) + 45}
const std::vector<HandBox> kPickToy1 = {
    BOX(0, 454, 290),  BOX(1, 454, 290),  BOX(2, 454, 290),  BOX(3, 454, 290),  BOX(4, 460, 295),
    BOX(5, 460, 295),  BOX(6, 460, 295),  BOX(7, 460, 295),  BOX(8, 460, 302),  BOX(9, 460, 302),
    BOX(10, 460, 302), BOX(11, 460, 302), BOX(12, 465, 320), BOX(13, 465, 320), BOX(14, 465, 320),
    BOX(15, 465, 320), BOX(16, 460, 327), BOX(17, 460, 327), BOX(18, 460, 327), BOX(19, 460, 327),
    BOX(20, 460, 329), BOX(21, 460, 329), BOX(22, 460, 325), BOX(23, 462, 294), BOX(24, 453, 264),
    BOX(25, 454, 246), BOX(26, 452, 225), BOX(27, 445, 207), BOX(28, 413, 195), BOX(29, 397, 195),
    BOX(30, 390, 195), BOX(31, 348, 195), BOX(32, 334, 206), BOX(33, 336, 206), BOX(34, 320, 206),
    BOX(35, 313, 232), BOX(36, 308, 246), BOX(37, 309, 264), BOX(38, 302, 272), BOX(39, 304, 278),
};
const std::vector<HandBox> kPickToy2 = {
    BOX(0, 475, 283),  BOX(1, 476, 283),  BOX(2, 475, 283),  BOX(3, 475, 283),  BOX(4, 475, 294),
    BOX(5, 475, 294),  BOX(6, 475, 294),  BOX(7, 471, 302),  BOX(8, 471, 308),  BOX(9, 471, 316),
    BOX(10, 469, 325), BOX(11, 471, 325), BOX(12, 466, 327), BOX(13, 466, 327), BOX(14, 466, 327),
    BOX(15, 466, 327), BOX(16, 466, 338), BOX(17, 466, 338), BOX(18, 466, 338), BOX(19, 466, 338),
    BOX(20, 466, 334), BOX(21, 468, 334), BOX(22, 461, 334), BOX(23, 454, 325), BOX(24, 461, 292),
    BOX(25, 450, 274), BOX(26, 434, 248), BOX(27, 427, 230), BOX(28, 396, 206), BOX(29, 380, 197),
    BOX(30, 346, 206), BOX(31, 330, 206), BOX(32, 308, 246), BOX(33, 301, 264), BOX(34, 294, 272),
    BOX(35, 287, 278), BOX(36, 299, 283), BOX(37, 292, 283), BOX(38, 294, 292), BOX(39, 292, 292),
    BOX(40, 299, 294), BOX(41, 292, 294),
};
#undef BOX

/// A table pixel rectangle per recording (left of the bin, never covered), also by eye: the
/// table's plane is fitted to its points by least squares, independently of the detector.
struct Rect {
  int x0, y0, x1, y1;
};
constexpr Rect kTablePatch{150, 400, 210, 440};

/// n.p + d = 0 through the valid points of a pixel rectangle (smallest principal axis).
Eigen::Vector4d fit_plane(const Cloud& cloud, const Rect& r) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> pts;
  for (int v = r.y0; v < r.y1; ++v) {
    for (int u = r.x0; u < r.x1; ++u) {
      const PointT& p = cloud.points[static_cast<std::size_t>(v) * cloud.width + u];
      if (is_valid(p)) pts.push_back(p.getVector3fMap().cast<double>());
    }
  }
  for (const auto& p : pts) mean += p;
  mean /= static_cast<double>(std::max<std::size_t>(1, pts.size()));
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : pts) cov += (p - mean) * (p - mean).transpose();
  const Eigen::Vector3d n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  return {n.x(), n.y(), n.z(), -n.dot(mean)};
}

struct SequenceResult {
  int frames = 0, in_view = 0, found = 0, located = 0, false_alarms = 0;
  std::size_t person = 0, person_on_table = 0;
  std::vector<double> ms, cpu_ms;
};

SequenceResult run_sequence(const std::string& name, const std::vector<HandBox>& truth) {
  SequenceResult out;
  auto seq = io::open_sequence(test::data_dir() / "hrt1" / name);
  EXPECT_TRUE(seq.ok());
  if (!seq.ok()) return out;
  EXPECT_EQ(seq->frames.size(), truth.size());
  Eigen::Vector4d table = Eigen::Vector4d::Zero();
  for (std::size_t f = 0; f < seq->frames.size() && f < truth.size(); ++f) {
    auto frame = io::load_sequence_frame(*seq, f);
    EXPECT_TRUE(frame.ok());
    if (!frame.ok()) return out;
    const Cloud& cloud = *frame->cloud;
    if (f == 0) table = fit_plane(cloud, kTablePatch);  // the camera does not move
    const HandDetection d = timed_detect(cloud, &out.cpu_ms);
    const HandBox& box = truth[f];
    ++out.frames;
    out.in_view += box.in_view;
    out.ms.push_back(d.ms);
    // Where the most confident hand's hand proper is, in pixels.
    double cu = -1, cv = -1;
    if (!d.hands.empty() && !d.hands.front().tip_indices.empty()) {
      cu = cv = 0;
      for (int i : d.hands.front().tip_indices) cu += i % d.width, cv += i / d.width;
      cu /= d.hands.front().tip_indices.size(), cv /= d.hands.front().tip_indices.size();
    }
    const bool found = !d.hands.empty();
    const bool located = found && cu >= box.x0 && cu <= box.x1 && cv >= box.y0 && cv <= box.y1;
    out.found += box.in_view && found;
    out.located += box.in_view && located;
    out.false_alarms += !box.in_view && found;
    // Person pixels on the table: within 1.5 cm of its plane and inside the table's image region
    // (the plane extends beyond the table; the person standing behind it is not on it).
    std::size_t on_table = 0;
    for (int i : d.person_indices) {
      const Eigen::Vector3d p = cloud.points[i].getVector3fMap().cast<double>();
      if (std::abs(table.head<3>().dot(p) + table(3)) < 0.015) ++on_table;
    }
    out.person += d.person_indices.size();
    out.person_on_table += on_table;
    std::printf("%s %02zu: truth %s (%d,%d)-(%d,%d); hand %s, tip at (%.0f, %.0f)%s; person on table %zu px;%s\n", name.c_str(),
                f, box.in_view ? "hand" : "none", box.x0, box.y0, box.x1, box.y1, found ? "found" : "MISSED", cu, cv,
                found ? (located ? " in box" : " OUTSIDE box") : "", on_table, describe(d).c_str());
    dump(cloud, d, name + "_" + std::to_string(f));
  }
  std::printf("%s: hand in view in %d of %d frames, found in %d, hand proper inside the box in %d, false alarms %d; "
              "person %zu px, %zu (%.2f%%) within 1.5 cm of the table plane; median per frame %.2f ms CPU, %.2f ms wall-clock\n",
              name.c_str(), out.in_view, out.frames, out.found, out.located, out.false_alarms, out.person, out.person_on_table,
              out.person ? 100.0 * out.person_on_table / out.person : 0.0, median(out.cpu_ms), median(out.ms));
  return out;
}

TEST(HandDetector, Hrt1PickToy1) {
  SCENEWATCH_REQUIRE_DATA("hrt1/pick_toy_1");
  const SequenceResult r = run_sequence("pick_toy_1", kPickToy1);
  EXPECT_EQ(r.in_view, 40);
  EXPECT_GE(r.found, 39);    // measured 40
  EXPECT_GE(r.located, 38);  // measured 40
  EXPECT_EQ(r.false_alarms, 0);
  EXPECT_LT(r.person_on_table, 0.01 * std::max<std::size_t>(1, r.person));
}

TEST(HandDetector, Hrt1PickToy2) {
  SCENEWATCH_REQUIRE_DATA("hrt1/pick_toy_2");
  const SequenceResult r = run_sequence("pick_toy_2", kPickToy2);
  EXPECT_EQ(r.in_view, 42);
  EXPECT_GE(r.found, 41);    // measured 42
  // Measured 40: in frames 15 and 37 the hand proper still takes in part of the toy's
  // skin-coloured face, which touches the fingers in depth, and its centre drops below the box.
  EXPECT_GE(r.located, 38);
  EXPECT_EQ(r.false_alarms, 0);
  EXPECT_LT(r.person_on_table, 0.01 * std::max<std::size_t>(1, r.person));
  // The body stays in view in this recording: some of it must be found.
  EXPECT_GT(r.person, 100000u);
}

// ---------------------------------------------------------------------------------------------
// Real scenes with nobody in them: no hand, no person.

TEST(HandDetector, NoHandsInEmptyTabletopScenes) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn0.pcd");
  int frames = 0, with_hands = 0;
  for (int k = 0; k < 45; ++k) {
    auto frame = io::load_cloud_frame(test::data_dir() / "mosd/learn" / ("learn" + std::to_string(k) + ".pcd"));
    ASSERT_TRUE(frame.ok()) << k;
    const HandDetection d = detect_hands(*frame->cloud, HandConfig{});
    ++frames;
    with_hands += !d.hands.empty();
    if (!d.hands.empty()) std::printf("mosd learn%d:%s\n", k, describe(d).c_str());
    dump(*frame->cloud, d, "mosd_" + std::to_string(k));
  }
  std::printf("mosd: hands in %d of %d scenes without a person\n", with_hands, frames);
  EXPECT_LE(with_hands, 0);
}

TEST(HandDetector, HandsInAnEmptyKitchen) {
  SCENEWATCH_REQUIRE_DATA("redkitchen");
  auto seq = io::open_sequence(test::data_dir() / "redkitchen");
  ASSERT_TRUE(seq.ok());
  int with_hands = 0;
  for (std::size_t f = 0; f < seq->frames.size(); ++f) {
    auto frame = io::load_sequence_frame(*seq, f);
    ASSERT_TRUE(frame.ok());
    const HandDetection d = detect_hands(*frame->cloud, HandConfig{});
    with_hands += !d.hands.empty();
    if (!d.hands.empty()) std::printf("redkitchen %zu:%s\n", f, describe(d).c_str());
    dump(*frame->cloud, d, "redkitchen_" + std::to_string(f));
  }
  std::printf("redkitchen: hands in %d of %zu frames without a person\n", with_hands, seq->frames.size());
  // Known weakness, measured 46 of 50: wood (a tray's edge, chair slats, a table), a red cupboard's
  // lit edge and a red toy are skin-coloured and long, and the view is hand-held, so the border
  // cuts everything. The detector alone has no memory; in the pipeline, hands on surfaces the map
  // has remembered are dropped (Stream.* count 10 frames here). The floor is the measured figure,
  // so that more false hands fail; lower it when the detector improves.
  EXPECT_LE(with_hands, 46);
}

// ---------------------------------------------------------------------------------------------
// Robustness: what is not an organized colour frame gives an empty detection.

TEST(HandDetector, UnorganizedCloudGivesNothing) {
  Cloud cloud;
  for (int i = 0; i < 1000; ++i) {
    PointT p;
    p.x = 0.001f * i, p.y = 0.0f, p.z = 1.0f;
    p.r = 220, p.g = 170, p.b = 140;
    cloud.push_back(p);
  }
  ASSERT_EQ(cloud.height, 1u);
  const HandDetection d = detect_hands(cloud, HandConfig{});
  EXPECT_TRUE(d.hands.empty());
  EXPECT_TRUE(d.labels.empty());
  EXPECT_TRUE(d.person_indices.empty());
  EXPECT_FALSE(d.is_agent(0));
}

TEST(HandDetector, AllNaNCloudGivesNothing) {
  Cloud cloud(640, 480);
  for (auto& p : cloud.points) {
    p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
    p.r = 220, p.g = 170, p.b = 140;
  }
  const HandDetection d = detect_hands(cloud, HandConfig{});
  EXPECT_TRUE(d.hands.empty());
  EXPECT_TRUE(d.person_indices.empty());
  EXPECT_EQ(d.width, 640);
  EXPECT_EQ(d.height, 480);
}

TEST(HandDetector, TinyAndEmptyCloudsGiveNothing) {
  Cloud one(1, 1);
  one.points[0].x = 0, one.points[0].y = 0, one.points[0].z = 1;
  one.points[0].r = 220, one.points[0].g = 170, one.points[0].b = 140;
  EXPECT_TRUE(detect_hands(one, HandConfig{}).hands.empty());
  Cloud empty;
  EXPECT_TRUE(detect_hands(empty, HandConfig{}).hands.empty());
  // Claims to be organized but holds too few points.
  Cloud broken(4, 4);
  broken.points.resize(3);
  EXPECT_TRUE(detect_hands(broken, HandConfig{}).hands.empty());
  // Organized, skin everywhere, one flat wall: not a hand (no arm shape).
  Cloud wall(64, 48);
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) {
      PointT& p = wall.at(u, v);
      p.z = 1.0f, p.x = (u - 31.5f) / 60.0f, p.y = (v - 23.5f) / 60.0f;
      p.r = 220, p.g = 170, p.b = 140;
    }
  }
  EXPECT_TRUE(detect_hands(wall, HandConfig{}).hands.empty());
}

TEST(HandDetector, ConfigValidation) {
  EXPECT_TRUE(validate(HandConfig{}).ok());
  const auto bad = [](auto change, const char* key) {
    HandConfig c;
    change(c);
    const Status s = validate(c);
    EXPECT_FALSE(s.ok()) << key;
    if (!s.ok()) {
      EXPECT_NE(s.error().message.find(key), std::string::npos) << s.error().message;
    }
  };
  bad([](HandConfig& c) { c.min_hand_area_m2 = 0.5; }, "min_area_m2");
  bad([](HandConfig& c) { c.depth_jump_m = 0; }, "depth_jump_m");
  bad([](HandConfig& c) { c.border_margin_px = -1; }, "border_margin_px");
  bad([](HandConfig& c) { c.person_max_range_m = 0; }, "person_max_range_m");
  bad([](HandConfig& c) { c.person_max_extent_m = -1; }, "person_max_extent_m");
  bad([](HandConfig& c) { c.person_max_depth_offset_m = 0; }, "person_max_depth_offset_m");
  bad([](HandConfig& c) { c.skin_dilation_px = 100; }, "skin_dilation_px");
  bad([](HandConfig& c) { c.tip_length_m = 0; }, "tip_length_m");
  bad([](HandConfig& c) { c.tip_clearance_m = -0.1; }, "tip_clearance_m");
  bad([](HandConfig& c) { c.min_arm_length_m = -1; }, "min_arm_length_m");
  bad([](HandConfig& c) { c.max_arm_length_m = 0.1; }, "min_arm_length_m");
  bad([](HandConfig& c) { c.min_arm_width_m = -1; }, "min_arm_width_m");
  bad([](HandConfig& c) { c.min_elongation = 0.5; }, "min_elongation");
  bad([](HandConfig& c) { c.free_arm_min_elongation = 1.0; }, "free_arm_min_elongation");
  bad([](HandConfig& c) { c.free_arm_min_length_m = 0; }, "free_arm_min_length_m");
  bad([](HandConfig& c) { c.support_plane_tolerance_m = 0; }, "support_plane_tolerance_m");
  bad([](HandConfig& c) { c.grid_step = 0; }, "grid_step");
  // A disabled detector finds nothing.
  HandConfig off;
  off.enabled = false;
  Cloud wall(8, 8);
  EXPECT_TRUE(detect_hands(wall, off).hands.empty());
}

// The remembered support planes (HandMemory) against the detector that searches them in every
// frame, the oracle: on the hrt1 recordings (fixed camera) the same hands, pixel for pixel or
// nearly (a remembered plane is not refitted to the frame's noise).
TEST(HandDetector, RememberedPlanesGiveTheSameHandsOnHrt1) {
  for (const std::string name : {"pick_toy_1", "pick_toy_2"}) {
    SCENEWATCH_REQUIRE_DATA("hrt1/" + name);
    auto seq = io::open_sequence(test::data_dir() / "hrt1" / name);
    ASSERT_TRUE(seq.ok());
    HandMemory memory;
    std::size_t same = 0, both = 0, frames = 0;
    for (std::size_t f = 0; f < seq->frames.size(); ++f) {
      auto frame = io::load_sequence_frame(*seq, f);
      ASSERT_TRUE(frame.ok());
      const HandDetection searched = detect_hands(*frame->cloud, HandConfig{});
      const HandDetection remembered = detect_hands(*frame->cloud, HandConfig{}, &memory);
      ++frames;
      EXPECT_EQ(searched.hands.size(), remembered.hands.size()) << name << " frame " << f;
      for (std::size_t i = 0; i < searched.labels.size(); ++i) {
        const bool a = searched.labels[i] == AgentLabel::kHand, b = remembered.labels[i] == AgentLabel::kHand;
        same += a && b;
        both += a || b;
      }
    }
    const double iou = both ? static_cast<double>(same) / both : 1.0;
    std::printf("%s: hand proper's pixels, remembered vs searched planes: IoU %.4f over %zu frames\n", name.c_str(), iou, frames);
    EXPECT_GT(iou, 0.95);
  }
}

// A hand-held camera (7-Scenes redkitchen, 50 posed frames): the remembered planes follow the
// camera's motion (HandMemory::camera_moved), so they are searched for less often, with no more
// false agents (there is no person here: skin-coloured wood, which the pipeline's remembered-
// surface check drops later) than searching in every frame.
TEST(HandDetector, RememberedPlanesFollowAMovingCamera) {
  SCENEWATCH_REQUIRE_DATA("redkitchen");
  auto seq = io::open_sequence(test::data_dir() / "redkitchen");
  ASSERT_TRUE(seq.ok());
  HandMemory moved, fixed;
  std::optional<Pose> before;
  std::size_t same = 0, both = 0, same_fixed = 0, both_fixed = 0, agents_searched = 0, agents_moved = 0, agents_fixed = 0;
  for (std::size_t f = 0; f < seq->frames.size(); ++f) {
    auto frame = io::load_sequence_frame(*seq, f);
    ASSERT_TRUE(frame.ok());
    ASSERT_TRUE(frame->T_world_camera.has_value());
    if (before) moved.camera_moved((frame->T_world_camera->inverse() * *before).cast<float>());
    before = frame->T_world_camera;
    const HandDetection searched = detect_hands(*frame->cloud, HandConfig{});
    const HandDetection remembered = detect_hands(*frame->cloud, HandConfig{}, &moved);
    const HandDetection unmoved = detect_hands(*frame->cloud, HandConfig{}, &fixed);
    for (std::size_t i = 0; i < searched.labels.size(); ++i) {
      const bool a = searched.labels[i] != AgentLabel::kNone, b = remembered.labels[i] != AgentLabel::kNone;
      const bool c = unmoved.labels[i] != AgentLabel::kNone;
      same += a && b;
      both += a || b;
      same_fixed += a && c;
      both_fixed += a || c;
      agents_searched += a;
      agents_moved += b;
      agents_fixed += c;
    }
  }
  const double iou = both ? static_cast<double>(same) / both : 1.0;
  std::printf("redkitchen: planes in the camera's frame, against searching every frame: IoU %.4f; agent pixels "
              "(all false here) searched %zu, planes following %zu, planes in the camera's frame %zu\n",
              both_fixed ? static_cast<double>(same_fixed) / both_fixed : 1.0, agents_searched, agents_moved, agents_fixed);
  std::printf("redkitchen: plane searches over %zu frames: %zu with the planes following the camera, %zu without; "
              "agents' pixels against searching every frame: IoU %.4f (%zu pixels)\n",
              seq->frames.size(), moved.plane_searches(), fixed.plane_searches(), iou, both);
  // Measured: 25 searches against 58 (tables and walls together); the false agents' pixels
  // 1.24 M against 1.50 M for searching every frame and 1.12 M for planes kept in the camera's
  // frame. RANSAC itself does not find the same planes twice here (the camera-frame memory agrees
  // with searching every frame at IoU 0.69, the following one at 0.62), so the pixels are not
  // compared one by one.
  EXPECT_LE(moved.plane_searches(), 30u);
  EXPECT_LE(agents_moved, agents_searched) << "no more false agents than searching every frame";
}

}  // namespace
}  // namespace scenewatch::foreground
