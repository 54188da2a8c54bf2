// Real data: consecutive mOSD scenes taken from the same, unmoved Kinect while objects were added,
// removed or moved. The labels give the objects, read pixel by pixel in the other scene: an object
// of AFTER that keeps its depth on fewer than 80 % of its pixels in sight in BEFORE is a true
// addition (and the other way round a removal); one mostly hidden there is left out. Object-level precision and recall, strict (point IoU >= 0.5 with the
// whole object, both ways), are printed per pair and overall, and overall for the evidence alone
// (change.complete_objects off: what diff reported before issue 10's whole-object events).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>

#include "scenewatch/change/diff.h"
#include "scenewatch/change/event_scoring.h"
#include "scenewatch/io/cloud_io.h"
#include "test_data.h"

namespace scenewatch::change {
namespace {

struct Scene {
  io::CloudFile file;
  std::vector<std::uint32_t> labels;
  std::vector<Eigen::Vector3f> xyz;
};

Scene load(int i) {
  const auto path = test::data_dir() / "mosd/learn" / ("learn" + std::to_string(i) + ".pcd");
  Scene s;
  auto file = io::read_cloud(path);
  EXPECT_TRUE(file.ok());
  auto labels = io::read_pcd_labels(path);
  EXPECT_TRUE(labels.ok());
  if (!file.ok() || !labels.ok()) return s;
  s.file = *file;
  s.labels = *labels;
  for (const auto& p : s.file.cloud->points) s.xyz.push_back(p.getVector3fMap());
  return s;
}

// The camera did not move when the table pixels that both scenes label as table have the same
// depth (the scenes of one session share the recording's exact table depth).
bool same_camera(const Scene& a, const Scene& b) {
  return change::same_camera_by_labels(a.xyz, a.labels, b.xyz, b.labels);
}

// "precision P (matched/events) recall R (matched/changes) mean IoU I", as every line below says it.
std::string describe(const ChangeScore& s) {
  char text[160];
  std::snprintf(text, sizeof text, "precision %.3f (%zu/%zu) recall %.3f (%zu/%zu) mean IoU %.3f", s.precision(),
                s.matched_events, s.events, s.recall(), s.matched_changes, s.true_changes, s.mean_iou());
  return text;
}

std::vector<Scene> load_scenes() {
  std::vector<Scene> scenes;
  for (int i = 0; i <= 44; ++i) scenes.push_back(load(i));
  return scenes;
}

// Calls f(before index, before, after, truth) for each pair of consecutive scenes of one camera.
template <class F>
void for_each_same_camera_pair(const std::vector<Scene>& scenes, F&& f) {
  for (int i = 0; i + 1 < static_cast<int>(scenes.size()); ++i) {
    const Scene &b = scenes[i], &a = scenes[i + 1];
    if (!b.file.cloud || !a.file.cloud || !same_camera(b, a)) continue;
    f(i, b, a, true_changes_from_labels(b.xyz, b.labels, a.xyz, a.labels));
  }
}

TEST(MosdChange, SameCameraPairs) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn0.pcd");
  const std::vector<Scene> scenes = load_scenes();
  ChangeScore total, evidence_only;
  DiffOptions without_completion;
  without_completion.change.complete_objects = false;
  std::size_t pairs = 0, pairs_with_change = 0;
  std::vector<double> ms, completion_ms;
  for_each_same_camera_pair(scenes, [&](int i, const Scene& b, const Scene& a, const std::vector<TrueChange>& truth) {
    Frame fb, fa;
    fb.cloud = b.file.cloud;
    fa.cloud = a.file.cloud;
    auto result = diff(fb, fa);
    ASSERT_TRUE(result.ok()) << result.error().message;
    EXPECT_EQ(result->method, DiffMethod::kSameCamera);
    const ChangeScore s = score_changes(result->events, truth);
    total += s;
    auto fringe = diff(fb, fa, without_completion);
    ASSERT_TRUE(fringe.ok()) << fringe.error().message;
    evidence_only += score_changes(fringe->events, truth);
    ++pairs;
    pairs_with_change += truth.empty() ? 0 : 1;
    ms.push_back(result->total_ms);
    completion_ms.push_back(result->completion_ms);
    std::printf("  learn%-2d -> learn%-2d  truth %zu (", i, i + 1, truth.size());
    for (const auto& t : truth) std::printf(" %s%u", t.indices_after.empty() ? "-" : "+", t.object_id);
    std::printf(" ) events %zu:", result->events.size());
    for (const auto& e : result->events) {
      double best = 0;
      for (const auto& t : truth) best = std::max(best, change_iou(e, t));
      std::printf(" %s(%zu/%zu %.2f)", to_string(e.kind), e.indices_before.size(), e.indices_after.size(), best);
    }
    for (const auto& t : truth) {
      double best = 0;
      for (const auto& e : result->events) best = std::max(best, change_iou(e, t));
      if (best < 0.5) std::printf("\n     missed %s%u (%zu/%zu points) best IoU %.2f", t.indices_after.empty() ? "-" : "+", t.object_id, t.indices_before.size(), t.indices_after.size(), best);
    }
    for (const auto& e : result->events) {
      bool m = false;
      for (const auto& t : truth) m = m || change_iou(e, t) >= 0.5;
      if (m) continue;
      std::map<std::uint32_t, int> hist;
      for (int k : e.indices_after) ++hist[a.labels[k]];
      for (int k : e.indices_before) ++hist[1000 + b.labels[k]];
      std::printf("\n     unmatched %s size %.3f at %.2f %.2f %.2f:", to_string(e.kind), e.evidence.at("size_m"), e.centroid_world.x(), e.centroid_world.y(), e.centroid_world.z());
      for (auto [l, n] : hist) std::printf(" %u:%d", l, n);
    }
    std::printf(" | matched events %zu/%zu changes %zu/%zu IoU %.2f | %.1f ms (completion %.1f)\n", s.matched_events,
                s.events, s.matched_changes, s.true_changes, s.mean_iou(), result->total_ms, result->completion_ms);
  });
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  std::printf("mOSD same-camera pairs: %zu (%zu with a change): %s, median %.1f ms per pair, of which whole-object "
              "completion %.1f ms\n",
              pairs, pairs_with_change, describe(total).c_str(), median(ms), median(completion_ms));
  std::printf("the evidence alone (no completion): %s\n", describe(evidence_only).c_str());
  EXPECT_GE(pairs, 15u) << "the data README lists about twenty same-camera pairs";
  EXPECT_GE(total.true_changes, 8u);
  // Strict scoring (IoU >= 0.5 with the whole object, both ways), pixel truth: 0.972 (70/72) and
  // 0.963 (105/109) when these floors were set, against 0.605 and 0.633 for the evidence alone.
  // Before the pixel truth (an object within 1-2 cm of any labelled surface counted unchanged, so
  // 2 cm slides and turns in place were no change) and before evidence over several objects was
  // split per object: 0.868 (59/68) and 0.891 (90/101). What is left: learn0 and learn19 each
  // hold a stack the segmentation returns as one object; learn41's new box is cut in pieces.
  EXPECT_GE(total.precision(), 0.95);
  EXPECT_GE(total.recall(), 0.95);
  EXPECT_GT(total.precision(), evidence_only.precision()) << "completion must pay for itself";
  EXPECT_GT(total.recall(), evidence_only.recall()) << "completion must pay for itself";
}

// The same pairs through the map path, as for two frames of different poses: BEFORE inserted
// into a 1 cm occupancy map by the default (fast) insertion, AFTER checked against it. This is
// where holes in the map's free space show: a ray shortcut that left 13x more of it unknown
// (ray_stop_after 16 instead of 32) cost the evidence 3 points of precision and 3 of recall.
TEST(MosdChange, MapPathOnSameCameraPairs) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn0.pcd");
  const std::vector<Scene> scenes = load_scenes();
  DiffOptions options;
  options.force_map = true;
  options.map.resolution_m = 0.01;
  DiffOptions evidence = options;
  evidence.change.complete_objects = false;
  ChangeScore total, evidence_only;
  std::size_t pairs = 0;
  for_each_same_camera_pair(scenes, [&](int, const Scene& b, const Scene& a, const std::vector<TrueChange>& truth) {
    Frame fb, fa;
    fb.cloud = b.file.cloud;
    fa.cloud = a.file.cloud;
    auto result = diff(fb, fa, options);
    ASSERT_TRUE(result.ok()) << result.error().message;
    EXPECT_EQ(result->method, DiffMethod::kMap);
    total += score_changes(result->events, truth);
    auto fringe = diff(fb, fa, evidence);
    ASSERT_TRUE(fringe.ok()) << fringe.error().message;
    evidence_only += score_changes(fringe->events, truth);
    ++pairs;
  });
  std::printf("mOSD same-camera pairs through the map path (1 cm): %zu pairs: %s; the evidence alone: %s\n", pairs,
              describe(total).c_str(), describe(evidence_only).c_str());
  EXPECT_GE(pairs, 15u);
  // Measured when these floors were set: whole objects 0.957 (66/69) and 0.908 (99/109), the
  // same at ray_stop_after 16, 32 and 0 (completion fills what the holes lose); the evidence alone
  // 0.494 (43/87) and 0.523 (57/109) at 32 and at 0, 0.461 (41/89) and 0.495 (54/109) at 16.
  EXPECT_GE(total.precision(), 0.94);
  EXPECT_GE(total.recall(), 0.89);
  EXPECT_GE(evidence_only.precision(), 0.48);
  EXPECT_GE(evidence_only.recall(), 0.51);
}

}  // namespace
}  // namespace scenewatch::change
