// Real data: consecutive mOSD scenes taken from the same, unmoved Kinect while objects were added,
// removed or moved. The labels give the objects; a labelled object of AFTER with no labelled
// object surface of BEFORE within 1 cm is a true addition (and the other way round a removal,
// unless AFTER occludes it). Object-level precision and recall, strict (point IoU >= 0.5 with the
// whole object, both ways), are printed per pair and overall.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>

#include "scenewatch/change/diff.h"
#include "scenewatch/change/evaluation.h"
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

TEST(MosdChange, SameCameraPairs) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn0.pcd");
  std::vector<Scene> scenes;
  for (int i = 0; i <= 44; ++i) scenes.push_back(load(i));
  ChangeScore total;
  std::size_t pairs = 0, pairs_with_change = 0;
  std::vector<double> ms;
  for (int i = 0; i + 1 <= 44; ++i) {
    const Scene &b = scenes[i], &a = scenes[i + 1];
    if (!b.file.cloud || !a.file.cloud || !same_camera(b, a)) continue;
    const auto truth = true_changes_from_labels(b.xyz, b.labels, a.xyz, a.labels);
    Frame fb, fa;
    fb.cloud = b.file.cloud;
    fa.cloud = a.file.cloud;
    auto result = diff(fb, fa);
    ASSERT_TRUE(result.ok()) << result.error().message;
    EXPECT_EQ(result->method, DiffMethod::kSameCamera);
    const ChangeScore s = score_changes(result->events, truth);
    total += s;
    ++pairs;
    pairs_with_change += truth.empty() ? 0 : 1;
    ms.push_back(result->total_ms);
    std::printf("  learn%-2d -> learn%-2d  truth %zu (", i, i + 1, truth.size());
    for (const auto& t : truth) std::printf(" %s%u", t.indices_after.empty() ? "-" : "+", t.object_id);
    std::printf(" ) events %zu:", result->events.size());
    for (const auto& e : result->events) {
      std::printf(" %s(%zu/%zu)", to_string(e.kind), e.indices_before.size(), e.indices_after.size());
    }
    for (const auto& e : result->events) {
      bool m = false;
      for (const auto& t : truth) m = m || change_iou(e, t) >= 0.3;
      if (m) continue;
      std::map<std::uint32_t, int> hist;
      for (int k : e.indices_after) ++hist[a.labels[k]];
      for (int k : e.indices_before) ++hist[1000 + b.labels[k]];
      std::printf("\n     unmatched %s size %.3f at %.2f %.2f %.2f:", to_string(e.kind), e.evidence.at("size_m"), e.centroid_world.x(), e.centroid_world.y(), e.centroid_world.z());
      for (auto [l, n] : hist) std::printf(" %u:%d", l, n);
    }
    std::printf(" | matched events %zu/%zu changes %zu/%zu IoU %.2f | %.1f ms\n", s.matched_events, s.events,
                s.matched_changes, s.true_changes, s.mean_iou(), result->total_ms);
  }
  std::sort(ms.begin(), ms.end());
  std::printf("mOSD same-camera pairs: %zu (%zu with a change): precision %.3f (%zu/%zu) recall %.3f (%zu/%zu) mean IoU %.3f, median %.1f ms\n",
              pairs, pairs_with_change, total.precision(), total.matched_events, total.events, total.recall(),
              total.matched_changes, total.true_changes, total.mean_iou(), ms.empty() ? 0.0 : ms[ms.size() / 2]);
  EXPECT_GE(pairs, 15u) << "the data README lists about twenty same-camera pairs";
  EXPECT_GE(total.true_changes, 8u);
  // Strict scoring (IoU >= 0.5 with the whole object, both ways): 0.558 and 0.634 when these
  // floors were set; the lenient scoring of before (majority precision, recall at IoU 0.3) gave
  // 0.826 and 0.871 on the same events. Issue 10 (whole-object events) is to raise them.
  EXPECT_GE(total.precision(), 0.55);
  EXPECT_GE(total.recall(), 0.63);
}

}  // namespace
}  // namespace scenewatch::change
