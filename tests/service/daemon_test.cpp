// Integration: the real scenewatchd binary on a loopback port, driven through the protocol.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <chrono>
#include <thread>

#include <Eigen/Geometry>

#include "daemon_harness.h"
#include "scenewatch.pb.h"
#include "scenewatch/background/appearance.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/sim/simulator.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/service/frame_parser.h"
#include "shipped_scenario.h"

namespace scenewatch::test {
namespace {
namespace fs = std::filesystem;
using service::Client;

const char* const kMug = "pcl/table_scene_mug_stereo_textured.pcd";

proto::Request health() {
  return request([](proto::Request& r) { r.mutable_health(); });
}
proto::Request get_objects() {
  return request([](proto::Request& r) { r.mutable_get_objects(); });
}
proto::Request get_planes() {
  return request([](proto::Request& r) { r.mutable_get_planes(); });
}
proto::Request ingest_file(const fs::path& path) {
  return request([&](proto::Request& r) { r.mutable_ingest_file()->set_path(path.string()); });
}

class DaemonTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_ = make_temp_dir("daemon");
    data_root_ = tmp_ / "data";
    model_dir_ = tmp_ / "model";
    fs::create_directories(data_root_);
  }

  void TearDown() override {
    if (HasFailure()) std::cerr << "---- scenewatchd log ----\n" << daemon_.log() << "-------------------------\n";
    daemon_ = Daemon();  // kills the process if it still runs
    std::error_code ec;
    fs::remove_all(tmp_, ec);
  }

  /// Server section with the test's data roots and model directory.
  std::string server_yaml(const std::string& extra = "") const {
    std::string roots = "[" + data_root_.string();
    if (fs::exists(data_dir() / "pcl")) roots += ", " + (data_dir() / "pcl").string();
    roots += "]";
    return "  data_roots: " + roots + "\n  model_dir: " + model_dir_.string() + "\n" + extra;
  }

  proto::Request ingest_mug() const {
    auto frame = io::load_cloud_frame(data_dir() / kMug);
    EXPECT_TRUE(frame.ok()) << frame.error().message;
    proto::Request r;
    if (frame.ok()) *r.mutable_ingest_frame() = service::make_ingest_frame(*frame);
    return r;
  }

  /// The first n frames of 7-Scenes redkitchen as IngestFrame requests (fewer on a read error).
  std::vector<proto::Request> kitchen_frames(std::size_t n) const {
    std::vector<proto::Request> out;
    auto seq = io::open_sequence(data_dir() / "redkitchen");
    EXPECT_TRUE(seq.ok()) << seq.error().message;
    for (std::size_t i = 0; seq.ok() && i < n && i < seq->frames.size(); ++i) {
      auto frame = io::load_sequence_frame(*seq, i);
      EXPECT_TRUE(frame.ok()) << frame.error().message;
      if (!frame.ok()) break;
      *out.emplace_back().mutable_ingest_frame() = service::make_ingest_frame(*frame);
    }
    return out;
  }

  fs::path tmp_, data_root_, model_dir_;
  Daemon daemon_;
};

TEST_F(DaemonTest, IngestQuerySubscribeAndPersistAcrossRestarts) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml()));

  Client client = daemon_.connect();
  const auto alive = call(client, health());
  ASSERT_EQ(alive.status().code(), proto::Status::OK);
  EXPECT_EQ(alive.health().frames_processed(), 0u);

  const auto ingested = call(client, ingest_mug());
  ASSERT_EQ(ingested.status().code(), proto::Status::OK) << ingested.status().message();
  EXPECT_GE(ingested.ingest().planes_size(), 1);
  EXPECT_GE(ingested.ingest().clusters_size(), 1);

  EXPECT_EQ(ingested.ingest().events_size(), 0) << "a first frame reports no change";

  // The same scene read by the daemon itself, from an allowed root.
  const auto by_file = call(client, ingest_file(fs::absolute(data_dir() / kMug)));
  ASSERT_EQ(by_file.status().code(), proto::Status::OK) << by_file.status().message();
  EXPECT_GE(by_file.ingest().planes_size(), 1);

  // Outside the roots, even through "..": refused without reading.
  for (const fs::path& outside : {fs::path("/etc/passwd"), data_root_ / ".." / ".." / "etc" / "passwd"}) {
    const auto denied = call(client, ingest_file(outside));
    EXPECT_EQ(denied.status().code(), proto::Status::PERMISSION_DENIED) << outside;
    EXPECT_NE(denied.status().message().find("outside the data roots"), std::string::npos)
        << denied.status().message();
  }

  const auto planes = call(client, get_planes());
  ASSERT_EQ(planes.status().code(), proto::Status::OK);
  EXPECT_GE(planes.planes().planes_size(), 1);
  const auto objects = call(client, get_objects());
  ASSERT_EQ(objects.status().code(), proto::Status::OK);
  ASSERT_GE(objects.objects().objects_size(), 1);
  EXPECT_EQ(objects.objects().frames_processed(), 2u);
  EXPECT_FALSE(objects.objects().objects(0).has_ontology()) << "described only on request";

  // Described by the ontology on request: the mug is a cup (42.1 mm mean radius measured, as
  // `scenewatch fit` finds it offline), with its grasps.
  const auto described = call(client, request([](proto::Request& r) { r.mutable_get_objects()->set_describe(true); }));
  ASSERT_EQ(described.status().code(), proto::Status::OK) << described.status().message();
  const proto::Object* mug = nullptr;
  for (const auto& o : described.objects().objects())
    if (!mug || o.point_count() > mug->point_count()) mug = &o;
  ASSERT_NE(mug, nullptr);
  ASSERT_TRUE(mug->has_ontology());
  EXPECT_EQ(mug->ontology().class_name(), "cup");
  EXPECT_NEAR(mug->ontology().primitive().radius_m(), 0.042, 0.002);
  EXPECT_GE(mug->ontology().grasps_size(), 1);

  const auto stats = call(client, request([](proto::Request& r) { r.mutable_stats(); }));
  EXPECT_EQ(stats.stats().frames_processed(), 2u);
  EXPECT_GE(stats.stats().connections(), 1u);

  // SIGTERM saves the model; a new daemon on the same model directory finds it again.
  ASSERT_EQ(daemon_.terminate(), std::optional<int>(0)) << daemon_.log();
  EXPECT_NE(daemon_.log().find("saved the model"), std::string::npos) << daemon_.log();
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml()));
  Client again = daemon_.connect();
  const auto restored = call(again, get_objects());
  ASSERT_EQ(restored.status().code(), proto::Status::OK);
  ASSERT_EQ(restored.objects().objects_size(), objects.objects().objects_size());
  for (int i = 0; i < objects.objects().objects_size(); ++i) {
    EXPECT_EQ(restored.objects().objects(i).id(), objects.objects().objects(i).id());
    EXPECT_EQ(restored.objects().objects(i).point_count(), objects.objects().objects(i).point_count());
    EXPECT_NEAR(restored.objects().objects(i).centroid().x(), objects.objects().objects(i).centroid().x(), 1e-9);
  }
  const auto restored_planes = call(again, get_planes());
  EXPECT_EQ(restored_planes.planes().planes_size(), planes.planes().planes_size());
  EXPECT_EQ(restored_planes.planes().frames_processed(), 2u);
}

TEST_F(DaemonTest, SubscribersHearAChangeOnce) {
  // learn12 -> learn13 of mOSD through the daemon over TCP: the same Kinect, unmoved, an object
  // put on the table. The subscriber hears OBJECT_ADDED once the change held for
  // change.persistence_frames (3) frames, and nothing more while the scene stays as it is.
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn13.pcd");
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml()));
  Client subscriber = daemon_.connect();
  const auto subscribed = call(subscriber, request([](proto::Request& r) { r.mutable_subscribe(); }));
  ASSERT_EQ(subscribed.status().code(), proto::Status::OK) << subscribed.status().message();
  auto frame_of = [](const char* name) {
    auto frame = io::load_cloud_frame(data_dir() / "mosd/learn" / name);
    EXPECT_TRUE(frame.ok()) << frame.error().message;
    proto::Request r;
    if (frame.ok()) *r.mutable_ingest_frame() = service::make_ingest_frame(*frame);
    return r;
  };
  const proto::Request before = frame_of("learn12.pcd"), after = frame_of("learn13.pcd");
  Client client = daemon_.connect();
  ASSERT_EQ(call(client, before).status().code(), proto::Status::OK);
  int replied = 0;
  for (int i = 0; i < 8; ++i) {
    const auto response = call(client, after);
    ASSERT_EQ(response.status().code(), proto::Status::OK) << response.status().message();
    replied += response.ingest().events_size();
    EXPECT_TRUE(i >= 2 || response.ingest().events_size() == 0) << "confirmed on the third frame, not before";
  }
  ASSERT_GE(replied, 1);
  for (int k = 0; k < replied; ++k) {
    auto event = subscriber.next_event(kCallTimeoutS);
    ASSERT_TRUE(event.ok()) << event.error().message;
    EXPECT_EQ(event->kind(), proto::Event::OBJECT_ADDED);
    EXPECT_EQ(event->level(), proto::Event::MISMATCH);
    EXPECT_GT(event->id(), subscribed.subscribe().last_event_id());
  }
  auto extra = subscriber.next_event(0.5);
  EXPECT_FALSE(extra.ok()) << "one fact, one event: nothing more was pushed";
  const auto log = call(client, request([](proto::Request& r) { r.mutable_get_events()->set_since(0); }));
  EXPECT_EQ(log.events().events_size(), replied);
}

TEST_F(DaemonTest, RealKitchenStreamedOverTcpIsCalm) {
  // The calm stream as a planner meets it: 50 posed VGA RGB-D frames of an unchanged room
  // (7-Scenes redkitchen, hand-held camera) sent over TCP, a subscriber listening. Before the calm
  // stream work this raised 1386 events; the offline replay and the daemon must agree on none.
  SCENEWATCH_REQUIRE_DATA("redkitchen/frame-000150.color.png");
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml()));
  Client subscriber = daemon_.connect();
  ASSERT_EQ(call(subscriber, request([](proto::Request& r) { r.mutable_subscribe(); })).status().code(),
            proto::Status::OK);
  auto seq = io::open_sequence(data_dir() / "redkitchen");
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  Client client = daemon_.connect();
  int replied = 0;
  for (std::size_t i = 0; i < seq->frames.size(); ++i) {
    auto frame = io::load_sequence_frame(*seq, i);
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    proto::Request r;
    *r.mutable_ingest_frame() = service::make_ingest_frame(*frame);
    const auto response = call(client, r);
    ASSERT_EQ(response.status().code(), proto::Status::OK) << response.status().message();
    replied += response.ingest().events_size();
  }
  EXPECT_EQ(replied, 0);
  EXPECT_FALSE(subscriber.next_event(0.5).ok()) << "nothing was pushed";
  const auto stats = call(client, request([](proto::Request& r) { r.mutable_stats(); }));
  EXPECT_EQ(stats.stats().frames_processed(), seq->frames.size());
  EXPECT_EQ(stats.stats().events_emitted(), 0u);
}

TEST_F(DaemonTest, FramesSentAheadAreAnsweredInOrderAsIfSentOneByOne) {
  // A client that sends the next frame before the reply to the one before (`scenewatch ingest`
  // keeps two in flight; the daemon decodes the next while it processes the one before): the
  // replies come in request order and say what the same frames sent one by one say. A request
  // sent behind the frames, without waiting, sees all of them.
  SCENEWATCH_REQUIRE_DATA("redkitchen/frame-000150.color.png");
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml()));
  constexpr std::uint64_t kFrames = 6;
  const std::vector<proto::Request> frames = kitchen_frames(kFrames);
  ASSERT_EQ(frames.size(), kFrames);
  // What a reply says, without its timings.
  auto summary = [](const proto::IngestReply& r) {
    std::string s = std::to_string(r.frame_index()) + " " + std::to_string(r.points()) + " planes " +
                    std::to_string(r.planes_size()) + " events " + std::to_string(r.events_size()) + " clusters";
    for (const auto& c : r.clusters()) s += " " + std::to_string(c.point_count());
    return s;
  };
  Client client = daemon_.connect();
  std::vector<std::string> one_by_one;
  for (const auto& r : frames) {
    const auto response = call(client, r);
    ASSERT_EQ(response.status().code(), proto::Status::OK) << response.status().message();
    one_by_one.push_back(summary(response.ingest()));
  }
  ASSERT_EQ(call(client, request([](proto::Request& r) { r.mutable_reset(); })).status().code(), proto::Status::OK);

  std::vector<std::uint64_t> ids;
  for (const auto& r : frames) {
    auto id = client.start(r);
    ASSERT_TRUE(id.ok()) << id.error().message;
    ids.push_back(*id);
  }
  auto planes_id = client.start(get_planes());
  ASSERT_TRUE(planes_id.ok());
  for (std::uint64_t i = 0; i < kFrames; ++i) {
    auto reply = client.receive(120);
    ASSERT_TRUE(reply.ok()) << reply.error().message;
    ASSERT_EQ(reply->id(), ids[i]) << "replies come in request order";
    ASSERT_EQ(reply->status().code(), proto::Status::OK) << reply->status().message();
    EXPECT_EQ(summary(reply->ingest()), one_by_one[i]) << "frame " << i;
  }
  auto planes = client.receive(120);
  ASSERT_TRUE(planes.ok()) << planes.error().message;
  ASSERT_EQ(planes->id(), *planes_id);
  EXPECT_EQ(planes->planes().frames_processed(), kFrames) << "a query behind the frames waits for all of them";
}

TEST_F(DaemonTest, ALiveStreamThatOutpacesTheModelSkipsToTheNewestFrame) {
  // A live sensor sends 30 frames/s without waiting for replies; a room frame takes longer than
  // 33 ms. Eight VGA kitchen frames sent back to back as live frames: the first is processed at
  // once, the ones that arrived meanwhile are answered "skipped" except the newest, which is
  // processed. Every request gets its reply, in order. Frames not marked live are never skipped.
  SCENEWATCH_REQUIRE_DATA("redkitchen/frame-000150.color.png");
  // A 1 cm map keeps a room frame's processing well above the daemon's reading of the next 4.6 MB
  // frame off the socket: at 2 cm the two were within a factor of 2-3, and under the suite's
  // parallel load only 4 of 8 were skipped. At 1 cm: 6 of 8, alone and beside other tests
  // (2026-11-27; the floor below is 5).
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml() + "background:\n  resolution_m: 0.01\n"));
  constexpr std::uint64_t kFrames = 8;
  std::vector<proto::Request> requests = kitchen_frames(kFrames);
  ASSERT_EQ(requests.size(), kFrames);
  for (std::uint64_t i = 0; i < kFrames; ++i) requests[i].set_id(i + 1);
  auto send_all = [&](bool live) {
    Client client = daemon_.connect();
    for (auto& r : requests) {
      r.mutable_ingest_frame()->set_live(live);
      r.set_token(daemon_.token());
      EXPECT_TRUE(client.send(r).ok());
    }
    std::vector<bool> skipped;
    for (std::uint64_t i = 0; i < kFrames; ++i) {
      auto reply = client.receive(120);
      EXPECT_TRUE(reply.ok()) << (reply.ok() ? "" : reply.error().message);
      if (!reply.ok()) break;
      EXPECT_EQ(reply->id(), i + 1) << "replies come in request order";
      EXPECT_EQ(reply->status().code(), proto::Status::OK) << reply->status().message();
      skipped.push_back(reply->ingest().skipped());
    }
    return skipped;
  };

  const std::vector<bool> live = send_all(true);
  ASSERT_EQ(live.size(), kFrames);
  const auto skipped = static_cast<std::uint64_t>(std::count(live.begin(), live.end(), true));
  std::printf("8 live frames back to back: %llu processed, %llu skipped\n",
              static_cast<unsigned long long>(kFrames - skipped), static_cast<unsigned long long>(skipped));
  EXPECT_FALSE(live.front()) << "the first frame finds nothing newer waiting";
  EXPECT_FALSE(live.back()) << "the newest frame is always processed";
  EXPECT_GE(skipped, kFrames - 3) << "frames that arrived during one frame's processing are skipped";
  Client client = daemon_.connect();
  auto stats = call(client, request([](proto::Request& r) { r.mutable_stats(); }));
  EXPECT_EQ(stats.stats().frames_skipped(), skipped);
  EXPECT_EQ(stats.stats().frames_processed(), kFrames - skipped);

  const std::vector<bool> queued = send_all(false);
  EXPECT_EQ(std::count(queued.begin(), queued.end(), true), 0) << "frames not marked live are all processed";
  stats = call(client, request([](proto::Request& r) { r.mutable_stats(); }));
  EXPECT_EQ(stats.stats().frames_processed(), 2 * kFrames - skipped);
}

TEST_F(DaemonTest, SimulatedChangesReachTheSubscriberOnceEach) {
  // The simulator's cup_added and object_moved (320x240, 12 frames per phase, hand-held camera)
  // streamed over TCP into a fresh daemon each: the subscriber hears exactly one event, of the
  // right kind, where the truth says, and nothing else.
  struct Case {
    const char* scenario;
    proto::Event::Kind kind;
  };
  for (const Case& c : {Case{"cup_added", proto::Event::OBJECT_ADDED}, Case{"object_moved", proto::Event::OBJECT_MOVED}}) {
    SCOPED_TRACE(c.scenario);
    ShippedScenario shipped = shipped_scenario(c.scenario, 320, 240, 12);
    ASSERT_TRUE(shipped.simulator);
    const sim::Scenario& scenario = shipped.scenario;
    auto& simulator = shipped.simulator;
    const auto truth = simulator->changes();
    ASSERT_EQ(truth.size(), 1u);
    const Eigen::Vector2d where = c.kind == proto::Event::OBJECT_ADDED
                                      ? Eigen::Vector2d(truth[0].added.at(0).T_world_object.translation().head<2>())
                                      : Eigen::Vector2d(truth[0].moved.at(0).T_world_after.translation().head<2>());
    ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml() + "segmentation:\n  up_vector: [0, 0, 1]\n"));
    Client subscriber = daemon_.connect();
    ASSERT_EQ(call(subscriber, request([](proto::Request& r) { r.mutable_subscribe(); })).status().code(),
              proto::Status::OK);
    Client client = daemon_.connect();
    double stamp = 0;
    for (std::size_t phase = 0; phase < simulator->phase_count(); ++phase) {
      for (int f = 0; f < simulator->frame_count(phase); ++f) {
        auto frame = sim::as_frame(simulator->render(phase, f), scenario.intrinsics, stamp += 1.0 / 30);
        ASSERT_TRUE(frame.ok());
        proto::Request r;
        *r.mutable_ingest_frame() = service::make_ingest_frame(*frame);
        const auto response = call(client, r);
        ASSERT_EQ(response.status().code(), proto::Status::OK) << response.status().message();
      }
    }
    auto event = subscriber.next_event(kCallTimeoutS);
    ASSERT_TRUE(event.ok()) << event.error().message;
    EXPECT_EQ(event->kind(), c.kind);
    EXPECT_LT((Eigen::Vector2d(event->centroid_world().x(), event->centroid_world().y()) - where).norm(), 0.10);
    EXPECT_FALSE(subscriber.next_event(0.5).ok()) << "one fact, one event";
    ASSERT_EQ(daemon_.terminate(), std::optional<int>(0)) << daemon_.log();
    std::error_code ec;
    fs::remove_all(model_dir_, ec);  // the next case starts from an empty model
  }
}

// Issue 13's persistence through the daemon: the simulator's hand_picks_cup_upright (320x240, all
// its frames: a hand lifts the cup, carries it and turns it about its axis, puts it down) streamed
// over TCP. Describing the objects records them as instances in MODEL_DIR/ontology.sqlite, and the
// handled cup teaches the cup class its motions (free x y z yaw, frozen roll pitch), which
// ListClasses shows beside the defined ones and a restarted daemon still knows.
TEST_F(DaemonTest, HandledObjectsTeachTheirClassMotionsThatSurviveARestart) {
  auto loaded = sim::load_scenario(source_dir() / "sample_clouds/scenarios/hand_picks_cup_upright.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  const sim::Scenario scenario = sim::with_resolution(*loaded, 320, 240);
  auto simulator = sim::Simulator::create(scenario);
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml()));
  Client client = daemon_.connect();
  double stamp = 0;
  for (std::size_t phase = 0; phase < simulator->phase_count(); ++phase) {
    for (int f = 0; f < simulator->frame_count(phase); ++f) {
      auto frame = sim::as_frame(simulator->render(phase, f), simulator->scenario().intrinsics, stamp += 1.0 / 30);
      ASSERT_TRUE(frame.ok());
      proto::Request r;
      *r.mutable_ingest_frame() = service::make_ingest_frame(*frame);
      ASSERT_EQ(call(client, r).status().code(), proto::Status::OK);
    }
  }
  const auto described = call(client, request([](proto::Request& r) { r.mutable_get_objects()->set_describe(true); }));
  ASSERT_EQ(described.status().code(), proto::Status::OK) << described.status().message();
  const proto::Object* cup = nullptr;
  for (const auto& o : described.objects().objects())
    if (o.foreground()) cup = &o;
  ASSERT_NE(cup, nullptr) << "the cup was promoted to the foreground";
  ASSERT_EQ(cup->ontology().class_name(), "cup");
  ASSERT_EQ(std::vector<std::string>(cup->free_dofs().begin(), cup->free_dofs().end()),
            (std::vector<std::string>{"x", "y", "z", "yaw"}));
  // Asked again at once: the cached description, no second instance.
  ASSERT_EQ(call(client, request([](proto::Request& r) { r.mutable_get_objects()->set_describe(true); })).status().code(),
            proto::Status::OK);

  // The class as defined allows fewer motions than were learnt: ListClasses says which is which.
  proto::Request define;
  define.mutable_define_class()->set_yaml(
      "classes:\n  - {name: cup, shape: frustum, radius_m: [0.025, 0.07], height_m: [0.04, 0.18], taper_deg: [-5, 15],"
      " top: open, max_rms_m: 0.005, min_explained: 0.4, allowed_dofs: [z]}\n");
  ASSERT_EQ(call(client, define).status().code(), proto::Status::OK);
  auto cup_class = [](const proto::Response& listed) {
    proto::ObjectClass found;
    for (const auto& c : listed.list_classes().classes())
      if (c.name() == "cup") found = c;
    return found;
  };
  auto strings = [](const google::protobuf::RepeatedPtrField<std::string>& field) {
    return std::vector<std::string>(field.begin(), field.end());
  };
  const auto list = request([](proto::Request& r) { r.mutable_list_classes(); });
  for (int run = 0; run < 2; ++run) {
    SCOPED_TRACE(run == 0 ? "before the restart" : "after the restart");
    const proto::ObjectClass c = cup_class(call(client, list));
    EXPECT_EQ(strings(c.defined_dofs()), (std::vector<std::string>{"z"}));
    EXPECT_EQ(strings(c.learnt_free_dofs()), (std::vector<std::string>{"x", "y", "z", "yaw"}));
    EXPECT_EQ(strings(c.learnt_frozen_dofs()), (std::vector<std::string>{"roll", "pitch"}));
    EXPECT_EQ(strings(c.allowed_dofs()), (std::vector<std::string>{"x", "y", "z", "yaw"}));
    if (run == 1) break;
    ASSERT_EQ(daemon_.terminate(), std::optional<int>(0)) << daemon_.log();
    {  // Every object described once (the second GetObjects used the cache), the cup among them.
      auto store = ontology::ClassStore::open(model_dir_ / ontology::kClassStoreFile);
      ASSERT_TRUE(store.ok()) << store.error().message;
      auto instances = store->instances();
      ASSERT_TRUE(instances.ok()) << instances.error().message;
      const auto with_class = std::count_if(described.objects().objects().begin(), described.objects().objects().end(),
                                            [](const proto::Object& o) { return !o.ontology().class_name().empty(); });
      EXPECT_EQ(instances->size(), static_cast<std::size_t>(with_class));
      auto cups = store->instances("cup");
      ASSERT_TRUE(cups.ok());
      ASSERT_GE(cups->size(), 1u);
      EXPECT_NE(cups->back().parameters_json.find("\"radius_m\""), std::string::npos) << cups->back().parameters_json;
    }
    ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml()));
    client = daemon_.connect();
  }
}

TEST_F(DaemonTest, BadClientsNeitherChangeTheModelNorStopTheDaemon) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml("  read_timeout_s: 0.3\n  frame_timeout_s: 1.0\n")));
  Client setup = daemon_.connect();
  ASSERT_EQ(call(setup, ingest_mug()).status().code(), proto::Status::OK);
  const auto baseline = call(setup, get_objects());
  ASSERT_GE(baseline.objects().objects_size(), 1);
  const std::string baseline_bytes = baseline.objects().SerializeAsString();

  // After each bad client: a fresh client is served and sees the very same objects.
  auto expect_unchanged = [&](const std::string& what) {
    SCOPED_TRACE(what);
    ASSERT_TRUE(daemon_.running()) << daemon_.log();
    Client probe = daemon_.connect();
    EXPECT_EQ(call(probe, health()).status().code(), proto::Status::OK);
    const auto objects = call(probe, get_objects());
    EXPECT_EQ(objects.objects().SerializeAsString(), baseline_bytes);
  };
  // The server closed the connection after its error reply.
  auto expect_closed = [](Client& client) {
    auto next = client.receive(kCallTimeoutS);
    ASSERT_FALSE(next.ok());
    EXPECT_NE(next.error().message.find("closed"), std::string::npos) << next.error().message;
  };

  {  // A truncated PCD read by the server: the error names the file and the problem.
    std::ifstream in(data_dir() / kMug, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(data_root_ / "truncated.pcd", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    Client client = daemon_.connect();
    const auto response = call(client, ingest_file(data_root_ / "truncated.pcd"));
    EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT);
    EXPECT_NE(response.status().message().find("truncated.pcd"), std::string::npos) << response.status().message();
    EXPECT_NE(response.status().message().find("truncated"), std::string::npos) << response.status().message();
    expect_unchanged("truncated PCD");
  }
  {  // Garbage inside a well-formed frame: an error reply, and the connection stays usable.
    Client client = daemon_.connect();
    ASSERT_TRUE(client.send_raw(service::encode_frame(std::string("\xff\xfe garbage \x01\x02", 13))).ok());
    auto reply = client.receive(kCallTimeoutS);
    ASSERT_TRUE(reply.ok()) << reply.error().message;
    EXPECT_EQ(reply->id(), 0u);
    EXPECT_EQ(reply->status().code(), proto::Status::INVALID_ARGUMENT);
    EXPECT_EQ(call(client, health()).status().code(), proto::Status::OK);
    expect_unchanged("garbage payload");
  }
  {  // Bad clouds and poses over the wire.
    Client client = daemon_.connect();
    proto::Request bad_size = ingest_mug();
    bad_size.mutable_ingest_frame()->mutable_cloud()->mutable_xyz()->resize(1000);
    auto response = call(client, bad_size);
    EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT);
    EXPECT_NE(response.status().message().find("cloud.xyz"), std::string::npos) << response.status().message();
    proto::Request nan_pose = ingest_mug();
    auto* pose = nan_pose.mutable_ingest_frame()->mutable_pose();
    for (int i = 0; i < 16; ++i) pose->add_matrix(i % 5 == 0 ? 1.0 : 0.0);
    pose->set_matrix(3, std::nan(""));
    response = call(client, nan_pose);
    EXPECT_EQ(response.status().code(), proto::Status::INVALID_ARGUMENT);
    EXPECT_NE(response.status().message().find("pose"), std::string::npos) << response.status().message();
    expect_unchanged("bad cloud and pose");
  }
  {  // An empty call: UNKNOWN_REQUEST with the request's id; the connection stays open.
    Client client = daemon_.connect();
    proto::Request empty;
    empty.set_id(77);
    ASSERT_TRUE(client.send(empty).ok());
    auto reply = client.receive(kCallTimeoutS);
    ASSERT_TRUE(reply.ok()) << reply.error().message;
    EXPECT_EQ(reply->id(), 77u);
    EXPECT_EQ(reply->status().code(), proto::Status::UNKNOWN_REQUEST);
    EXPECT_EQ(call(client, health()).status().code(), proto::Status::OK);
    expect_unchanged("unknown request");
  }
  {  // A length prefix above the maximum: an error naming both numbers, then the server closes.
    Client client = daemon_.connect();
    ASSERT_TRUE(client.send_raw(std::string("\x7f\xff\xff\xff", 4)).ok());
    auto reply = client.receive(kCallTimeoutS);
    ASSERT_TRUE(reply.ok()) << reply.error().message;
    EXPECT_EQ(reply->status().code(), proto::Status::INVALID_ARGUMENT);
    EXPECT_NE(reply->status().message().find("2147483647"), std::string::npos) << reply->status().message();
    EXPECT_NE(reply->status().message().find("67108864"), std::string::npos) << reply->status().message();
    expect_closed(client);
    expect_unchanged("oversized length");
  }
  {  // Bytes that are not our protocol at all (their first 4 bytes read as a huge length).
    Client client = daemon_.connect();
    ASSERT_TRUE(client.send_raw("GET / HTTP/1.1\r\nHost: localhost\r\n\r\n").ok());
    auto reply = client.receive(kCallTimeoutS);
    ASSERT_TRUE(reply.ok()) << reply.error().message;
    EXPECT_EQ(reply->status().code(), proto::Status::INVALID_ARGUMENT);
    expect_closed(client);
    expect_unchanged("raw garbage");
  }
  {  // A zero length.
    Client client = daemon_.connect();
    ASSERT_TRUE(client.send_raw(std::string(4, '\0')).ok());
    auto reply = client.receive(kCallTimeoutS);
    ASSERT_TRUE(reply.ok()) << reply.error().message;
    EXPECT_EQ(reply->status().code(), proto::Status::INVALID_ARGUMENT);
    expect_closed(client);
    expect_unchanged("zero length");
  }
  {  // A client that disconnects in the middle of a frame.
    Client client = daemon_.connect();
    ASSERT_TRUE(client.send_raw(std::string("\x00\x00\x03\xe8", 4) + std::string(10, 'x')).ok());
    client.close();
    expect_unchanged("disconnect mid-frame");
  }
  {  // A client that stalls in the middle of a frame: the read timeout closes it.
    Client client = daemon_.connect();
    ASSERT_TRUE(client.send_raw(std::string("\x00\x00\x03\xe8", 4) + std::string(10, 'x')).ok());
    auto reply = client.receive(kCallTimeoutS);
    ASSERT_TRUE(reply.ok()) << reply.error().message;
    EXPECT_EQ(reply->status().code(), proto::Status::UNAVAILABLE);
    EXPECT_NE(reply->status().message().find("read timeout"), std::string::npos) << reply->status().message();
    expect_closed(client);
    expect_unchanged("stalled mid-frame");
  }
  {  // A client that drips a byte of its frame every 0.2 s: no single stall reaches the read
     // timeout (0.3 s), the frame deadline (1 s) closes it all the same.
    Client client = daemon_.connect();
    ASSERT_TRUE(client.send_raw(std::string("\x00\x00\x03\xe8", 4)).ok());
    const auto started = std::chrono::steady_clock::now();
    Result<proto::Response> reply = invalid_argument("no reply yet");
    for (int i = 0; i < 25 && !reply.ok(); ++i) {
      reply = client.receive(0.2);  // waits up to 0.2 s for the daemon's answer
      if (!reply.ok()) ASSERT_TRUE(client.send_raw("x").ok());
    }
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    ASSERT_TRUE(reply.ok()) << "no answer while dripping for 5 s: " << reply.error().message;
    EXPECT_EQ(reply->status().code(), proto::Status::UNAVAILABLE);
    EXPECT_NE(reply->status().message().find("frame timeout"), std::string::npos) << reply->status().message();
    EXPECT_LT(elapsed, 2.0) << "the deadline is 1 s after the first byte";
    expect_closed(client);
    expect_unchanged("dripping a frame");
  }
  EXPECT_TRUE(daemon_.running());
  EXPECT_EQ(daemon_.terminate(), std::optional<int>(0));
  const std::string log = daemon_.log();
  EXPECT_NE(log.find("connected"), std::string::npos);
  EXPECT_NE(log.find("read timeout"), std::string::npos);
  EXPECT_NE(log.find("frame timeout"), std::string::npos);
}

TEST_F(DaemonTest, ManyClientsAreServedWhileFramesAreProcessed) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml()));
  const proto::Request mug = ingest_mug();
  std::atomic<int> failures{0};
  std::thread ingester([&] {
    auto client = Client::connect("127.0.0.1", daemon_.port(), 10.0);
    if (!client.ok()) {
      ++failures;
      return;
    }
    client->set_token(daemon_.token());
    for (int i = 0; i < 3; ++i) {
      auto r = client->call(mug, kCallTimeoutS);
      if (!r.ok() || r->status().code() != proto::Status::OK) ++failures;
    }
  });
  std::vector<std::thread> readers;
  for (int t = 0; t < 8; ++t) {
    readers.emplace_back([&] {
      auto client = Client::connect("127.0.0.1", daemon_.port(), 10.0);
      if (!client.ok()) {
        ++failures;
        return;
      }
      for (int i = 0; i < 20; ++i) {
        for (const auto& req : {health(), get_objects(), get_planes()}) {
          auto r = client->call(req, kCallTimeoutS);
          if (!r.ok() || r->status().code() != proto::Status::OK) ++failures;
        }
      }
    });
  }
  ingester.join();
  for (auto& t : readers) t.join();
  EXPECT_EQ(failures.load(), 0);
  Client client = daemon_.connect();
  EXPECT_EQ(call(client, health()).health().frames_processed(), 3u);
}

// Idle clients cannot lock the others out: at the limit, the connection quiet for longest makes
// room. Subscribers wait for events by design and are never made to; when every connection is a
// subscriber (or busy), a newcomer is turned away.
TEST_F(DaemonTest, AtTheConnectionLimitTheQuietestMakesRoom) {
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml("  max_connections: 2\n")));
  Client first = daemon_.connect();
  ASSERT_EQ(call(first, health()).status().code(), proto::Status::OK);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // first is the quieter
  Client second = daemon_.connect();
  ASSERT_EQ(call(second, health()).status().code(), proto::Status::OK);
  Client third = daemon_.connect();
  auto served = third.call(health(), kCallTimeoutS);
  ASSERT_TRUE(served.ok()) << served.error().message;
  EXPECT_EQ(served->status().code(), proto::Status::OK) << "the newcomer is served";
  auto evicted = first.receive(kCallTimeoutS);
  ASSERT_TRUE(evicted.ok()) << evicted.error().message;
  EXPECT_EQ(evicted->status().code(), proto::Status::UNAVAILABLE);
  EXPECT_NE(evicted->status().message().find("make room"), std::string::npos) << evicted->status().message();
  auto next = first.receive(kCallTimeoutS);
  EXPECT_FALSE(next.ok()) << "the quietest connection is closed after its error reply";
  EXPECT_EQ(call(second, health()).status().code(), proto::Status::OK) << "the other one is untouched";
  second.close();
  third.close();

  // Two subscribers hold both slots: a third client is turned away, and they keep their events.
  auto subscribe = [] { return request([](proto::Request& r) { r.mutable_subscribe(); }); };
  std::vector<Client> subscribers;
  for (int attempt = 0; attempt < 200 && subscribers.size() < 2; ++attempt) {
    Client c = daemon_.connect();
    auto r = c.call(subscribe(), kCallTimeoutS);
    if (r.ok() && r->status().code() == proto::Status::OK) {
      subscribers.push_back(std::move(c));
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the closes above not yet seen
    }
  }
  ASSERT_EQ(subscribers.size(), 2u);
  // Connections closed above may still hold a slot until the daemon has seen them go (one of them
  // would then be evicted to make room, and nobody turned away): wait until only the two remain.
  std::uint32_t connected = 0;
  for (int attempt = 0; attempt < 200; ++attempt) {
    connected = call(subscribers.front(), request([](proto::Request& r) { r.mutable_stats(); })).stats().connections();
    if (connected == 2) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(connected, 2u);
  Client turned_away = daemon_.connect();
  auto reply = turned_away.receive(kCallTimeoutS);
  ASSERT_TRUE(reply.ok()) << reply.error().message;
  EXPECT_EQ(reply->status().code(), proto::Status::UNAVAILABLE);
  EXPECT_NE(reply->status().message().find("too many connections"), std::string::npos) << reply->status().message();
  for (auto& s : subscribers) EXPECT_EQ(call(s, health()).status().code(), proto::Status::OK);
}

// Unfinished frames are held within one budget for all clients: several clients each holding
// most of a large frame cannot fill the memory. The one that goes over is closed; the others and
// new clients are served.
TEST_F(DaemonTest, UnfinishedFramesShareOneMemoryBudget) {
  ASSERT_NO_FATAL_FAILURE(
      daemon_.start(tmp_, server_yaml("  max_message_bytes: 1000000\n  max_buffered_bytes: 1500000\n")));
  const std::string header("\x00\x0f\x42\x40", 4);  // 1,000,000 bytes follow
  std::vector<Client> holders;
  holders.push_back(daemon_.connect());
  ASSERT_TRUE(holders[0].send_raw(header + std::string(800000, 'x')).ok());
  holders.push_back(daemon_.connect());
  ASSERT_TRUE(holders[1].send_raw(header + std::string(800000, 'y')).ok());
  // Whichever the daemon read second goes over the budget (usually the second client).
  int refused = -1;
  for (int attempt = 0; attempt < 20 && refused < 0; ++attempt) {
    for (int i = 0; i < 2 && refused < 0; ++i) {
      auto reply = holders[i].receive(0.25);
      if (!reply.ok()) continue;
      EXPECT_EQ(reply->status().code(), proto::Status::UNAVAILABLE);
      EXPECT_NE(reply->status().message().find("server.max_buffered_bytes"), std::string::npos) << reply->status().message();
      refused = i;
    }
  }
  ASSERT_GE(refused, 0) << "one of the two must be refused";
  Client probe = daemon_.connect();
  EXPECT_EQ(call(probe, health()).status().code(), proto::Status::OK) << "new clients are served";
  holders[1 - refused].close();  // its share is given back: a large frame fits again
  // (retried while the daemon has not yet seen the close)
  Result<proto::Response> parsed = invalid_argument("not tried");
  for (int attempt = 0; attempt < 50; ++attempt) {
    Client third = daemon_.connect();
    ASSERT_TRUE(third.send_raw(header + std::string(1000000, 'z')).ok());
    parsed = third.receive(kCallTimeoutS);
    if (parsed.ok() && parsed->status().code() != proto::Status::UNAVAILABLE) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  EXPECT_EQ(parsed->status().code(), proto::Status::INVALID_ARGUMENT) << "read whole, then refused as no request: "
                                                                       << parsed->status().message();
}

// Who may change the model: only a client holding the token of the daemon's token file. Any
// other local client may read, but its Reset, SaveModel, IngestFile, IngestFrame, ClearBox and
// LoadModel are refused and change nothing, neither in memory nor on disk.
TEST_F(DaemonTest, OnlyTheTokenHolderChangesTheModel) {
  SCENEWATCH_REQUIRE_DATA(kMug);
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml()));
  struct stat st {};
  ASSERT_EQ(::stat(daemon_.token_file().c_str(), &st), 0) << daemon_.token_file();
  EXPECT_EQ(st.st_mode & 07777, 0600u) << "the token file is readable by the daemon's user only";
  EXPECT_EQ(daemon_.token().size(), 64u);
  EXPECT_NE(daemon_.log().find(daemon_.token_file().string()), std::string::npos) << "the log says where it is";
  EXPECT_EQ(daemon_.log().find(daemon_.token()), std::string::npos) << "the log never shows the token";

  Client owner = daemon_.connect();
  ASSERT_EQ(call(owner, ingest_mug()).status().code(), proto::Status::OK);
  ASSERT_EQ(call(owner, request([](proto::Request& r) { r.mutable_save_model(); })).status().code(), proto::Status::OK);
  const auto objects_before = call(owner, get_objects());
  ASSERT_EQ(objects_before.objects().frames_processed(), 1u);
  const fs::path saved_before = fs::read_symlink(model_dir_ / "current");

  Client stranger = daemon_.connect_without_token();
  EXPECT_EQ(call(stranger, health()).status().code(), proto::Status::OK) << "reading stays open";
  EXPECT_EQ(call(stranger, get_objects()).objects().objects_size(), objects_before.objects().objects_size());
  const std::vector<proto::Request> changes = {
      request([](proto::Request& r) { r.mutable_reset(); }),
      request([](proto::Request& r) { r.mutable_save_model(); }),
      request([](proto::Request& r) { r.mutable_load_model(); }),
      ingest_file(data_dir() / kMug),
      ingest_mug(),
      request([](proto::Request& r) {
        auto* box = r.mutable_clear_box()->mutable_box();
        box->mutable_min()->set_x(-10), box->mutable_min()->set_y(-10), box->mutable_min()->set_z(-10);
        box->mutable_max()->set_x(10), box->mutable_max()->set_y(10), box->mutable_max()->set_z(10);
      })};
  for (const std::string& token : {std::string(), std::string(64, 'a'), daemon_.token().substr(0, 63)}) {
    for (proto::Request change : changes) {
      change.set_token(token);
      const auto refused = call(stranger, change);
      EXPECT_EQ(refused.status().code(), proto::Status::PERMISSION_DENIED) << change.call_case();
      EXPECT_NE(refused.status().message().find("needs the daemon's token"), std::string::npos)
          << refused.status().message();
    }
  }
  const auto objects_after = call(stranger, get_objects());
  EXPECT_EQ(objects_after.objects().frames_processed(), 1u) << "the model is unchanged";
  EXPECT_EQ(objects_after.objects().SerializeAsString(), objects_before.objects().SerializeAsString());
  EXPECT_EQ(fs::read_symlink(model_dir_ / "current"), saved_before) << "nothing was saved";

  // The token holder's Reset forgets the frame.
  ASSERT_EQ(call(owner, request([](proto::Request& r) { r.mutable_reset(); })).status().code(), proto::Status::OK);
  EXPECT_EQ(call(stranger, health()).health().frames_processed(), 0u);
  ASSERT_EQ(daemon_.terminate(), std::optional<int>(0));

  // A token file others may read is refused at start (the daemon does not quietly use it).
  const fs::path open_token = tmp_ / "open-token";
  std::ofstream(open_token) << "0123456789abcdef0123456789abcdef\n";
  fs::permissions(open_token, fs::perms::owner_read | fs::perms::owner_write | fs::perms::others_read,
                  fs::perm_options::replace);
  const auto refused = run_command(
      {daemon_binary().string(), "--port", "0", "--token-file", open_token.string(), "--model-dir", ""}, tmp_);
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find("chmod 600"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find(open_token.string()), std::string::npos) << refused.err;
}

// Homing after a restart (issue 29 item 4) through the real daemon: a model of the kitchen's
// files 0-248 saved, scenewatchd started on it in refine mode, files 250-... streamed over TCP
// with their poses in another odometry frame (35 degrees about z, 1.4 m). GetLocalization then
// reports the camera homed with T_world_odom the inverse of that offset; an unknown camera is NOT_FOUND.
TEST_F(DaemonTest, GetLocalizationReportsTheHomedCameraAfterARestart) {
  SCENEWATCH_REQUIRE_DATA("redkitchen_long");
  auto seq = io::open_sequence(data_dir() / "redkitchen_long");
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  const std::size_t half = seq->frames.size() / 2;
  {
    pipeline::WorkingMemory model(pipeline::Config{});
    for (std::size_t i = 0; i < half; ++i) ASSERT_TRUE(model.process(*io::load_sequence_frame(*seq, i)).ok());
    ASSERT_TRUE(model.save(model_dir_).ok());
  }
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml("localization:\n  mode: refine\n")));
  Client client = daemon_.connect();
  const auto where = [&](const std::string& camera) {
    return call(client, request([&](proto::Request& r) { r.mutable_get_localization()->set_camera(camera); }));
  };
  EXPECT_EQ(where("kitchen").status().code(), proto::Status::NOT_FOUND) << "no frame yet";
  Pose offset = Pose::Identity();
  offset.linear() = Eigen::AngleAxisd(35.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  offset.translation() = Eigen::Vector3d(1.4, 0.0, 0.0);
  std::optional<std::size_t> homed_at;
  const std::size_t streamed = 10;
  for (std::size_t i = half; i < half + streamed; ++i) {
    auto frame = io::load_sequence_frame(*seq, i);
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    frame->T_world_camera = offset * *frame->T_world_camera;
    frame->camera = "kitchen";
    proto::Request r;
    *r.mutable_ingest_frame() = service::make_ingest_frame(*frame);
    const auto reply = call(client, r);
    ASSERT_EQ(reply.status().code(), proto::Status::OK) << reply.status().message();
    if (!homed_at && reply.ingest().localization().state() == "tracking") homed_at = i - half;
  }
  ASSERT_TRUE(homed_at.has_value()) << "not homed within " << streamed << " frames";
  const auto reply = where("kitchen");
  ASSERT_EQ(reply.status().code(), proto::Status::OK) << reply.status().message();
  ASSERT_EQ(reply.localization().cameras_size(), 1);
  const auto& cam = reply.localization().cameras(0);
  EXPECT_EQ(cam.camera(), "kitchen");
  EXPECT_EQ(cam.state(), "tracking") << cam.reason();
  EXPECT_TRUE(cam.homed());
  ASSERT_EQ(cam.t_world_odom().matrix_size(), 16);
  Eigen::Matrix4d m;
  for (int k = 0; k < 16; ++k) m(k / 4, k % 4) = cam.t_world_odom().matrix(k);
  const auto odom_error = background::view_distance(pose_from_matrix(m), offset.inverse());
  std::cout << "daemon homing: tracking from frame " << *homed_at << ", T_world_odom off by " << 1000 * odom_error.translation_m
            << " mm " << odom_error.rotation_deg << " deg\n";
  EXPECT_LT(odom_error.translation_m, 0.05);
  EXPECT_LT(odom_error.rotation_deg, 5.0);
  // Every camera, and a camera the daemon never heard of: an error naming it.
  const auto all = call(client, request([](proto::Request& r) { r.mutable_get_localization(); }));
  ASSERT_EQ(all.status().code(), proto::Status::OK);
  EXPECT_EQ(all.localization().cameras_size(), 1);
  const auto unknown = where("nope");
  EXPECT_EQ(unknown.status().code(), proto::Status::NOT_FOUND);
  EXPECT_NE(unknown.status().message().find("nope"), std::string::npos) << unknown.status().message();
}

// Issue 29: a change of a camera's localization state is pushed to subscribers. A camera streams
// the real kitchen in refine mode; one frame comes with its pose 1 m off, which the alignment
// cannot accept (lost), and the next frames are right again (tracking). The subscriber is told
// each change the ingest replies show, in order, and nothing else.
TEST_F(DaemonTest, LocalizationChangesArePushedToSubscribers) {
  SCENEWATCH_REQUIRE_DATA("redkitchen_long");
  auto seq = io::open_sequence(data_dir() / "redkitchen_long");
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml("localization:\n  mode: refine\n")));
  Client client = daemon_.connect();
  Client subscriber = daemon_.connect();
  ASSERT_EQ(call(subscriber, request([](proto::Request& r) { r.mutable_subscribe(); })).status().code(), proto::Status::OK);
  const std::size_t off_frame = 4;
  std::vector<std::pair<std::string, bool>> seen;  // state and homing, as each reply says
  std::vector<std::pair<std::string, bool>> changes;
  for (std::size_t i = 0; i < 7; ++i) {
    auto frame = io::load_sequence_frame(*seq, i);
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    if (i == off_frame) frame->T_world_camera->translation() += Eigen::Vector3d(1.0, 0.0, 0.0);
    frame->camera = "kitchen";
    proto::Request r;
    *r.mutable_ingest_frame() = service::make_ingest_frame(*frame);
    const auto reply = call(client, r);
    ASSERT_EQ(reply.status().code(), proto::Status::OK) << reply.status().message();
    const auto& where = reply.ingest().localization();
    const std::pair<std::string, bool> now{where.state(), where.homed()};
    if (seen.empty() || seen.back() != now) changes.push_back(now);
    seen.push_back(now);
  }
  ASSERT_EQ(seen[off_frame].first, "lost") << "the frame 1 m off must be lost";
  ASSERT_EQ(seen.back().first, "tracking");
  for (std::size_t k = 0; k < changes.size(); ++k) {
    auto pushed = subscriber.next_pushed(kCallTimeoutS);
    ASSERT_TRUE(pushed.ok()) << "change " << k << " (" << changes[k].first << ") not pushed: " << pushed.error().message;
    ASSERT_EQ(pushed->id(), 0u);
    ASSERT_EQ(pushed->localization().cameras_size(), 1);
    const auto& camera = pushed->localization().cameras(0);
    EXPECT_EQ(camera.camera(), "kitchen");
    EXPECT_EQ(camera.state(), changes[k].first) << "change " << k;
    EXPECT_EQ(camera.homed(), changes[k].second) << "change " << k;
    if (camera.state() == "lost") EXPECT_FALSE(camera.reason().empty());
  }
  std::cout << "localization notices: " << changes.size() << " changes in 7 frames\n";
  EXPECT_FALSE(subscriber.next_pushed(0.5).ok()) << "nothing more than the changes";
}

TEST_F(DaemonTest, StartsEmptyWithoutAModelAndRefusesABadConfig) {
  ASSERT_NO_FATAL_FAILURE(daemon_.start(tmp_, server_yaml()));
  Client client = daemon_.connect();
  EXPECT_EQ(call(client, get_objects()).objects().objects_size(), 0);
  EXPECT_NE(daemon_.log().find("starting empty"), std::string::npos) << daemon_.log();
  ASSERT_EQ(daemon_.terminate(), std::optional<int>(0));

  const fs::path bad = tmp_ / "bad.yaml";
  std::ofstream(bad) << "server:\n  prot: 7878\n";
  const auto result = run_command({daemon_binary().string(), "--config", bad.string()}, tmp_);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.err.find("server.prot"), std::string::npos) << result.err;
  EXPECT_EQ(run_command({daemon_binary().string(), "--help"}, tmp_).exit_code, 0);
  EXPECT_EQ(run_command({daemon_binary().string(), "--port", "x"}, tmp_).exit_code, 2);
}

}  // namespace
}  // namespace scenewatch::test
