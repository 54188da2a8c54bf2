// Whole-object completion (issue 10): the rule that decides which segmented objects a cluster of
// evidence belongs to, the merging and the surfaces that stayed, on hand-made labels; the
// decimated segmentation against the full one on real data; and, with the simulator's exact
// labels, a 2 cm move and an object hidden behind a new one from one unmoved camera.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <numeric>

#include "scenewatch/change/whole_objects.h"
#include "scenewatch/change/diff.h"
#include "scenewatch/change/event_scoring.h"
#include "scenewatch/io/cloud_io.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::change {
namespace {

using Spans = std::vector<std::pair<int, int>>;  // index ranges [begin, end)

// Labels of a frame of `n` points, one object per list of index ranges.
ObjectLabels labels_of(std::size_t n, const std::vector<Spans>& objects) {
  ObjectLabels l;
  l.object_of.assign(n, -1);
  for (const Spans& spans : objects) {
    l.members.emplace_back();
    for (const auto& [begin, end] : spans)
      for (int i = begin; i < end; ++i) {
        l.object_of[i] = static_cast<int>(l.members.size()) - 1;
        l.members.back().push_back(i);
      }
  }
  return l;
}

// Columns [u0, u1) of every row of a 100x10 image.
Spans columns(int u0, int u1) {
  Spans spans;
  for (int v = 0; v < 10; ++v) spans.emplace_back(v * 100 + u0, v * 100 + u1);
  return spans;
}

std::vector<int> range(int begin, int end) {
  std::vector<int> v(end - begin);
  std::iota(v.begin(), v.end(), begin);
  return v;
}

TEST(Completion, AFringeBelongsToItsObjectAStrayMinorityDoesNot) {
  const ObjectLabels l = labels_of(1000, {{{0, 400}}, {{400, 500}}, {{500, 900}}});
  const Config config;
  // The fringe a short move uncovers: a tenth of object 0, all of the evidence on it.
  EXPECT_EQ(explaining_objects(range(0, 40), l, config), std::vector<int>{0});
  // Mostly object 0, a few points on object 2's border: object 2 is not pulled in.
  std::vector<int> e = range(0, 90);
  for (int i = 500; i < 510; ++i) e.push_back(i);
  EXPECT_EQ(explaining_objects(e, l, config), std::vector<int>{0});
  // Evidence spread over two objects, most of each covered: both (objects moved together).
  e = range(0, 300);
  for (int i = 400; i < 460; ++i) e.push_back(i);
  EXPECT_EQ(explaining_objects(e, l, config), (std::vector<int>{0, 1}));
  // Evidence on no object: nothing explains it.
  EXPECT_TRUE(explaining_objects(range(920, 990), l, config).empty());
}

// An organized 100x10 cloud: a wall at 1 m, object points in front of it where `near` says.
Cloud flat_cloud(float z = 1.0f) {
  Cloud c;
  c.width = 100;
  c.height = 10;
  for (int v = 0; v < 10; ++v)
    for (int u = 0; u < 100; ++u) {
      PointT p;
      p.z = z;
      p.x = (u - 49.5f) * z / 525.f;
      p.y = (v - 4.5f) * z / 525.f;
      p.r = p.g = p.b = 128;
      c.push_back(p);
    }
  c.width = 100;
  c.height = 10;
  return c;
}

ChangeCluster cluster_on(const Cloud& cloud, ChangeKind kind, std::vector<int> indices) {
  ChangeCluster c;
  c.kind = kind;
  c.indices = std::move(indices);
  c.evidence_count = c.indices.size();
  for (int i : c.indices) c.points_world.push_back(cloud.points[i].getVector3fMap().cast<double>());
  return c;
}

Intrinsics flat_camera() { return centred_pinhole(100, 10, 525); }

TEST(Completion, TwoFringesOfOneObjectBecomeOneWholeObject) {
  const Cloud before = flat_cloud(), after = flat_cloud();
  // AFTER: one object over columns 20-59; BEFORE: none.
  const ObjectLabels la = labels_of(after.size(), {columns(20, 60)});
  const ObjectLabels lb = labels_of(before.size(), {});
  const CompletionFrame fb{&before, Pose::Identity(), &lb, flat_camera()};
  const CompletionFrame fa{&after, Pose::Identity(), &la, flat_camera()};
  std::vector<ChangeCluster> clusters = {cluster_on(after, ChangeKind::kAdded, {20, 21, 120, 121}),
                                         cluster_on(after, ChangeKind::kAdded, {58, 59, 158, 159}),
                                         cluster_on(after, ChangeKind::kAdded, {90, 91, 190, 191})};
  const auto out = complete_clusters(clusters, fb, fa, Config{});
  ASSERT_EQ(out.size(), 2u) << "the two fringes of the object merge; the evidence off it stays apart";
  EXPECT_TRUE(out[0].completed);
  EXPECT_EQ(out[0].indices, la.members[0]);
  EXPECT_EQ(out[0].evidence_count, 8u);
  EXPECT_EQ(out[0].region.width, 40);
  EXPECT_FALSE(out[1].completed);
  EXPECT_EQ(out[1].indices, (std::vector<int>{90, 91, 190, 191}));
}

TEST(Completion, SurfacesTheOtherFrameSeesOnAnUnchangedObjectStayOut) {
  // AFTER: one segment over columns 0-59 (a new object merged with an old one it touches);
  // BEFORE: the old object alone over columns 40-59, at the same depth, with no change on it.
  const Cloud before = flat_cloud(), after = flat_cloud();
  const ObjectLabels la = labels_of(after.size(), {columns(0, 60)}), lb = labels_of(before.size(), {columns(40, 60)});
  const CompletionFrame fb{&before, Pose::Identity(), &lb, flat_camera()};
  const CompletionFrame fa{&after, Pose::Identity(), &la, flat_camera()};
  std::vector<int> evidence;
  for (int v = 0; v < 10; ++v)
    for (int u = 0; u < 40; ++u) evidence.push_back(v * 100 + u);
  const auto out = complete_clusters({cluster_on(after, ChangeKind::kAdded, evidence)}, fb, fa, Config{});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].indices, evidence) << "the old object's surface, seen where it was, is not the new one's";
}

// A 100x10 wall at 1 m; pieces at 0.9 m over columns [10, 30) and [60, 80); between them
// columns [30, 60) at `gap_z` (NaN: no depth), with a sensor shadow at columns 30-31.
struct SplitScene {
  Cloud cloud = flat_cloud();
  ObjectLabels labels;
  explicit SplitScene(float gap_z) {
    labels.object_of.assign(cloud.size(), -1);
    labels.members.resize(2);
    for (int v = 0; v < 10; ++v)
      for (int u = 10; u < 80; ++u) {
        const int i = v * 100 + u;
        PointT& p = cloud.points[i];
        const float z = u < 30 || u >= 60 ? 0.9f : u < 32 ? std::numeric_limits<float>::quiet_NaN() : gap_z;
        p.x = (u - 49.5f) * z / 525.f;
        p.y = (v - 4.5f) * z / 525.f;
        p.z = z;
        if (u >= 30 && u < 60) continue;
        const int o = u < 30 ? 0 : 1;
        labels.object_of[i] = o;
        labels.members[o].push_back(i);
      }
  }
};

TEST(Completion, PiecesSplitByANearerSurfaceAreOneObject) {
  SplitScene hidden(0.6f);
  join_hidden_pieces(hidden.labels, hidden.cloud, Config{});
  ASSERT_EQ(hidden.labels.members.size(), 1u) << "a box in front cuts one object in two";
  EXPECT_EQ(hidden.labels.members[0].size(), 400u);
  SplitScene apart(1.0f);
  join_hidden_pieces(apart.labels, apart.cloud, Config{});
  EXPECT_EQ(apart.labels.members.size(), 2u) << "the wall behind shows between them: two objects";
  SplitScene shadow(std::numeric_limits<float>::quiet_NaN());
  join_hidden_pieces(shadow.labels, shadow.cloud, Config{});
  EXPECT_EQ(shadow.labels.members.size(), 2u) << "nothing seen between them: no reason to join";
}

// Point IoU of two index sets.
double iou(std::vector<int> a, std::vector<int> b) {
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  std::vector<int> both;
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
  const std::size_t uni = a.size() + b.size() - both.size();
  return uni ? static_cast<double>(both.size()) / uni : 1.0;
}

// The oracle of the decimated segmentation is the full one: every object of the full
// segmentation is found again on every second pixel, with nearly the same points.
TEST(Completion, SegmentingEverySecondPixelFindsTheObjectsOfTheFullSegmentation) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn13.pcd");
  for (const char* name : {"learn13", "learn29", "learn38"}) {
    auto file = io::read_cloud(test::data_dir() / "mosd/learn" / (std::string(name) + ".pcd"));
    ASSERT_TRUE(file.ok()) << file.error().message;
    const ObjectLabels full = segment_objects(*file->cloud, segmentation::Config{}, 1);
    const ObjectLabels half = segment_objects(*file->cloud, segmentation::Config{}, 2);
    ASSERT_GE(full.members.size(), 2u) << name;
    for (std::size_t o = 0; o < full.members.size(); ++o) {
      double best = 0;
      for (const auto& m : half.members) best = std::max(best, iou(full.members[o], m));
      std::printf("  %s object %zu (%zu points): best IoU at every second pixel %.3f\n", name, o, full.members[o].size(), best);
      EXPECT_GE(best, 0.9) << name << " object " << o;
    }
  }
}

// --- simulator: one unmoved camera, exact labels ---

constexpr const char* kTwoBoxes = R"(
name: two_boxes
seed: 3
objects:
  - {id: 1, name: cereal, shape: box, size_m: [0.06, 0.16, 0.24], color: [230, 190, 40],
     texture: {type: noise, color: [190, 60, 30], scale_m: 0.04}, position: [0.0, 0.05], yaw_deg: 0}
  - {id: 2, name: tin, shape: cylinder, radius_m: 0.04, height_m: 0.12, color: [60, 90, 200], position: [0.25, -0.05]}
phases:
  - name: before
    frames: 1
    camera: {type: static, position: [-0.9, 0.0, 1.35], target: [0.0, 0.0, 0.8]}
  - name: after
    frames: 1
    changes: CHANGES
    camera: {type: static, position: [-0.9, 0.0, 1.35], target: [0.0, 0.0, 0.8]}
)";

struct SimPair {
  Frame before, after;
  LabelImage labels_before, labels_after;
};

SimPair render_pair(const std::string& changes) {
  std::string yaml = kTwoBoxes;
  yaml.replace(yaml.find("CHANGES"), 7, changes);
  SimPair pair;
  auto scenario = sim::parse_scenario(yaml, "two_boxes");
  EXPECT_TRUE(scenario.ok()) << (scenario.ok() ? "" : scenario.error().message);
  if (!scenario.ok()) return pair;
  auto simulator = sim::Simulator::create(*scenario);
  EXPECT_TRUE(simulator.ok());
  if (!simulator.ok()) return pair;
  const sim::SimFrame b = simulator->render(0, 0), a = simulator->render(1, 0);
  auto fb = sim::as_frame(b, scenario->intrinsics, 0.0), fa = sim::as_frame(a, scenario->intrinsics, 1.0);
  EXPECT_TRUE(fb.ok() && fa.ok());
  if (!fb.ok() || !fa.ok()) return pair;
  pair.before = *fb;
  pair.after = *fa;
  pair.labels_before = b.labels;
  pair.labels_after = a.labels;
  return pair;
}

std::vector<int> pixels_of(const Frame& f, const LabelImage& labels, int id) {
  std::vector<int> out;
  for (std::size_t i = 0; i < labels.labels.size(); ++i)
    if (labels.labels[i] == id * 10 && is_valid(f.cloud->points[i])) out.push_back(static_cast<int>(i));
  return out;
}

void print_events(const char* what, const DiffResult& r) {
  std::printf("%s: %zu events\n", what, r.events.size());
  for (const auto& e : r.events)
    std::printf("  %s: %s [%zu / %zu points]\n", to_string(e.kind), e.detail.c_str(), e.indices_before.size(), e.indices_after.size());
}

TEST(CompletionSim, AShortMoveIsOneMoveOfTheWholeObject) {
  // The textured box slides 2 cm sideways: only 2 cm wide fringes leave and enter free space.
  const SimPair p = render_pair("{move: [{id: 1, position: [0.0, 0.07]}]}");
  ASSERT_TRUE(p.before.cloud && p.after.cloud);
  auto result = diff(p.before, p.after);
  ASSERT_TRUE(result.ok()) << result.error().message;
  ASSERT_EQ(result->method, DiffMethod::kSameCamera);
  print_events("box moved by 2 cm", *result);
  DiffOptions evidence_only;
  evidence_only.change.complete_objects = false;
  auto fringe = diff(p.before, p.after, evidence_only);
  ASSERT_TRUE(fringe.ok());
  print_events("the same, evidence only", *fringe);

  TrueChange truth;
  truth.object_id = 1;
  truth.indices_before = pixels_of(p.before, p.labels_before, 1);
  truth.indices_after = pixels_of(p.after, p.labels_after, 1);
  ASSERT_EQ(result->events.size(), 1u) << "one object moved, one event";
  const Event& e = result->events.front();
  EXPECT_EQ(e.kind, EventKind::kObjectMoved);
  ASSERT_TRUE(e.displacement_world.has_value());
  EXPECT_NEAR(e.displacement_world->norm(), 0.02, 0.01);
  const double whole = change_iou(e, truth);
  double best_fringe = 0;
  for (const auto& f : fringe->events) best_fringe = std::max(best_fringe, change_iou(f, truth));
  std::printf("IoU with the whole box: %.3f completed, %.3f evidence only\n", whole, best_fringe);
  EXPECT_GE(whole, 0.9);
  EXPECT_LT(best_fringe, 0.5) << "without completion the event is the fringe (else this test checks nothing)";
}

TEST(CompletionSim, AnObjectHiddenBehindANewOneIsNotRemoved) {
  // A box is put down right in front of the tin, touching it: the tin is mostly hidden, and its
  // visible rest joins the new box in AFTER's segmentation.
  const SimPair p = render_pair(
      "{add: [{id: 3, name: box, shape: box, size_m: [0.06, 0.12, 0.09], color: [200, 60, 60],"
      " position: [0.18, -0.05]}]}");
  ASSERT_TRUE(p.before.cloud && p.after.cloud);
  auto result = diff(p.before, p.after);
  ASSERT_TRUE(result.ok()) << result.error().message;
  print_events("box put in front of the tin", *result);
  const std::vector<int> tin_before = pixels_of(p.before, p.labels_before, 2);
  const std::vector<int> tin_after = pixels_of(p.after, p.labels_after, 2);
  const std::vector<int> box = pixels_of(p.after, p.labels_after, 3);
  std::printf("tin: %zu pixels before, %zu after; new box %zu\n", tin_before.size(), tin_after.size(), box.size());
  ASSERT_GT(tin_after.size(), 0u) << "a part of the tin must stay visible for this test";
  ASSERT_LT(2 * tin_after.size(), tin_before.size()) << "the tin must be mostly hidden for this test";
  // The case to handle: the new box and the tin's visible rest are one segment of AFTER.
  const ObjectLabels segments = segment_objects(*p.after.cloud, segmentation::Config{}, 2);
  const int box_segment = segments.object_of[box[box.size() / 2]];
  std::size_t tin_on_it = 0;
  for (int i : tin_after) tin_on_it += box_segment >= 0 && segments.object_of[i] == box_segment ? 1 : 0;
  std::printf("tin pixels in the new box's segment: %zu of %zu\n", tin_on_it, tin_after.size());
  ASSERT_GT(2 * tin_on_it, tin_after.size()) << "for this test the segmentation must join the tin's rest to the box";
  ASSERT_EQ(result->events.size(), 1u);
  const Event& e = result->events.front();
  EXPECT_EQ(e.kind, EventKind::kObjectAdded) << "the tin was not removed, only hidden";
  TrueChange added;
  added.object_id = 3;
  added.indices_after = box;
  std::printf("IoU with the new box: %.3f\n", change_iou(e, added));
  EXPECT_GE(change_iou(e, added), 0.9);
  std::vector<int> tin_in_event;
  std::set_intersection(e.indices_after.begin(), e.indices_after.end(), tin_after.begin(), tin_after.end(),
                        std::back_inserter(tin_in_event));
  EXPECT_LT(tin_in_event.size(), tin_after.size() / 10) << "the tin's visible rest is not part of the new box";
}

}  // namespace
}  // namespace scenewatch::change
