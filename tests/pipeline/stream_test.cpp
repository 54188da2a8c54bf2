// The event stream as a planner receives it: sequences through the working memory, every event of
// every kind counted. Unchanged scenes must stay calm (real ones included); a change must be told
// once, promptly, at the right place, and nothing else.
//
// Simulator scenarios are rendered frame by frame with their reported poses. An event is right
// when its kind matches the truth and its centroid lies within 10 cm (in the table plane) of where
// the object was put (added, moved) or stood (removed). Transparent objects have no depth: their
// removal is right as an APPEARANCE_CHANGE.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scenewatch/io/sequence.h"
#include "scenewatch/localization/pose_error.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::pipeline {
namespace {

struct StreamEvent {
  Event event;
  std::size_t phase = 0;
  int frame = 0;  ///< within its phase
};

struct SequenceRun {
  std::vector<StreamEvent> events;
  std::vector<sim::ChangeTruth> truth;
  std::size_t frames = 0;
  /// With hidden poses: each placed frame's pose in the memory's world, and its true pose.
  std::vector<Pose> placed, truths;
  double rmse_m() const { return localization::trajectory_rmse_m(placed, truths); }
};

void print_event(const std::string& name, const StreamEvent& s) {
  const Event& e = s.event;
  std::printf("  %s phase %zu frame %d: %s score %.3f at (%.3f, %.3f, %.3f) %s\n", name.c_str(), s.phase, s.frame,
              to_string(e.kind), e.score, e.centroid_world.x(), e.centroid_world.y(), e.centroid_world.z(), e.detail.c_str());
}

struct RunOptions {
  LocalizationMode mode = LocalizationMode::kGiven;
  /// The simulated sensor reports each frame's pose with this much noise (metres, degrees; 1
  /// sigma, independent per frame), as odometry or an arm's kinematics would.
  std::pair<double, double> pose_noise = {0, 0};
  /// Each phase's frames come from a camera of their own (one camera joins after each change), as
  /// two `scenewatch ingest` runs without --camera send them.
  bool camera_per_phase = false;
  /// localization.noise_m / noise_deg set to the pose noise.
  bool noise_configured = false;
  /// Frames come without a pose (`track` mode): the memory's world is then its first camera's
  /// frame, and no up direction is known. Events are brought into the scenario's world by the
  /// first frame's true pose, and every placed frame's pose is scored against the truth.
  bool hide_poses = false;
};

SequenceRun run_scenario(const std::string& name, int frames, int width, int height, const RunOptions& options = {}) {
  const auto [mode, pose_noise, camera_per_phase, noise_configured, hide_poses] = options;
  SequenceRun run;
  auto loaded = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios" / (name + ".yaml"));
  EXPECT_TRUE(loaded.ok());
  if (!loaded.ok()) return run;
  sim::Scenario scenario = sim::with_frames(sim::with_resolution(*loaded, width, height), frames);
  scenario.sensor.pose_sigma_m = pose_noise.first;
  scenario.sensor.pose_sigma_deg = pose_noise.second;
  auto simulator = sim::Simulator::create(scenario);
  EXPECT_TRUE(simulator.ok());
  if (!simulator.ok()) return run;
  run.truth = simulator->changes();
  Config config;
  if (!hide_poses) config.segmentation.up = Eigen::Vector3d::UnitZ();
  config.localization.mode = mode;
  if (noise_configured) {
    config.localization.noise_m = pose_noise.first;
    config.localization.noise_deg = pose_noise.second;
  }
  WorkingMemory memory(config);
  Pose T_world_memory = Pose::Identity();  // the memory's world in the scenario's, by the first frame
  double stamp = 0;
  for (std::size_t phase = 0; phase < simulator->phase_count(); ++phase) {
    for (int f = 0; f < simulator->frame_count(phase); ++f) {
      auto frame = sim::as_frame(simulator->render(phase, f), scenario.intrinsics, stamp += 1.0 / 30);
      EXPECT_TRUE(frame.ok());
      if (!frame.ok()) return run;
      if (camera_per_phase) frame->camera = "camera" + std::to_string(phase);
      const Pose truth = frame->pose_or_identity();
      if (hide_poses) frame->T_world_camera.reset();
      auto result = memory.process(*frame);
      EXPECT_TRUE(result.ok());
      if (!result.ok()) return run;
      const localization::Localization& where = result->localization;
      if (run.frames++ == 0 && hide_poses) T_world_memory = truth * where.T_world_camera.inverse();
      if (hide_poses && where.placed()) {
        run.placed.push_back(where.T_world_camera);
        run.truths.push_back(truth);
      }
      for (const auto& e : result->events) {
        run.events.push_back({e, phase, f});
        if (hide_poses) run.events.back().event.centroid_world = T_world_memory * e.centroid_world;
        print_event(name, run.events.back());
      }
    }
  }
  return run;
}

struct Score {
  std::size_t events = 0, right = 0, truths = 0, found = 0;
  int worst_delay = 0;  ///< frames after the change became visible (phase start), over found changes
};

Score score(const SequenceRun& run) {
  struct Want {
    EventKind kind;
    Eigen::Vector2d xy;
    std::size_t phase;
  };
  std::vector<Want> wants;
  for (std::size_t p = 0; p < run.truth.size(); ++p) {
    const auto& c = run.truth[p];
    const std::size_t phase = p + 1;  // changes happen between phase p and p + 1
    for (const auto& o : c.added) wants.push_back({EventKind::kObjectAdded, o.T_world_object.translation().head<2>(), phase});
    // A transparent object has no depth: its removal is told by the space it left dark being seen
    // through (change/dark_space.h), an OBJECT_REMOVED as any other.
    for (const auto& o : c.removed) wants.push_back({EventKind::kObjectRemoved, o.T_world_object.translation().head<2>(), phase});
    for (const auto& m : c.moved) wants.push_back({EventKind::kObjectMoved, m.T_world_after.translation().head<2>(), phase});
  }
  Score s;
  s.events = run.events.size();
  s.truths = wants.size();
  std::vector<char> found(wants.size(), 0);
  for (const auto& se : run.events) {
    bool right = false;
    for (std::size_t i = 0; i < wants.size(); ++i) {
      if (wants[i].kind != se.event.kind || wants[i].phase != se.phase ||
          (se.event.centroid_world.head<2>() - wants[i].xy).norm() > 0.10 || found[i]) {
        continue;  // a second event for a change already told is not right
      }
      right = true;
      found[i] = 1;
      s.worst_delay = std::max(s.worst_delay, se.frame);
      break;
    }
    s.right += right ? 1 : 0;
  }
  for (char f : found) s.found += f;
  return s;
}

void print(const std::string& name, const Score& s, const SequenceRun& run) {
  std::printf("%-16s %zu frames: events %zu (%.1f per 100 frames), right %zu | truth %zu found %zu | worst delay %d frames\n",
              name.c_str(), run.frames, s.events, run.frames ? 100.0 * s.events / run.frames : 0.0, s.right, s.truths,
              s.found, s.worst_delay);
}

TEST(Stream, EachChangeIsOneEventAtTheRightPlaceWithinFiveFrames) {
  for (const char* name : {"cup_added", "object_moved"}) {
    const SequenceRun run = run_scenario(name, 12, 320, 240);
    const Score s = score(run);
    print(name, s, run);
    EXPECT_EQ(s.truths, 1u) << name;
    EXPECT_EQ(s.found, s.truths) << name << ": the change was told";
    EXPECT_EQ(s.events, s.truths) << name << ": one fact, one event, and nothing else";
    EXPECT_LE(s.worst_delay, 5) << name;
  }
}

TEST(Stream, RemovedGlassesAreToldWhereTheirDarkSpaceIsSeenThrough) {
  // The seed's experiment: two clear glasses (holes in every depth image, a faint tint in colour)
  // are removed between two circles around a set table. Their space, dark from every side of the
  // first circle, is seen through on the second: one OBJECT_REMOVED each, at the glass.
  const SequenceRun run = run_scenario("glasses_removed", 71, 320, 240);
  const Score s = score(run);
  print("glasses_removed", s, run);
  EXPECT_EQ(s.truths, 2u);
  EXPECT_EQ(s.found, 2u);
  EXPECT_EQ(s.events, s.right) << "every event is one of the two removals";
  EXPECT_LE(s.worst_delay, 5);
}

TEST(Stream, ACameraThatJoinsAfterTheChangeTellsItAsTheFirstWould) {
  // The frames after the change come from a camera that has not seen the scene before. It sees the
  // cup in front of a table only the first camera saw; that table is hidden, not displaced (two
  // cameras' versions of a surface lie within their tolerances of each other), so the cup is an
  // addition, not only an appearance change (as it was before the displacement was bounded). A
  // moved object is told as an addition where it went: its old spot is a surface only the first
  // camera saw, and a camera claims removals only of surfaces it saw itself (seen through by
  // another camera, a surface is as often a reflection or a hole: 4 more false removals in the two
  // kitchen cameras below when the new camera could claim them beyond the same bound).
  for (const char* name : {"cup_added"}) {
    RunOptions joined_after_change;
    joined_after_change.camera_per_phase = true;
    const SequenceRun run = run_scenario(name, 12, 320, 240, joined_after_change);
    const Score s = score(run);
    print(std::string(name) + ", a new camera after the change", s, run);
    EXPECT_EQ(s.found, s.truths) << name;
    EXPECT_EQ(s.events, s.truths) << name;
  }
}

// Issue 29's simulator check: poses reported with 5 mm / 0.25 degrees of noise per frame.
TEST(Stream, PoseNoiseOfFiveMillimetres) {
  for (const LocalizationMode mode : {LocalizationMode::kGiven, LocalizationMode::kRefine}) {
    RunOptions noisy;
    noisy.mode = mode;
    noisy.pose_noise = {0.005, 0.25};
    for (const char* name : {"cup_added", "object_moved"}) {
      const SequenceRun run = run_scenario(name, 12, 320, 240, noisy);
      const Score s = score(run);
      print(std::string(name) + " with pose noise, " + localization::mode_name(mode), s, run);
      EXPECT_EQ(s.found, s.truths) << name << " " << localization::mode_name(mode);
      EXPECT_EQ(s.events, s.truths) << name << " " << localization::mode_name(mode);
    }
    const SequenceRun calm = run_scenario("clutter", 90, 320, 240, noisy);
    print(std::string("clutter with pose noise, ") + localization::mode_name(mode), score(calm), calm);
    EXPECT_TRUE(calm.events.empty()) << localization::mode_name(mode);
  }
}

// The same at full length and resolution (object_moved: 120 frames at 640x480), where the given
// poses alone raise false APPEARANCE_CHANGEs (5 measured with scenewatch replay); `refine` told
// the pose source's noise (localization.noise_m, noise_deg) tells the move and nothing else.
TEST(Stream, PoseNoiseOfFiveMillimetresAtFullLengthWithTheNoiseConfigured) {
  RunOptions told;
  told.mode = LocalizationMode::kRefine;
  told.pose_noise = {0.005, 0.25};
  told.noise_configured = true;
  const SequenceRun run = run_scenario("object_moved", 60, 640, 480, told);
  const Score s = score(run);
  print("object_moved with pose noise, refine told it, 640x480", s, run);
  EXPECT_EQ(s.found, s.truths);
  EXPECT_EQ(s.events, s.truths);
  EXPECT_LE(s.worst_delay, 5);
}

// Issue 29's `track` row against exact truth: no poses at all, from an empty memory. The kitchen's
// poses are a reconstruction's (localization.md); the simulator's are exact.
TEST(Stream, TrackModeWithoutPosesFollowsTheSimulatorsTruth) {
  RunOptions track;
  track.mode = LocalizationMode::kTrack;
  track.hide_poses = true;
  struct Case {
    const char* name;
    int frames;
    double max_rmse_m;
  };
  // Measured (full length, 640x480): cup_added 2.6 mm RMS over 0.68 m of path, object_moved
  // 11.1 mm over 2.85 m, clutter 24.1 mm over 3.46 m; each change one event, clutter none.
  for (const Case& c : {Case{"cup_added", 40, 0.0035}, Case{"object_moved", 60, 0.013}, Case{"clutter", 90, 0.027}}) {
    const SequenceRun run = run_scenario(c.name, c.frames, 640, 480, track);
    const Score s = score(run);
    print(std::string(c.name) + " tracked without poses", s, run);
    std::printf("  trajectory: RMSE %.1f mm over %zu placed frames of %zu\n", 1000 * run.rmse_m(), run.placed.size(),
                run.frames);
    EXPECT_EQ(run.placed.size(), run.frames) << c.name << ": no frame lost";
    EXPECT_LT(run.rmse_m(), c.max_rmse_m) << c.name;
    EXPECT_EQ(s.found, s.truths) << c.name;
    EXPECT_EQ(s.events, s.truths) << c.name << ": as calm as with the poses given";
  }
}

TEST(Stream, StaticClutterSeenByAMovingCameraIsCalm) {
  // clutter: twelve objects close together, many occlusions, a transparent glass, half a circle.
  const SequenceRun run = run_scenario("clutter", 200, 320, 240);
  print("clutter (static)", score(run), run);
  EXPECT_TRUE(run.events.empty());
}

// Real sequences: a posed recording read as the CLI and the daemon read it.
// The frames are played in the order given (indices into the sequence), each from the camera named
// beside it (none: one camera).
// `frames_with_hands`, when given, counts the frames in which the hand detector kept a hand.
std::vector<Event> run_recording(const std::filesystem::path& dir, const std::vector<std::size_t>& order,
                                 const std::vector<std::string>& cameras = {}, std::size_t* frames_with_hands = nullptr) {
  std::vector<Event> events;
  auto seq = io::open_sequence(dir);
  EXPECT_TRUE(seq.ok()) << seq.error().message;
  if (!seq.ok()) return events;
  WorkingMemory memory(Config{});
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    auto frame = io::load_sequence_frame(*seq, i);
    EXPECT_TRUE(frame.ok()) << frame.error().message;
    if (!frame.ok()) return events;
    if (k < cameras.size()) frame->camera = cameras[k];
    auto result = memory.process(*frame);
    EXPECT_TRUE(result.ok()) << result.error().message;
    if (!result.ok()) return events;
    if (frames_with_hands && result->hands > 0) ++*frames_with_hands;
    for (const auto& e : result->events) {
      print_event(dir.filename().string(), StreamEvent{e, 0, static_cast<int>(i)});
      events.push_back(e);
    }
  }
  return events;
}

TEST(Stream, RealKitchenSeenByAHandHeldCameraIsCalm) {
  // 7-Scenes redkitchen, 50 posed frames of an unchanged room: before the calm stream (issue 9)
  // this gave 1386 events (1104 APPEARANCE_CHANGE, 222 OBJECT_APPEARED, 60 OBJECT_GONE).
  SCENEWATCH_REQUIRE_DATA("redkitchen/frame-000150.color.png");
  std::vector<std::size_t> forward;
  for (std::size_t i = 0; i < 50; ++i) forward.push_back(i);
  std::size_t with_hands = 0;
  const auto events = run_recording(test::data_dir() / "redkitchen", forward, {}, &with_hands);
  std::printf("redkitchen: %zu events in 50 frames, hands in %zu frames\n", events.size(), with_hands);
  EXPECT_TRUE(events.empty());
  // Nobody is in this kitchen. The wooden worktop seen first in frames 0-9 was taken for an arm
  // until the map held its surface (10 frames) while the colour was not registered to the depth:
  // its skin-like colour lay on the points of the surfaces beside it (sensor.fit_colour_registration).
  EXPECT_EQ(with_hands, 0u);
}

TEST(Stream, RealKitchenRevisitedIsCalm) {
  // The same 50 frames forth and back: on the way back every view is familiar (its keyframes are
  // 2 to 98 frames old), so image surprise may speak on its own; the room has not changed.
  SCENEWATCH_REQUIRE_DATA("redkitchen/frame-000150.color.png");
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < 50; ++i) order.push_back(i);
  for (std::size_t i = 50; i-- > 0;) order.push_back(i);
  const auto events = run_recording(test::data_dir() / "redkitchen", order);
  std::printf("redkitchen forth and back: %zu events in 100 frames\n", events.size());
  EXPECT_TRUE(events.empty());
}

TEST(Stream, RealKitchenStretchHeldOutFromTuningIsCalm) {
  // redkitchen_long's files 250-498, which no remedy of issue 28 was tuned on (files 0-248 were):
  // 18 false events before the sensor model, 1 after (a sliver at 2.6 m seen through by 8 cm,
  // frame 105), 0 since a gap counts the map surface's noise as well as the frame's.
  SCENEWATCH_REQUIRE_DATA("redkitchen_long/frame-000498.color.jpg");
  std::vector<std::size_t> order;
  for (std::size_t i = 125; i < 250; ++i) order.push_back(i);
  std::size_t with_hands = 0;
  const auto events = run_recording(test::data_dir() / "redkitchen_long", order, {}, &with_hands);
  std::printf("redkitchen_long files 250-498: %zu events in 125 frames, hands in %zu frames\n", events.size(), with_hands);
  EXPECT_TRUE(events.empty());
  // Nobody is in it either: 13 frames with "hands" when a hand's points had to fall in an occupied
  // voxel to count as furniture, 10 since they count within the sensor's axial tolerance along
  // their ray (a wooden cupboard side entering the view, files 410-442, blanked as an arm and so
  // never put in the map), 9 since that tolerance holds the camera's measured misalignment against
  // the map, as the change detector's does; 1 since each frame's colour is registered to its
  // depth (sensor.fit_colour_registration: the wood's colour had lain on other surfaces' points).
  EXPECT_LE(with_hands, 1u);
}

TEST(Stream, TwoCamerasOnOneRoomInterleaved) {
  // Two stretches of the same unchanged kitchen, 300 frames apart in the recording, sent frame by
  // frame in turn as two cameras would: files 0-198 as camera "a", files 300-498 as camera "b".
  // Their given poses disagree by centimetres where they see the same surfaces.
  SCENEWATCH_REQUIRE_DATA("redkitchen_long/frame-000498.color.jpg");
  std::vector<std::size_t> order;
  std::vector<std::string> cameras;
  for (std::size_t i = 0; i < 100; ++i) {
    order.push_back(i);
    cameras.push_back("a");
    order.push_back(150 + i);
    cameras.push_back("b");
  }
  const auto events = run_recording(test::data_dir() / "redkitchen_long", order, cameras);
  std::printf("redkitchen_long two cameras interleaved: %zu events in 200 frames\n", events.size());
  // 3 measured before the noise along the ray counted the incidence (change.incidence_aware), 1
  // since; 2 (1 per 100 frames, the bound) since a surface only the other camera saw stops
  // a claim only as far behind as a displaced version of it could lie (so that a camera joining
  // after a change can tell an addition): an OBJECT_ADDED of 36 points at 2.2 m, 14-20 cm in front
  // of camera b's surface. Other interleavings, not tuned on: files 0-248 with 250-498 either way
  // round, 2 events before and after; files 80-198 with 380-498, 0 before and after. 1 since a
  // gap counts the map surface's noise as well as the frame's: the addition at 2.9 m remains.
  EXPECT_LE(events.size(), 1u);
}

}  // namespace
}  // namespace scenewatch::pipeline
