// The ontology as a pipeline stage (issue 33 item 2): a WorkingMemory given a real cloud describes
// its objects with classes, without any service, and keeps the description until the object is
// seen again. The oracle is the daemon's (daemon_test, `scenewatch fit`): the PCL mug is a cup of
// 42 mm mean radius.
#include <gtest/gtest.h>

#include <vector>

#include "scenewatch/io/sequence.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/pipeline/working_memory.h"
#include "test_data.h"

namespace scenewatch::pipeline {
namespace {

const char* const kMug = "pcl/table_scene_mug_stereo_textured.pcd";

TEST(ObjectDescriberTest, AWorkingMemoryDescribesARealMugAsACup) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  auto frame = io::load_cloud_frame(test::data_dir() / kMug);
  ASSERT_TRUE(frame.ok()) << frame.error().message;
  auto classes = ontology::ClassCatalog::open(test::source_dir() / "config/ontology.yaml", {});
  ASSERT_TRUE(classes.ok()) << classes.error().message;
  WorkingMemory memory(Config{});
  ASSERT_TRUE(memory.process(*frame).ok());
  const auto snapshot = memory.snapshot();
  ASSERT_GE(snapshot->objects.size(), 1u);

  std::vector<std::uint64_t> told;  // the objects described anew
  const auto tell = [&](const TrackedObject& object, const ObjectClassInfo&) { told.push_back(object.id); };
  const auto described = memory.describe_objects(*snapshot, **classes, tell);
  ASSERT_EQ(described.size(), snapshot->objects.size()) << "one entry per object, in the snapshot's order";
  std::size_t mug = 0;  // the mug is the largest object on the table
  for (std::size_t k = 1; k < snapshot->objects.size(); ++k)
    if (snapshot->objects[k].cluster.point_count > snapshot->objects[mug].cluster.point_count) mug = k;
  ASSERT_NE(described[mug], nullptr) << "a tracked object has points";
  EXPECT_EQ(described[mug]->class_name, "cup");
  EXPECT_GT(described[mug]->score, 0.5);
  ASSERT_TRUE(described[mug]->primitive.has_value());
  EXPECT_NEAR(described[mug]->primitive->radius_m, 0.042, 0.002);
  EXPECT_GE(described[mug]->grasps.size(), 1u);
  std::size_t with_points = 0;
  for (const auto& d : described) with_points += d ? 1 : 0;
  EXPECT_EQ(told.size(), with_points) << "each description made is told once";

  // Asked again at once: the same descriptions from the cache, none made anew.
  told.clear();
  const auto again = memory.describe_objects(*snapshot, **classes, tell);
  EXPECT_TRUE(told.empty());
  ASSERT_EQ(again.size(), described.size());
  for (std::size_t k = 0; k < again.size(); ++k) EXPECT_EQ(again[k], described[k]) << "object " << k;

  // A reset forgets the known surfaces the descriptions made, and the descriptions with them:
  // asked again at once, every object is described anew (ids are reused after a reset).
  memory.reset();
  told.clear();
  memory.describe_objects(*snapshot, **classes, tell);
  EXPECT_EQ(told.size(), with_points) << "the cache must not outlive a reset";
}

}  // namespace
}  // namespace scenewatch::pipeline
