// Offline: a recording through the working memory, exactly as the daemon would process it, with
// the event stream printed as it arises and a summary that counts it (events per 100 frames) and
// times it (median and p90 per frame, per stage).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "config_file.h"
#include "frame_spec.h"
#include "install_layout.h"
#include "scenewatch/background/appearance.h"
#include "scenewatch/core/event_json.h"
#include "scenewatch/io/image_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/pipeline/working_memory.h"
#include "subcommand.h"

namespace scenewatch::cli {
namespace {

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(q * (v.size() - 1) + 0.5));
  return v[i];
}

// How far the event lies from the camera that saw it (metres): what a false event's cause
// usually hides in (the far end of the range, where depth noise grows with its square).
double range_from_camera(const Frame& frame, const Event& e) {
  return (e.centroid_world - frame.pose_or_identity().translation()).norm();
}

std::string event_line(std::size_t frame, const Event& e, double range_m) {
  char head[320];
  std::snprintf(head, sizeof head, "frame %4zu  %-17s %-14s score %7.3f  at (%.3f, %.3f, %.3f)  %.2f m from the camera", frame,
                to_string(e.kind), to_string(e.level), e.score, e.centroid_world.x(), e.centroid_world.y(), e.centroid_world.z(),
                range_m);
  std::string line = head;
  if (e.region) {
    std::snprintf(head, sizeof head, "  pixels x %d-%d, y %d-%d", e.region->x, e.region->x + e.region->width - 1, e.region->y,
                  e.region->y + e.region->height - 1);
    line += head;
  }
  if (e.object_id) line += "  object " + std::to_string(*e.object_id);
  if (!e.detail.empty()) line += "  " + e.detail;
  return line;
}

using Described = std::vector<std::shared_ptr<const pipeline::ObjectClassInfo>>;

// The object list after a frame, as GetObjects gives it: one line, or one JSON object. `described`:
// empty, or one class per object (WorkingMemory::describe_objects; null: an object without points).
void print_objects(std::size_t frame, const pipeline::SceneSnapshot& snapshot, const Described& described, bool json) {
  const auto described_as = [&](std::size_t k) { return k < described.size() ? described[k].get() : nullptr; };
  if (json) {
    nlohmann::json list = nlohmann::json::array();
    for (std::size_t k = 0; k < snapshot.objects.size(); ++k) {
      const TrackedObject& o = snapshot.objects[k];
      const Eigen::Vector3d& c = o.cluster.centroid;
      const Eigen::Vector3d& e = o.cluster.box.extents;
      list.push_back({{"id", o.id}, {"centroid", {c.x(), c.y(), c.z()}}, {"extents", {e.x(), e.y(), e.z()}},
                      {"points", o.cluster.point_count}, {"observations", o.observations}, {"plane", o.cluster.plane_id},
                      {"foreground", o.foreground.has_value()}});
      if (const auto* info = described_as(k)) {
        list.back()["class"] = info->class_name;
        list.back()["score"] = info->score;
      }
    }
    nlohmann::json planes = nlohmann::json::array();
    for (const auto& p : snapshot.planes) {
      nlohmann::json hull = nlohmann::json::array();
      for (const auto& h : p.hull) hull.push_back({h.x(), h.y(), h.z()});
      planes.push_back({{"id", p.id}, {"centroid", {p.centroid.x(), p.centroid.y(), p.centroid.z()}}, {"area_m2", p.area_m2},
                        {"hull", hull}});
    }
    std::cout << nlohmann::json{{"frame", frame}, {"objects", list}, {"planes", planes}}.dump() << "\n";
    return;
  }
  std::printf("frame %4zu  %zu objects:", frame, snapshot.objects.size());
  for (std::size_t k = 0; k < snapshot.objects.size(); ++k) {
    const TrackedObject& o = snapshot.objects[k];
    const Eigen::Vector3d& e = o.cluster.box.extents;
    std::printf("  #%llu %.0fx%.0fx%.0f cm %zu pts %d seen%s", static_cast<unsigned long long>(o.id), 100 * e.x(), 100 * e.y(),
                100 * e.z(), o.cluster.point_count, o.observations, o.foreground ? " fg" : "");
    if (const auto* info = described_as(k)) std::printf(" %s (score %.2f)", info->class_name.c_str(), info->score);
  }
  std::printf("\n");
}

// What localization made of the frames: states, corrections of the given poses, its time.
struct LocalizationSummary {
  std::map<std::string, std::size_t> states;
  std::vector<double> correction_mm, correction_deg, ms;
  std::vector<io::StampedPose> trajectory;

  void add(const Frame& frame, const localization::Localization& l) {
    ++states[localization::state_name(l.state)];
    if (l.placed()) trajectory.push_back({frame.stamp_s, l.T_world_camera});
    if (l.state == localization::State::kGiven) return;
    ms.push_back(l.ms);
    if (l.given && l.mode == LocalizationMode::kRefine && l.state == localization::State::kTracking) {
      correction_mm.push_back(1000 * l.correction_m);
      correction_deg.push_back(l.correction_deg);
    }
  }
  std::string line() const {
    std::string out = "localization:";
    for (const auto& [state, n] : states) out += " " + state + " " + std::to_string(n);
    char buf[200];
    if (!correction_mm.empty()) {
      std::snprintf(buf, sizeof buf, "; correction of the given poses median %.1f mm %.2f deg, p95 %.1f mm", percentile(correction_mm, 0.5),
                    percentile(correction_deg, 0.5), percentile(correction_mm, 0.95));
      out += buf;
    }
    if (!ms.empty()) {
      std::snprintf(buf, sizeof buf, "; median %.1f ms", percentile(ms, 0.5));
      out += buf;
    }
    return out;
  }
};

// What a replay counted and timed, for its summary.
struct Tally {
  std::size_t frames = 0, events = 0, frames_with_hands = 0;
  std::map<std::string, std::size_t> by_kind;
  std::map<std::string, std::vector<double>> stage_ms;
  std::vector<double> frame_ms;
  LocalizationSummary located;
};

// The summary after the last frame: one JSON object, or a few lines.
void print_summary(const Tally& t, const pipeline::Stats& stats, double wall_s, bool json) {
  const double per100 = t.frames ? 100.0 * t.events / t.frames : 0.0;
  if (json) {
    nlohmann::json summary = {{"summary", true},
                              {"frames", t.frames},
                              {"events", t.events},
                              {"events_per_100_frames", per100},
                              {"by_kind", t.by_kind},
                              {"median_frame_ms", percentile(t.frame_ms, 0.5)},
                              {"p90_frame_ms", percentile(t.frame_ms, 0.9)},
                              {"tracked_objects", stats.tracked_objects},
                              {"frames_with_hands", t.frames_with_hands},
                              {"keyframes", stats.keyframes},
                              {"localization", {{"states", t.located.states},
                                                {"median_correction_mm", percentile(t.located.correction_mm, 0.5)},
                                                {"median_correction_deg", percentile(t.located.correction_deg, 0.5)},
                                                {"median_ms", percentile(t.located.ms, 0.5)}}}};
    for (const auto& [stage, v] : t.stage_ms) summary["median_stage_ms"][stage] = percentile(v, 0.5);
    for (const auto& [camera, r] : stats.colour_registration) {
      summary["colour_registration"][camera] = {{"scale", r.scale}, {"shift_x_px", r.shift_x_px}, {"shift_y_px", r.shift_y_px}};
    }
    std::cout << summary.dump() << "\n";
    return;
  }
  std::printf("\n%zu frames, %zu events (%.1f per 100 frames)", t.frames, t.events, per100);
  for (const auto& [kind, count] : t.by_kind) std::printf(", %s %zu", kind.c_str(), count);
  std::printf("\nper frame: median %.1f ms, p90 %.1f ms (%.1f s in all, with decoding)\n", percentile(t.frame_ms, 0.5),
              percentile(t.frame_ms, 0.9), wall_s);
  std::printf("stage medians:");
  for (const auto& [stage, v] : t.stage_ms) std::printf("  %s %.1f ms", stage.c_str(), percentile(v, 0.5));
  std::printf("\nmodel: %zu tracked objects, %zu keyframes, %zu occupied voxels; hands seen in %zu frames\n",
              stats.tracked_objects, stats.keyframes, stats.map_occupied_leaves, t.frames_with_hands);
  std::printf("%s\n", t.located.line().c_str());
  for (const auto& [camera, r] : stats.colour_registration) {
    std::printf("colour registered to depth (%s): scale %.4f, shift %+.1f, %+.1f px\n", camera.empty() ? "default camera" : camera.c_str(),
                r.scale, r.shift_x_px, r.shift_y_px);
  }
}

}  // namespace

int run_replay(const ReplayOptions& options) {
  auto config = read_config_file(options.config);
  if (!config) return fail(config.error().message);
  if (!options.localization.empty()) {
    auto mode = localization::parse_mode(options.localization);
    if (!mode) return fail("--localization: " + mode.error().message);
    config->localization.mode = *mode;
  }
  if (!options.heatmap_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.heatmap_dir, ec);
    if (ec) return fail("--heatmaps '" + options.heatmap_dir + "': " + ec.message());
  }
  // --classes: the daemon's classes file (no store: nothing learnt is kept).
  std::unique_ptr<ontology::ClassCatalog> classes;
  if (options.classes) {
    const auto classes_file =
        options.classes_file.empty() ? apps::config_dir() / "ontology.yaml" : std::filesystem::path(options.classes_file);
    auto catalog = ontology::ClassCatalog::open(classes_file, {});
    if (!catalog) return fail("--classes: " + catalog.error().message);
    classes = std::move(*catalog);
  }
  pipeline::WorkingMemory memory(*config);
  Tally tally;
  const auto wall0 = std::chrono::steady_clock::now();
  for (const auto& spec : options.inputs) {
    InputOptions sequence(sequence_options(options.depth_scale_m));
    sequence.bag = options.bag;
    std::size_t index = 0;
    auto st = for_each_frame(spec, std::nullopt, [&](Frame frame) -> Status {
      const std::size_t k = index++;
      if (options.stride > 1 && k % options.stride != 0) return {};
      auto result = memory.process(frame);
      if (!result) return Error{result.error().code, frame.source + ": " + result.error().message};
      tally.frame_ms.push_back(result->total_ms);
      tally.located.add(frame, result->localization);
      if (options.json && !result->localization.placed()) {
        std::cout << nlohmann::json{{"frame", tally.frames}, {"source", frame.source}, {"localization", "lost"},
                                    {"reason", result->localization.reason}}.dump() << "\n";
      }
      tally.stage_ms["segmentation"].push_back(result->segment_ms);
      tally.stage_ms["change"].push_back(result->change_ms);
      tally.stage_ms["surprise"].push_back(result->surprise_ms);
      tally.stage_ms["map insertion"].push_back(result->insert_ms);
      tally.stage_ms["hands"].push_back(result->hands_ms);
      tally.frames_with_hands += result->hands > 0 ? 1 : 0;
      tally.stage_ms["foreground"].push_back(result->foreground_ms);
      if (!options.heatmap_dir.empty() && result->surprise) {
        char name[64];
        std::snprintf(name, sizeof name, "surprise-%06zu.png", tally.frames);
        auto kf = background::keyframe_from_frame(frame);
        const ColorImage observed = kf ? kf->color : ColorImage{};
        if (auto w = io::write_color_png(std::filesystem::path(options.heatmap_dir) / name,
                                         surprise::heatmap_overlay(result->surprise->map, observed));
            !w)
          return w;
      }
      for (const auto& e : result->events) {
        ++tally.events;
        ++tally.by_kind[to_string(e.kind)];
        if (options.json) {
          nlohmann::json j = to_json(e);
          j["frame"] = tally.frames;
          j["source"] = frame.source;
          j["range_m"] = range_from_camera(frame, e);
          std::cout << j.dump() << "\n";
        } else {
          std::cout << event_line(tally.frames, e, range_from_camera(frame, e)) << "\n";
        }
      }
      if (options.objects) {
        const auto snapshot = memory.snapshot();
        const Described described = classes ? memory.describe_objects(*snapshot, *classes) : Described{};
        print_objects(tally.frames, *snapshot, described, options.json);
      }
      ++tally.frames;
      if (options.progress && !options.json && tally.frames % 25 == 0) {
        std::cerr << "  " << tally.frames << " frames, " << tally.events << " events\n";
      }
      return {};
    }, sequence);
    if (!st) return fail(st.error().message);
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (!options.trajectory.empty()) {
    if (auto st = io::write_tum(options.trajectory, tally.located.trajectory); !st) return fail("--trajectory: " + st.error().message);
  }
  print_summary(tally, memory.stats(), wall_s, options.json);
  return kExitOk;
}

void add_replay_command(CLI::App& app, Action& action) {
  auto options = std::make_shared<ReplayOptions>();
  auto* replay = app.add_subcommand(
      "replay",
      "offline: run recordings through the working memory exactly as the daemon would (no daemon), print\n"
      "each event as it arises, then count them (events per 100 frames, by kind) and time the frames\n"
      "(median and p90, per stage). The way to see what a planner would be told about a recording.");
  replay->footer(
      "Inputs: SEQDIR (every frame, with its poses), SEQDIR:N, SEQDIR:A-B (frames A to B, 0-based), cloud files.\n"
      "Examples:\n"
      "  scenewatch replay ../shared/data/redkitchen\n"
      "  scenewatch replay ../shared/data/hrt1/pick_toy_1:0-14 --config config/scenewatchd.yaml --json\n"
      "  scenewatch replay ../shared/data/pcl/table_scene_mug_stereo_textured.pcd --objects --classes\n"
      "  scenewatch replay rgbd_dataset_freiburg1_xyz          (a TUM RGB-D folder: rgb.txt, depth.txt, groundtruth.txt)\n"
      "  scenewatch replay ../shared/data/ycb --depth-scale 0.0001   (depth in units of 0.1 mm)\n"
      "  scenewatch replay kitchen.bag:0-99 --depth-topic /camera/aligned_depth_to_color/image_raw   (a ROS bag)\n"
      "Scenario scripts: `scenewatch replay SCRIPT.yaml [--check] [--port P] [--token-file F]` streams what the\n"
      "script names (a simulator scenario or a sequence folder) through a RUNNING daemon over TCP, prints the\n"
      "events and the foreground objects, and compares them with the script's expectations (docs/testing.md,\n"
      "'Scenario scripts'); with --check it exits 1 when one is not met.\n"
      "  scenewatch replay tests/scenarios/hand_tilts_cup.yaml --check --port 7501");
  replay->add_option("inputs", options->inputs, "sequence folders, ROS bags, frame ranges or cloud files")->required();
  replay->add_option("--config", options->config, "YAML config, as the daemon's (its pipeline sections are used)");
  replay->add_option("--stride", options->stride, "process every N-th frame of each input")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  replay->add_option("--heatmaps", options->heatmap_dir,
                     "write each frame's image surprise over its colour image as DIR/surprise-NNNNNN.png");
  replay->add_flag("--json", options->json, "one JSON object per event (with its frame), then a summary object");
  add_depth_scale_option(replay, options->depth_scale_m);
  add_bag_options(replay, options->bag);
  replay->add_option("--localization", options->localization,
                     "where frames were taken: given (trust their poses; the default), refine (align the given pose to "
                     "the memory), track (no poses needed); overrides localization.mode")
      ->check(CLI::IsMember({"given", "refine", "track"}));
  replay->add_option("--trajectory", options->trajectory,
                     "write the poses the memory used (aligned frames) as a TUM trajectory: t tx ty tz qx qy qz qw");
  auto* objects_flag = replay->add_flag("--objects", options->objects,
                                        "after each frame, the object list a planner would get (GetObjects): id, size, "
                                        "points, sightings");
  auto* classes_flag =
      replay->add_flag("--classes", options->classes,
                       "with --objects: each object's class and score, as GetObjects with describe gives them (the "
                       "ontology; an object is described again when seen again and its description is older than 2 s)")
          ->needs(objects_flag);
  replay->add_option("--classes-file", options->classes_file,
                     "the object classes for --classes (default: the shipped ontology.yaml, in /etc/scenewatch when installed)")
      ->needs(classes_flag);
  // A scenario script goes to a running daemon, with flags of its own.
  struct Scenario {
    bool check = false;
    RemoteOptions remote;
  };
  auto scenario = std::make_shared<Scenario>();
  replay->add_flag("--check", scenario->check, "scenario scripts: exit 1 when an expectation is not met");
  replay->add_option("--host", scenario->remote.host, "scenario scripts: the daemon's host")->capture_default_str();
  replay->add_option("--port", scenario->remote.port, "scenario scripts: the daemon's TCP port")->check(CLI::Range(1, 65535))->capture_default_str();
  replay->add_option("--token-file", scenario->remote.token_file, "scenario scripts: the daemon's access token")->capture_default_str();
  on_parsed(replay, action, [options, scenario] {
    const bool script = options->inputs.size() == 1 && std::filesystem::path(options->inputs[0]).extension() == ".yaml";
    if (script) return run_scenario(scenario->remote, options->inputs[0], scenario->check);
    return run_replay(*options);
  });
}

}  // namespace scenewatch::cli
