// The working memory end to end on synthetic and real frames: events, tracking, validation,
// snapshots, save and load.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <random>
#include <thread>

#include "scenewatch/io/cloud_io.h"
#include "scenewatch/pipeline/working_memory.h"
#include "shipped_config.h"
#include "test_data.h"

namespace scenewatch::pipeline {
namespace {
namespace fs = std::filesystem;

// A camera 1 m above a 1.2 x 1.2 m table top (world z = 0), looking down, rendered as an
// organized cloud by casting one ray per pixel against the table and axis-aligned boxes on it.
struct Box {
  Eigen::Vector3d lo, hi;
};

Cloud render(const std::vector<Box>& boxes, const Pose& T_world_camera, int w = 160, int h = 120) {
  Cloud c(w, h);
  const double f = 0.5 * w;  // 90 degree horizontal field of view
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector3d dir_c = Eigen::Vector3d((u - 0.5 * w) / f, (v - 0.5 * h) / f, 1.0).normalized();
      const Eigen::Vector3d o = T_world_camera.translation();
      const Eigen::Vector3d d = T_world_camera.linear() * dir_c;
      double best = std::numeric_limits<double>::infinity();
      if (d.z() < 0) {
        const double t = -o.z() / d.z();
        const Eigen::Vector3d p = o + t * d;
        if (std::abs(p.x()) <= 0.6 && std::abs(p.y()) <= 0.6) best = t;
      }
      for (const Box& b : boxes) {  // slab test
        double t0 = 0, t1 = best;
        for (int i = 0; i < 3; ++i) {
          const double inv = 1.0 / d(i);
          double a = (b.lo(i) - o(i)) * inv, c2 = (b.hi(i) - o(i)) * inv;
          if (a > c2) std::swap(a, c2);
          t0 = std::max(t0, a);
          t1 = std::min(t1, c2);
        }
        if (t0 <= t1 && t0 < best) best = t0;
      }
      PointT& p = c.at(u, v);
      if (!std::isfinite(best)) {
        p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const Eigen::Vector3f pc = (best * dir_c).cast<float>();
      p.getVector3fMap() = pc;
      p.r = p.g = p.b = 150;
    }
  return c;
}

Pose looking_down(double height = 1.0) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();  // z down, y flipped
  T.translation() = Eigen::Vector3d(0, 0, height);
  return T;
}

Frame make_frame(const std::vector<Box>& boxes, double stamp) {
  Frame f;
  f.cloud = std::make_shared<Cloud>(render(boxes, looking_down()));
  f.T_world_camera = looking_down();
  f.stamp_s = stamp;
  f.source = "synthetic";
  return f;
}

Config test_config() {
  Config c;
  c.segmentation.up = Eigen::Vector3d::UnitZ();
  c.segmentation.min_cluster_points = 20;
  c.background.resolution_m = 0.02;
  return c;
}

const Box kCube{{0.10, 0.10, 0.0}, {0.20, 0.20, 0.10}};
const Box kTall{{-0.25, -0.20, 0.0}, {-0.15, -0.10, 0.20}};

std::size_t count_kind(const std::vector<Event>& events, EventKind kind) {
  return static_cast<std::size_t>(std::count_if(events.begin(), events.end(), [kind](const Event& e) { return e.kind == kind; }));
}

TEST(WorkingMemory, ObjectListAppearsStaysAndGoes) {
  // The object list alone (change detection off): it raises no events; an object leaves the list
  // once its space was seen free in tracking.gone_frames (2) frames.
  Config config = test_config();
  config.change_enabled = false;
  WorkingMemory wm(config);

  auto r1 = wm.process(make_frame({kCube, kTall}, 1.0));
  ASSERT_TRUE(r1.ok()) << r1.error().message;
  ASSERT_EQ(r1->planes.size(), 1u);
  EXPECT_NEAR(r1->planes[0].normal.z(), 1.0, 1e-3) << "plane in world coordinates";
  EXPECT_NEAR(r1->planes[0].d, 0.0, 0.01);
  ASSERT_EQ(r1->objects.size(), 2u);
  EXPECT_TRUE(r1->events.empty()) << "first sight of an object is not a change";
  ASSERT_EQ(wm.snapshot()->objects.size(), 2u);

  // The same view again: the objects are matched, nothing new.
  auto r2 = wm.process(make_frame({kCube, kTall}, 2.0));
  ASSERT_TRUE(r2.ok());
  EXPECT_TRUE(r2->events.empty());
  auto snap = wm.snapshot();
  ASSERT_EQ(snap->objects.size(), 2u);
  for (const auto& o : snap->objects) EXPECT_EQ(o.observations, 2);
  const std::uint64_t max_id = std::max(snap->objects[0].id, snap->objects[1].id);

  // The cube is taken away: one frame that sees its space free is not enough, two are.
  ASSERT_TRUE(wm.process(make_frame({kTall}, 3.0)).ok());
  EXPECT_EQ(wm.snapshot()->objects.size(), 2u) << "hysteresis: one frame of free space";
  ASSERT_TRUE(wm.process(make_frame({kTall}, 4.0)).ok());
  snap = wm.snapshot();
  ASSERT_EQ(snap->objects.size(), 1u);
  EXPECT_NEAR(snap->objects[0].cluster.centroid.x(), -0.20, 0.03) << "the tall box stays";

  // A cube put somewhere else is a new object with a new id, listed once seen in
  // tracking.confirm_frames (2) frames: after the first frame, one sighting is not an object yet.
  const Box moved{{-0.25, 0.15, 0.0}, {-0.15, 0.25, 0.10}};
  auto r5 = wm.process(make_frame({kTall, moved}, 5.0));
  ASSERT_TRUE(r5.ok());
  EXPECT_TRUE(r5->events.empty());
  EXPECT_EQ(wm.snapshot()->objects.size(), 1u) << "seen once: not listed yet";
  ASSERT_TRUE(wm.process(make_frame({kTall, moved}, 6.0)).ok());
  snap = wm.snapshot();
  ASSERT_EQ(snap->objects.size(), 2u);
  EXPECT_GT(std::max(snap->objects[0].id, snap->objects[1].id), max_id) << "ids are never reused";
}

TEST(WorkingMemory, AChangeIsOneEventAndReachesSubscribers) {
  // With change detection on (the default): the cube taken away is one OBJECT_REMOVED, once the
  // removal held for change.persistence_frames (3) frames; the tracker adds nothing to it.
  WorkingMemory wm(test_config());
  std::vector<Event> pushed;
  const int token = wm.subscribe([&](const Event& e) { pushed.push_back(e); });
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(wm.process(make_frame({kCube, kTall}, 1.0 + i)).ok());
  EXPECT_TRUE(pushed.empty()) << "an unchanged scene raises nothing";
  for (int i = 0; i < 6; ++i) ASSERT_TRUE(wm.process(make_frame({kTall}, 4.0 + i)).ok());
  ASSERT_EQ(pushed.size(), 1u);
  EXPECT_EQ(pushed[0].kind, EventKind::kObjectRemoved);
  EXPECT_NEAR(pushed[0].centroid_world.x(), 0.15, 0.03);
  EXPECT_NEAR(pushed[0].centroid_world.y(), 0.15, 0.03);

  wm.unsubscribe(token);
  for (int i = 0; i < 6; ++i) ASSERT_TRUE(wm.process(make_frame({kTall, kCube}, 10.0 + i)).ok());
  EXPECT_EQ(pushed.size(), 1u) << "no events after unsubscribing";
  const auto log = wm.events_since(0);
  ASSERT_EQ(log.size(), 2u) << "removed, then added back";
  EXPECT_EQ(log[1].kind, EventKind::kObjectAdded);
  EXPECT_GT(log[1].id, log[0].id);
  EXPECT_EQ(wm.events_since(log[0].id).size(), 1u);

  // Reset forgets the log too; ids keep counting.
  wm.reset();
  EXPECT_TRUE(wm.events_since(0).empty());
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(wm.process(make_frame({kTall, kCube}, 20.0 + i)).ok());
  for (int i = 0; i < 6; ++i) ASSERT_TRUE(wm.process(make_frame({kTall}, 30.0 + i)).ok());
  const auto after_reset = wm.events_since(0);
  ASSERT_EQ(after_reset.size(), 1u);
  EXPECT_GT(after_reset[0].id, log[1].id);
}

TEST(WorkingMemory, OccludedObjectIsNotGone) {
  WorkingMemory wm(test_config());
  ASSERT_TRUE(wm.process(make_frame({kCube}, 1.0)).ok());
  // A large box now hides the cube from the camera: no evidence that it left.
  const Box cover{{0.05, 0.05, 0.0}, {0.25, 0.25, 0.6}};
  auto r = wm.process(make_frame({kCube, cover}, 2.0));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(count_kind(r->events, EventKind::kObjectGone), 0u);
}

TEST(WorkingMemory, BadFramesChangeNothing) {
  WorkingMemory wm(test_config());
  ASSERT_TRUE(wm.process(make_frame({kCube}, 1.0)).ok());
  const auto before = wm.snapshot();
  const Stats stats_before = wm.stats();

  Frame nan_pose = make_frame({kCube}, 2.0);
  nan_pose.T_world_camera->translation().x() = std::numeric_limits<double>::quiet_NaN();
  auto r = wm.process(nan_pose);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("non-finite"), std::string::npos);

  Frame skew = make_frame({kCube}, 2.0);
  skew.T_world_camera->linear()(0, 1) = 0.5;
  EXPECT_FALSE(wm.process(skew).ok());

  Frame empty;
  empty.cloud = std::make_shared<Cloud>();
  EXPECT_NE(wm.process(empty).error().message.find("empty"), std::string::npos);

  Frame all_nan;
  auto c = std::make_shared<Cloud>(4, 4);
  for (auto& p : c->points) p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
  all_nan.cloud = c;
  EXPECT_NE(wm.process(all_nan).error().message.find("no valid points"), std::string::npos);

  Frame wrong_k = make_frame({kCube}, 2.0);
  wrong_k.intrinsics = Intrinsics{500, 500, 320, 240, 640, 480};
  EXPECT_FALSE(wm.process(wrong_k).ok()) << "intrinsics for 640x480, cloud is 160x120";

  Frame huge = make_frame({kCube}, 2.0);
  auto far_cloud = std::make_shared<Cloud>(*huge.cloud);
  std::vector<PointT*> valid;
  for (auto& p : far_cloud->points)
    if (is_valid(p)) valid.push_back(&p);
  ASSERT_GE(valid.size(), 2u);
  valid[0]->x = 3e38f;
  valid[1]->z = -3e38f;
  huge.cloud = far_cloud;
  r = wm.process(huge);
  ASSERT_FALSE(r.ok()) << "finite but absurd coordinates";
  EXPECT_NE(r.error().message.find("2 points lie farther than 1000 m"), std::string::npos) << r.error().message;

  Frame long_camera = make_frame({kCube}, 2.0);
  long_camera.camera = std::string(129, 'c');
  r = wm.process(long_camera);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("camera name is 129 bytes long"), std::string::npos) << r.error().message;
  Frame control_camera = make_frame({kCube}, 2.0);
  control_camera.camera = "head\n";
  r = wm.process(control_camera);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("control character"), std::string::npos) << r.error().message;

  EXPECT_EQ(wm.snapshot(), before) << "the snapshot was not replaced";
  const Stats after = wm.stats();
  EXPECT_EQ(after.frames_processed, stats_before.frames_processed);
  EXPECT_EQ(after.map_leaf_nodes, stats_before.map_leaf_nodes);
}

TEST(WorkingMemory, OccupancyQueriesClearAndReset) {
  WorkingMemory wm(test_config());
  ASSERT_TRUE(wm.process(make_frame({kCube}, 1.0)).ok());
  EXPECT_EQ(wm.query({0.15, 0.15, 0.10}), background::Occupancy::kOccupied) << "the cube's top";
  EXPECT_EQ(wm.query({0.15, 0.15, 0.5}), background::Occupancy::kFree);
  EXPECT_EQ(wm.query({0.15, 0.15, 0.05}), background::Occupancy::kUnknown) << "inside the cube";
  EXPECT_EQ(wm.query_box({{0.1, 0.1, 0.09}, {0.2, 0.2, 0.11}}).state, background::Occupancy::kOccupied);
  EXPECT_GT(wm.clear_box({{0.1, 0.1, 0.08}, {0.2, 0.2, 0.12}}), 0u);
  EXPECT_EQ(wm.query({0.15, 0.15, 0.10}), background::Occupancy::kFree);
  wm.reset();
  EXPECT_EQ(wm.query({0.15, 0.15, 0.5}), background::Occupancy::kUnknown);
  EXPECT_TRUE(wm.snapshot()->objects.empty());
  EXPECT_EQ(wm.stats().frames_processed, 0u);
}

TEST(WorkingMemory, SaveAndLoadTheModelDirectory) {
  const test::TempDir dir("model");
  {
    WorkingMemory wm(test_config());
    EXPECT_EQ(wm.load(dir).error().code, ErrorCode::kNotFound) << "nothing saved yet";
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(wm.process(make_frame({kCube, kTall}, 1.0 + i)).ok());
    ASSERT_TRUE(wm.save(dir).ok());
    for (int i = 0; i < 4; ++i) ASSERT_TRUE(wm.process(make_frame({kTall}, 4.0 + i)).ok());
    ASSERT_TRUE(wm.save(dir).ok()) << "a second save replaces the first";
  }
  EXPECT_TRUE(fs::is_symlink(dir / "current"));
  std::size_t snapshots = 0;
  for (const auto& e : fs::directory_iterator(dir.path())) snapshots += e.path().filename().string().rfind("snap-", 0) == 0;
  EXPECT_EQ(snapshots, 1u) << "older snapshots are removed";

  WorkingMemory wm(test_config());
  ASSERT_TRUE(wm.load(dir).ok());
  auto snap = wm.snapshot();
  ASSERT_EQ(snap->objects.size(), 1u) << "the cube was gone at the second save";
  EXPECT_EQ(snap->planes.size(), 1u);
  EXPECT_EQ(wm.stats().frames_processed, 7u);
  EXPECT_DOUBLE_EQ(snap->last_stamp_s, 7.0) << "the last frame's stamp";
  ASSERT_EQ(wm.events_since(0).size(), 1u) << "the cube removed";
  EXPECT_EQ(wm.events_since(0)[0].kind, EventKind::kObjectRemoved);
  EXPECT_EQ(wm.query_box({{-0.22, -0.18, 0.18}, {-0.18, -0.12, 0.22}}).state, background::Occupancy::kOccupied)
      << "the map came back: the tall box's top";
  const std::uint64_t first_id = wm.events_since(0)[0].id;
  // New events continue the numbering; object ids are not reused.
  std::vector<Event> added;
  for (int i = 0; i < 5; ++i) {
    auto r = wm.process(make_frame({kTall, kCube}, 8.0 + i));
    ASSERT_TRUE(r.ok());
    added.insert(added.end(), r->events.begin(), r->events.end());
  }
  ASSERT_EQ(added.size(), 1u);
  EXPECT_EQ(added[0].kind, EventKind::kObjectAdded);
  EXPECT_GT(added[0].id, first_id);
  ASSERT_EQ(wm.snapshot()->objects.size(), 2u);
  for (const auto& o : wm.snapshot()->objects) EXPECT_TRUE(o.id == snap->objects[0].id || o.id > 2u);

  // A damaged model is refused and the loaded one stays.
  const fs::path current = fs::read_symlink(dir / "current");
  std::ofstream(dir / current / "scene.json") << "{ not json";
  auto st = wm.load(dir);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("scene.json"), std::string::npos);
  EXPECT_EQ(wm.snapshot()->objects.size(), 2u);
}

// The newest snapshots stay: a model saved over by mistake (a Reset, then a save) is still on disk,
// and pointing `current` back at it brings it back.
TEST(WorkingMemory, OlderSnapshotsAreKeptToUndoASave) {
  const test::TempDir dir("model");
  WorkingMemory wm(test_config());
  ASSERT_TRUE(wm.process(make_frame({kCube, kTall}, 1.0)).ok());
  ASSERT_TRUE(wm.save(dir, 3).ok());
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(wm.save(dir, 3).ok());
  wm.reset();
  ASSERT_TRUE(wm.save(dir, 3).ok()) << "the wiped model saved over the good one";
  std::vector<std::string> snapshots;
  for (const auto& e : fs::directory_iterator(dir.path())) {
    const std::string n = e.path().filename().string();
    if (n.rfind("snap-", 0) == 0) snapshots.push_back(n);
  }
  std::sort(snapshots.begin(), snapshots.end());
  ASSERT_EQ(snapshots, (std::vector<std::string>{"snap-000003", "snap-000004", "snap-000005"}));
  EXPECT_EQ(fs::read_symlink(dir / "current"), "snap-000005");
  WorkingMemory wiped(test_config());
  ASSERT_TRUE(wiped.load(dir).ok());
  EXPECT_EQ(wiped.stats().frames_processed, 0u);
  fs::remove(dir / "current");
  fs::create_directory_symlink("snap-000004", dir / "current");
  WorkingMemory restored(test_config());
  ASSERT_TRUE(restored.load(dir).ok());
  EXPECT_EQ(restored.stats().frames_processed, 1u) << "the model before the wipe";
  EXPECT_EQ(restored.snapshot()->objects.size(), 2u);
}

// A background.ot cut short (a full disk, a copy interrupted) is refused: OctoMap itself reads the
// first half of the tree and says nothing. The loaded model stays, and so does the file.
TEST(WorkingMemory, TruncatedBackgroundIsRefused) {
  const test::TempDir dir("model");
  {
    WorkingMemory wm(test_config());
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(wm.process(make_frame({kCube, kTall}, 1.0 + i)).ok());
    ASSERT_TRUE(wm.save(dir).ok());
  }
  const fs::path map = dir / fs::read_symlink(dir / "current") / "background.ot";
  const auto bytes = fs::file_size(map);
  fs::resize_file(map, bytes / 2);
  WorkingMemory wm(test_config());
  ASSERT_TRUE(wm.process(make_frame({kTall}, 1.0)).ok());
  auto st = wm.load(dir);
  ASSERT_FALSE(st.ok()) << "half a map must not load";
  EXPECT_NE(st.error().message.find("background.ot"), std::string::npos) << st.error().message;
  EXPECT_NE(st.error().message.find("damaged"), std::string::npos) << st.error().message;
  EXPECT_EQ(wm.stats().frames_processed, 1u) << "the model in memory is unchanged";
  EXPECT_EQ(fs::file_size(map), bytes / 2) << "nothing is written over the damaged file";
}

// At start-up a damaged newest snapshot is refused and the one before it is used; the damaged
// one and the `current` link stay as they are (nothing is deleted or written over).
TEST(WorkingMemory, StartUpFallsBackToTheNewestGoodSnapshot) {
  const test::TempDir dir("model");
  {
    WorkingMemory wm(test_config());
    for (int i = 0; i < 2; ++i) ASSERT_TRUE(wm.process(make_frame({kCube, kTall}, 1.0 + i)).ok());
    ASSERT_TRUE(wm.save(dir, 3).ok());
    ASSERT_TRUE(wm.process(make_frame({kCube, kTall}, 3.0)).ok());
    ASSERT_TRUE(wm.save(dir, 3).ok());
  }
  const fs::path newest = dir / fs::read_symlink(dir / "current");
  const auto bytes = fs::file_size(newest / "background.ot");
  fs::resize_file(newest / "background.ot", bytes / 2);

  WorkingMemory wm(test_config());
  EXPECT_FALSE(wm.load(dir).ok()) << "the strict load (LoadModel) still refuses the damaged current snapshot";
  auto loaded = wm.load_newest_good(dir);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_NE(loaded->folder.filename(), newest.filename());
  ASSERT_EQ(loaded->refused.size(), 1u);
  EXPECT_NE(loaded->refused[0].find("damaged"), std::string::npos) << loaded->refused[0];
  EXPECT_EQ(wm.stats().frames_processed, 2u) << "the older snapshot's model";
  EXPECT_EQ(dir / fs::read_symlink(dir / "current"), newest) << "current is left as it was";
  EXPECT_EQ(fs::file_size(newest / "background.ot"), bytes / 2) << "nothing is written over the damaged file";

  // No snapshot loads: an error naming each refusal. No model at all: kNotFound.
  fs::resize_file(loaded->folder / "background.ot", 10);
  WorkingMemory none(test_config());
  auto failed = none.load_newest_good(dir);
  ASSERT_FALSE(failed.ok());
  EXPECT_NE(failed.error().message.find("no snapshot loads"), std::string::npos) << failed.error().message;
  const test::TempDir empty("empty-model");
  EXPECT_EQ(none.load_newest_good(empty).error().code, ErrorCode::kNotFound);
}

TEST(WorkingMemory, ReadersRunWhileFramesAreProcessed) {
  WorkingMemory wm(test_config());
  std::atomic<bool> done{false};
  std::atomic<std::size_t> reads{0};
  std::thread reader([&] {
    while (!done) {
      auto s = wm.snapshot();
      ASSERT_NE(s, nullptr);
      wm.query({0, 0, 0.5});
      ++reads;
    }
  });
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(wm.process(make_frame({kCube, kTall}, i)).ok());
  done = true;
  reader.join();
  EXPECT_GT(reads.load(), 0u);
  EXPECT_EQ(wm.snapshot()->frames_processed, 10u);
}

TEST(WorkingMemory, RealKinectFrame) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn13.pcd");
  auto file = io::read_cloud(test::data_dir() / "mosd/learn/learn13.pcd");
  ASSERT_TRUE(file.ok());
  WorkingMemory wm(Config{});
  Frame f;
  f.cloud = file->cloud;
  f.stamp_s = 1;
  auto r = wm.process(f);
  ASSERT_TRUE(r.ok()) << r.error().message;
  std::printf("learn13: %zu planes, %zu objects, segment %.1f ms, insert %.1f ms, total %.1f ms\n", r->planes.size(),
              r->objects.size(), r->segment_ms, r->insert_ms, r->total_ms);
  EXPECT_EQ(r->planes.size(), 1u);
  EXPECT_EQ(r->objects.size(), 3u) << "learn13 has three boxes on the table";
  EXPECT_EQ(wm.snapshot()->objects.size(), 3u) << "in the object list at first sight (tracking.confirm_frames 1)";
  EXPECT_TRUE(r->events.empty()) << "a first frame reports no change";
}

// A single cloud of a pile lists at first sight what the segmentation finds: books lying on books,
// a sponge whose plane is the top of a book beside it, a tray under a box. None of them crosses
// its support's height, and none may be taken for something that does (the resting rule of the
// object list, pipeline/src/support_contact.h, drops a cluster only on evidence: the support's
// band beyond its foot, seen facing sideways). Measured with the shipped config: 146 objects
// listed of the 148 clusters of the 17 test_dev scenes, the same 146 as without the resting rule
// (the list's other rules leave out one cluster each in test49 and test57). A first version of the
// rule, whose patches took in the pile's neighbours and the object's own side, listed 141; one
// that also counted patches dropping below the band and facing sideways (a post's side), 145:
// test59's sponge, given the plane of a book's top beside it, with the table 3 cm lower.
TEST(WorkingMemory, EveryObjectOfAMosdPileIsListed) {
  SCENEWATCH_REQUIRE_DATA("mosd/test_dev/test59.pcd");
  const std::optional<Config> shipped = test::shipped_pipeline_config();
  ASSERT_TRUE(shipped);
  std::size_t clusters = 0, listed = 0;
  for (int n = 43; n <= 59; ++n) {
    auto file = io::read_cloud(test::data_dir() / ("mosd/test_dev/test" + std::to_string(n) + ".pcd"));
    ASSERT_TRUE(file.ok()) << file.error().message;
    WorkingMemory wm(*shipped);
    Frame f;
    f.cloud = file->cloud;
    f.stamp_s = 1;
    auto r = wm.process(f);
    ASSERT_TRUE(r.ok()) << r.error().message;
    clusters += r->objects.size();
    listed += wm.snapshot()->objects.size();
    std::printf("test%d: %zu listed of %zu clusters\n", n, wm.snapshot()->objects.size(), r->objects.size());
  }
  std::printf("test_dev: %zu objects listed of %zu clusters\n", listed, clusters);
  // Since the cut between stacked levels (segmentation.split_stacked): 155 of 157, the same two
  // left out; since the cut at depth steps (segmentation.split_depth_steps, 2026-12-03), 156 of
  // 158, still those two.
  EXPECT_EQ(clusters, 158u);
  EXPECT_EQ(listed, 156u);
}

}  // namespace
}  // namespace scenewatch::pipeline
