// The foreground tracker on the simulator's hand scenarios, with the hand taken from the exact
// label image: promotion, tracking and DoF learning on their own, apart from the hand detector's
// accuracy (tested in hand_detector_test.cpp) and from the daemon (tests/scenarios).
#include <gtest/gtest.h>

#include <cstdio>
#include <map>

#include "scenewatch/foreground/foreground_tracker.h"
#include "scenewatch/pipeline/object_tracker.h"
#include "scenewatch/segmentation/tabletop.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::foreground {
namespace {

constexpr std::uint16_t kHandLabel = 2;  // the simulator's label of the hand (ground_truth.json "labels")

HandDetection hands_from_labels(const LabelImage& labels) {
  HandDetection d;
  d.width = labels.width;
  d.height = labels.height;
  d.labels.assign(labels.labels.size(), AgentLabel::kNone);
  Hand h;
  for (std::size_t i = 0; i < labels.labels.size(); ++i) {
    if (labels.labels[i] != kHandLabel) continue;
    d.labels[i] = AgentLabel::kHand;
    h.indices.push_back(static_cast<int>(i));
  }
  h.tip_indices = h.indices;
  h.score = 1.0;
  if (!h.indices.empty()) d.hands.push_back(h);
  return d;
}

struct Outcome {
  std::vector<std::pair<int, Event>> events;  // frame, event
  std::vector<TrackedObject> objects;         // the foreground at the end
  std::map<int, Pose> true_cup, tracked_cup;  // per frame after promotion
  int cup_id = 0;
};

Outcome run(const std::string& name, int width, int height) {
  auto scenario = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios" / (name + ".yaml"));
  EXPECT_TRUE(scenario) << scenario.error().message;
  auto sim = sim::Simulator::create(sim::with_resolution(*scenario, width, height));
  EXPECT_TRUE(sim) << sim.error().message;
  ForegroundTracker fg{ForegroundConfig{}};
  pipeline::ObjectTracker known{pipeline::TrackingConfig{}};
  segmentation::Config seg;
  Outcome out;
  std::vector<Plane> planes;
  for (int k = 0; k < sim->frame_count(0); ++k) {
    const sim::SimFrame rendered = sim->render(0, k);
    auto frame = sim::as_frame(rendered, sim->scenario().intrinsics, k / 30.0);
    EXPECT_TRUE(frame);
    const HandDetection hands = hands_from_labels(rendered.labels);
    FrameView view;
    view.cloud = frame->cloud.get();
    view.T_world_camera = frame->pose_or_identity();
    view.stamp_s = frame->stamp_s;
    view.frame_index = static_cast<std::uint64_t>(k);
    view.hands = &hands;
    view.planes = &planes;
    view.K = &sim->scenario().intrinsics;
    std::vector<int> blank = fg.track(view);
    for (std::size_t i = 0; i < hands.labels.size(); ++i)
      if (hands.labels[i] != AgentLabel::kNone) blank.push_back(static_cast<int>(i));
    auto seen = std::make_shared<Cloud>(*frame->cloud);
    for (int i : blank) seen->points[static_cast<std::size_t>(i)].x = std::numeric_limits<float>::quiet_NaN();
    const Pose& T = view.T_world_camera;
    auto s = segmentation::segment(*seen, seg, Eigen::Vector3d::Zero());
    planes.clear();
    for (auto p : s.planes) {
      p.normal = T.linear() * p.normal;
      p.centroid = T * p.centroid;
      p.d = -p.normal.dot(p.centroid);
      planes.push_back(p);
    }
    std::vector<ObjectCluster> clusters;
    std::vector<pipeline::TrackerObservation> obs;
    for (auto c : s.objects) {
      c.centroid = T * c.centroid;
      c.box.center = T * c.box.center;
      clusters.push_back(c);
    }
    const ForegroundUpdate u = fg.update(view, clusters, known.objects());
    for (std::size_t i = 0; i < clusters.size(); ++i) {
      if (std::find(u.claimed_clusters.begin(), u.claimed_clusters.end(), i) != u.claimed_clusters.end()) continue;
      pipeline::TrackerObservation o;
      o.cluster = clusters[i];
      o.range_m = (clusters[i].centroid - T.translation()).norm();
      obs.push_back(o);
    }
    known.update(std::move(obs), view.stamp_s, [](const auto&) { return 0.0; });
    for (auto id : u.promoted) known.remove(id);
    for (const auto& e : u.events) {
      out.events.emplace_back(k, e);
      if (e.kind == EventKind::kObjectPromoted && out.cup_id == 0) out.cup_id = static_cast<int>(*e.object_id);
    }
    for (const auto& o : fg.objects()) {
      if (static_cast<int>(o.id) != out.cup_id) continue;
      out.tracked_cup[k] = o.foreground->T_world_object;
      for (const auto& p : rendered.truth.objects)
        if (p.id == 3) out.true_cup[k] = p.T_world_object;
    }
  }
  out.objects = fg.objects();
  return out;
}

std::vector<std::string> names(const DofFlags& f, bool value) {
  std::vector<std::string> out;
  for (int k = 0; k < kDofCount; ++k)
    if (f[static_cast<std::size_t>(k)] == value) out.push_back(to_string(static_cast<Dof>(k)));
  return out;
}

// The size of the cup's model when it was promoted (the event's evidence).
double first_model_points(const Outcome& o) {
  for (const auto& [k, e] : o.events)
    if (e.kind == EventKind::kObjectPromoted) return e.evidence.at("model_points");
  return 0;
}

struct TrackingError {
  double mean_cm = 0, worst_cm = 0, worst_deg = 0;
};

// Tracking error: the tracked motion since promotion against the true one (the model's frame is
// not the cup's, so poses are compared as motions from the same frame).
TrackingError report_tracking(const Outcome& o) {
  if (o.tracked_cup.empty()) return {1e9, 1e9, 1e9};
  const int first = o.tracked_cup.begin()->first;
  double worst_cm = 0, worst_deg = 0, sum_cm = 0;
  for (const auto& [k, T] : o.tracked_cup) {
    const Pose est = T * o.tracked_cup.at(first).inverse();
    const Pose truth = o.true_cup.at(k) * o.true_cup.at(first).inverse();
    const Eigen::Vector3d c = o.tracked_cup.at(first).translation();
    const double cm = 100 * ((est * c) - (truth * c)).norm();
    const double deg = Eigen::AngleAxisd(est.linear() * truth.linear().transpose()).angle() * 180 / M_PI;
    worst_cm = std::max(worst_cm, cm), worst_deg = std::max(worst_deg, deg), sum_cm += cm;
    if (std::getenv("SCENEWATCH_TEST_VERBOSE") && k % 4 == 0) {
      const double est_turn = Eigen::AngleAxisd(est.linear()).angle() * 180 / M_PI;
      const double true_turn = Eigen::AngleAxisd(truth.linear()).angle() * 180 / M_PI;
      std::printf("  frame %d: turned %.1f deg (true %.1f), error %.2f cm %.1f deg\n", k, est_turn, true_turn, cm, deg);
    }
  }
  std::printf("tracking over %zu frames: mean %.2f cm, worst %.2f cm, worst %.1f deg\n", o.tracked_cup.size(),
              sum_cm / o.tracked_cup.size(), worst_cm, worst_deg);
  return {sum_cm / o.tracked_cup.size(), worst_cm, worst_deg};
}

TEST(ForegroundTrackerTest, AnUprightCarryPromotesTheCupAndFreesXYZAndYawOnly) {
  const Outcome o = run("hand_picks_cup_upright", 640, 480);
  std::size_t promoted = 0, frozen = 0;
  int promoted_at = -1;
  for (const auto& [k, e] : o.events) {
    std::printf("frame %d %s %s\n", k, to_string(e.kind), e.detail.c_str());
    if (e.kind == EventKind::kObjectPromoted) ++promoted, promoted_at = k;
    if (e.kind == EventKind::kFrozenDofMotion) ++frozen;
  }
  // Measured with the model grown from the registered views: mean 0.60 cm, worst 1.18 cm (after
  // the release, as the hand withdraws) and 14.0 degrees over the 83 frames after promotion; with
  // the first view's model only (grow_model false): 0.60 cm, 0.85 cm, 18.0 degrees.
  const TrackingError error = report_tracking(o);
  EXPECT_LT(error.mean_cm, 0.7);
  EXPECT_LT(error.worst_cm, 1.3);
  EXPECT_LT(error.worst_deg, 16.0);
  EXPECT_EQ(promoted, 1u);
  EXPECT_EQ(frozen, 0u);
  // The cup is grasped at frame 35 and lifted from there to frame 50 (the scenario's keys, eased:
  // it rises 1.5 mm by frame 36, 12.5 mm by 38). Promoted when its tracked lift along the
  // table's normal exceeds promote_lift_m: measured at frame 38 (tracked lift 9.6 mm), within
  // the 3 frames the issue allows, and never before the lift starts.
  EXPECT_GE(promoted_at, 36);
  EXPECT_LE(promoted_at, 38);
  ASSERT_EQ(o.objects.size(), 1u);
  const auto& f = *o.objects[0].foreground;
  // The model grows from the registered views: the sides the 40 degree turn shows join it.
  std::printf("model points: %.0f at promotion, %zu after the carry\n", first_model_points(o), f.model_points);
  EXPECT_GT(static_cast<double>(f.model_points), 2.0 * first_model_points(o));  // measured 879 -> 2316
  ASSERT_EQ(f.handlings.size(), 1u);
  const auto free = names(f.free, true);
  std::printf("free DoFs after the carry:");
  for (const auto& n : free) std::printf(" %s", n.c_str());
  std::printf("\n");
  // x, y, z and yaw (the 40 degree turn, seen from the cup's print) free; roll and pitch frozen.
  EXPECT_EQ(free, (std::vector<std::string>{"x", "y", "z", "yaw"}));
}

TEST(ForegroundTrackerTest, TiltingAnUprightCupRaisesOneFrozenDofMotion) {
  const Outcome o = run("hand_tilts_cup", 320, 240);
  std::vector<Event> frozen;
  std::size_t promoted = 0;
  int promoted_at = -1;
  for (const auto& [k, e] : o.events) {
    std::printf("frame %d %s %s\n", k, to_string(e.kind), e.detail.c_str());
    if (e.kind == EventKind::kObjectPromoted) ++promoted, promoted_at = k;
    if (e.kind == EventKind::kFrozenDofMotion) frozen.push_back(e);
  }
  // Measured with the grown model: mean 0.78 cm, worst 1.44 cm, worst 26.3 degrees over the 170
  // frames after promotion (part of the 60 degree tilt is still lost); with the first view's model
  // only: 1.45 cm, 1.85 cm, 62.7 degrees.
  const TrackingError error = report_tracking(o);
  EXPECT_LT(error.mean_cm, 0.9);
  EXPECT_LT(error.worst_cm, 1.6);
  EXPECT_LT(error.worst_deg, 30.0);
  EXPECT_EQ(promoted, 1u);
  // Grasped at frame 28 and lifted from there (it rises 2.4 mm by frame 29, 19 mm by 31):
  // measured promoted at frame 31 (tracked lift 9.1 mm), the 3 frames.
  EXPECT_GE(promoted_at, 29);
  EXPECT_LE(promoted_at, 31);
  ASSERT_EQ(frozen.size(), 1u);
  const auto dof = static_cast<Dof>(static_cast<int>(frozen[0].evidence.at("dof")));
  EXPECT_TRUE(dof == Dof::kRoll || dof == Dof::kPitch) << to_string(dof);
}

}  // namespace
}  // namespace scenewatch::foreground
