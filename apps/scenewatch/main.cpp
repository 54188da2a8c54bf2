// scenewatch: the command-line client of scenewatchd, plus offline tools that work on files.
#include <CLI/CLI.hpp>

#include <filesystem>

#include <functional>
#include <optional>
#include <iostream>

#include "commands.h"

namespace {

using namespace scenewatch::cli;

void add_remote_options(CLI::App* command, RemoteOptions& options) {
  command->add_option("--host", options.host, "daemon host")->capture_default_str();
  command->add_option("--port", options.port, "daemon TCP port")->check(CLI::Range(1, 65535))->capture_default_str();
  command->add_option("--timeout", options.timeout_s, "seconds to wait for each answer, 0 = forever")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command->add_flag("--json", options.json, "print machine-readable JSON");
  command->add_option("--token-file", options.token_file,
                      "the daemon's access token, needed by ingest, clear, reset, save, load and define-class")
      ->capture_default_str();
}

/// The flags of the commands that read ROS bags (replay, ingest, fit): topics and TF frames.
void add_bag_options(CLI::App* command, scenewatch::io::BagOptions& bag) {
  command->add_option("--color-topic", bag.color_topic, "ROS bags: the colour sensor_msgs/Image topic (default: the only one)");
  command->add_option("--depth-topic", bag.depth_topic,
                      "ROS bags: the depth sensor_msgs/Image topic, 16UC1 in mm or 32FC1 in m (default: the only one)");
  command->add_option("--info-topic", bag.info_topic,
                      "ROS bags: the depth camera's sensor_msgs/CameraInfo topic (default: the only one, or the one beside the depth topic)");
  command->add_option("--cloud-topic", bag.cloud_topic,
                      "ROS bags without depth images: an organized sensor_msgs/PointCloud2 topic (default: the only one)");
  command->add_option("--world-frame", bag.world_frame, "ROS bags: the TF frame of the world (default: the root of the camera's TF tree)");
  command->add_option("--camera-frame", bag.camera_frame, "ROS bags: the camera's TF frame (default: the depth images' header.frame_id)");
}

/// --depth-scale for every command that reads RGB-D sequence folders.
void add_depth_scale_option(CLI::App* command, std::optional<double>& depth_scale_m) {
  command->add_option("--depth-scale", depth_scale_m,
                      "metres per depth unit of RGB-D sequence folders (0.001 = mm, 0.0002 = TUM's 1/5000 m, "
                      "0.0001 = 0.1 mm); default: the folder's depth-scale.txt, else its layout's unit")
      ->check(CLI::Range(1e-7, 1.0));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"scenewatch - talk to the scenewatchd perception service, or work on cloud files offline.\n"
               "Exit codes: 0 ok, 1 error (message on stderr), 2 usage."};
  app.set_version_flag("--version", "scenewatch " SCENEWATCH_VERSION);
  app.require_subcommand(1);
  RemoteOptions remote;
  // Accepted before the command too: `scenewatch --port 7879 health` as well as `scenewatch health --port 7879`.
  add_remote_options(&app, remote);
  std::function<int()> action;

  auto* health = app.add_subcommand("health", "check that the daemon answers");
  add_remote_options(health, remote);
  health->callback([&] { action = [&] { return run_health(remote); }; });

  auto* stats = app.add_subcommand("stats", "counters of the daemon and its map");
  add_remote_options(stats, remote);
  stats->callback([&] { action = [&] { return run_stats(remote); }; });

  auto* where = app.add_subcommand("localization", "where each camera is: state, T_world_odom, last correction, quality");
  where->add_option("--camera", remote.camera, "this camera only (an error when it sent no frame)");
  add_remote_options(where, remote);
  where->callback([&] { action = [&] { return run_localization(remote); }; });

  std::vector<std::string> ingest_paths;
  bool server_side = false;
  std::optional<double> ingest_depth_scale;
  auto* ingest = app.add_subcommand(
      "ingest", "send cloud files or RGB-D sequence folders, frame by frame (--json: one object per line)");
  ingest->footer(
      "Sequence folders: the 7-Scenes layout (frame-NNNNNN.color.png|.jpg, .depth.png, .pose.txt,\n"
      "camera-intrinsics.txt) or the TUM RGB-D layout (rgb.txt, depth.txt, groundtruth.txt), told apart by\n"
      "their files. Depth in mm (TUM: 1/5000 m) unless depth-scale.txt or --depth-scale says otherwise.\n"
      "ROS bags (ROS 1 .bag; rosbag2 .db3 or its folder): depth and colour images, CameraInfo and TF, topics\n"
      "guessed from their types or named by --depth-topic and the other bag flags.\n"
      "A sequence's frames go two at a time: the next frame is read and sent while the daemon processes the\n"
      "one before it; every frame is processed, in order, and the answers are printed in that order.");
  ingest->add_option("paths", ingest_paths, "cloud files, sequence folders and/or ROS bags (BAG, BAG:N, BAG:A-B)")->required();
  ingest->add_flag("--server-side", server_side,
                   "let the daemon read the files itself (absolute paths under its data roots)");
  std::optional<double> live_fps;
  ingest->add_option("--live", live_fps,
                     "stream sequence folders as a live sensor: FPS frames per second without waiting for replies; "
                     "the daemon skips a frame when a newer one is already waiting, and the summary counts them")
      ->check(CLI::Range(0.1, 1000.0));
  bool live_preload = false;
  ingest->add_flag("--preload", live_preload,
                   "with --live: decode every frame before the first is sent, so frames leave at FPS as from a "
                   "sensor and not at the pace of reading and decoding them (about 1.5 MB of memory per VGA frame); "
                   "the summary gives the rate achieved either way");
  ingest->add_option("--camera", remote.camera,
                     "the name of the camera the frames come from; frames of several cameras may feed one daemon at "
                     "once, each run its own camera (default: the first path's folder and this process's id, "
                     "e.g. redkitchen#4242)");
  std::string ingest_localization;
  ingest->add_option("--localization", ingest_localization,
                     "how the daemon finds each frame's pose: given, refine or track (no poses needed); "
                     "overrides its localization.mode for these frames")
      ->check(CLI::IsMember({"given", "refine", "track"}))
      ->each([&](const std::string& m) {
        remote.localization = m == "given" ? scenewatch::LocalizationMode::kGiven : m == "refine" ? scenewatch::LocalizationMode::kRefine : scenewatch::LocalizationMode::kTrack;
      });
  std::string ingest_trajectory;
  ingest->add_option("--trajectory", ingest_trajectory,
                     "write the poses the memory used (frames not lost) as a TUM trajectory: t tx ty tz qx qy qz qw");
  add_depth_scale_option(ingest, ingest_depth_scale);
  scenewatch::io::BagOptions ingest_bag;
  add_bag_options(ingest, ingest_bag);
  add_remote_options(ingest, remote);
  ingest->callback([&] {
    action = [&] {
      if (live_fps) {
        if (server_side) return fail("--live and --server-side do not go together");
        if (!ingest_trajectory.empty()) return fail("--trajectory and --live do not go together (live replies may be skipped)");
        return run_live_ingest(remote, ingest_paths, *live_fps, live_preload, ingest_depth_scale, ingest_bag);
      }
      if (live_preload) return fail("--preload goes with --live");
      return run_ingest(remote, ingest_paths, server_side, ingest_depth_scale, ingest_trajectory, ingest_bag);
    };
  });

  auto* planes = app.add_subcommand("planes", "supporting planes of the last frame");
  add_remote_options(planes, remote);
  planes->callback([&] { action = [&] { return run_planes(remote); }; });

  auto* objects = app.add_subcommand("objects", "the tracked objects");
  add_remote_options(objects, remote);
  bool describe_objects = false;
  objects->add_flag("--describe", describe_objects,
                    "also each object's class, fitted primitive and grasps (the ontology; about 20 ms per object)");
  objects->callback([&] { action = [&] { return run_objects(remote, describe_objects); }; });

  auto* hands = app.add_subcommand("hands", "the hands and the person seen in the last frame (where not to reach)");
  add_remote_options(hands, remote);
  hands->callback([&] { action = [&] { return run_hands(remote); }; });

  std::vector<double> points, box;
  auto* occupancy = app.add_subcommand("occupancy", "occupancy of world points (X Y Z ...) and/or a box");
  occupancy->add_option("point", points, "X Y Z, possibly several points");
  occupancy->add_option("--box", box, "MINX MINY MINZ MAXX MAXY MAXZ")->expected(6);
  add_remote_options(occupancy, remote);
  occupancy->callback([&] {
    action = [&] {
      if (points.size() % 3 != 0) {
        std::cerr << "scenewatch occupancy: points need 3 coordinates each, got " << points.size() << " numbers\n";
        return kExitUsage;
      }
      if (points.empty() && box.empty()) {
        std::cerr << "scenewatch occupancy: give a point X Y Z and/or --box\n";
        return kExitUsage;
      }
      return run_occupancy(remote, points, box);
    };
  });

  std::vector<double> clear_box;
  auto* clear = app.add_subcommand("clear-box", "mark the known voxels in a world box free");
  clear->add_option("box", clear_box, "MINX MINY MINZ MAXX MAXY MAXZ")->expected(6)->required();
  add_remote_options(clear, remote);
  clear->callback([&] { action = [&] { return run_clear_box(remote, clear_box); }; });

  auto* classes = app.add_subcommand("classes", "list the daemon's object classes (name, primitive, bounds, grasps)");
  add_remote_options(classes, remote);
  classes->callback([&] { action = [&] { return run_classes(remote); }; });

  std::string class_file;
  auto* define_class = app.add_subcommand(
      "define-class", "add or replace object classes from FILE (config/ontology.yaml's format); kept in the daemon's ontology.sqlite");
  define_class->add_option("file", class_file, "YAML file: classes: [...]")->required();
  add_remote_options(define_class, remote);
  define_class->callback([&] { action = [&] { return run_define_class(remote, class_file); }; });

  auto* reset = app.add_subcommand("reset", "forget everything: map, objects, events");
  add_remote_options(reset, remote);
  reset->callback([&] { action = [&] { return run_reset(remote); }; });

  auto* save = app.add_subcommand("save", "save the model to the daemon's model directory");
  add_remote_options(save, remote);
  save->callback([&] { action = [&] { return run_save(remote); }; });

  auto* load = app.add_subcommand("load", "reload the model from the daemon's model directory");
  add_remote_options(load, remote);
  load->callback([&] { action = [&] { return run_load(remote); }; });

  std::uint64_t since = 0;
  std::uint32_t max_count = 0;
  auto* events = app.add_subcommand("events", "events from the daemon's log");
  events->add_option("--since", since, "only events with a larger id")->capture_default_str();
  events->add_option("--max", max_count, "at most this many (0: the daemon's default, 1000)");
  add_remote_options(events, remote);
  events->callback([&] { action = [&] { return run_events(remote, since, max_count); }; });

  auto* watch = app.add_subcommand(
      "watch", "print events as they happen until Ctrl-C (--json: one per line), and each change of a camera's localization "
               "state (lost, found, homed; --json: {\"localization\": ...})");
  add_remote_options(watch, remote);
  watch->callback([&] { action = [&] { return run_watch(remote); }; });

  NextViewOptions next_view;
  std::uint64_t next_object = 0, next_event = 0;
  auto* next = app.add_subcommand("next-view", "where to look next: camera poses that would see most of a target's unknown side");
  auto* next_object_opt = next->add_option("--object", next_object, "a tracked object's id (complete its model)");
  auto* next_event_opt = next->add_option("--event", next_event, "an event's id (confirm or dismiss it)");
  auto* next_box_opt = next->add_option("--box", next_view.box, "MINX MINY MINZ MAXX MAXY MAXZ (world)")->expected(6);
  auto* next_ws_opt = next->add_flag("--workspace", next_view.workspace, "every tracked object");
  next->add_option("--measure", next_view.measure, "unobserved, rear_side, rear_side_entropy, occlusion_aware, visible");
  next->add_option("-n", next_view.n, "views to return")->capture_default_str()->check(CLI::Range(1, 1000));
  next->add_option("--radius", next_view.radius_m, "distance from the target's centre, m (0: the daemon's 0.7)");
  add_remote_options(next, remote);
  next->callback([&, next_object_opt, next_event_opt, next_box_opt, next_ws_opt] {
    action = [&, next_object_opt, next_event_opt, next_box_opt, next_ws_opt] {
      // count() is the number of values given (six for --box), not of times the option was named.
      const int targets = (next_object_opt->count() > 0) + (next_event_opt->count() > 0) + (next_box_opt->count() > 0) + (next_ws_opt->count() > 0);
      if (targets != 1) {
        std::cerr << "scenewatch next-view: give exactly one of --object, --event, --box, --workspace\n";
        return kExitUsage;
      }
      if (next_object_opt->count()) next_view.object_id = next_object;
      if (next_event_opt->count()) next_view.event_id = next_event;
      return run_next_view(remote, next_view);
    };
  });

  SegmentOptions segment_options;
  auto* segment = app.add_subcommand(
      "segment", "offline: find supporting planes and the objects on them in a cloud file (no daemon)");
  segment->add_option("file", segment_options.file, "cloud file (.pcd or .ply)")->required();
  segment->add_flag("--json", segment_options.json, "print JSON (objects with the indices of their points)");
  segment->add_option("--out", segment_options.out_dir,
                      "write object_000.pcd, ... and plane_000.pcd, ... into this folder");
  segment->add_option("--config", segment_options.config, "YAML config (its segmentation section is used)");
  segment->add_flag("--plane-indices", segment_options.plane_indices, "with --json: also list plane inlier indices");
  segment->callback([&] { action = [&] { return run_segment(segment_options); }; });

  FitOptions fit_options;
  auto* fit = app.add_subcommand(
      "fit", "offline: segment one frame, fit primitives to each object and classify it (no daemon)");
  fit->footer(
      "FILE: a .pcd/.ply cloud, or one frame of an RGB-D sequence folder (DIR:N, DIR/frame-NNNNNN).\n"
      "Shapes by CGAL's Efficient RANSAC on the object's normals; the largest cylinder is refined by\n"
      "least squares, held upright along the support's normal when it stands within 25 degrees of it.\n"
      "Each class's primitive is then fitted and checked against the class's bounds: the object gets the\n"
      "best accepted class (score, grasp points, completed model) or 'unknown' with its best primitive.\n"
      "Example: scenewatch fit ../shared/data/ycb/frame-000003 --depth-scale 0.0001");
  fit->add_option("file", fit_options.file, "cloud file, sequence frame or bag frame (BAG:N)")->required();
  fit->add_flag("--json", fit_options.json, "print JSON (each object's shapes, refined cylinder, class, candidates, grasps and timings)");
  fit->add_option("--config", fit_options.config, "YAML config (its segmentation section is used)");
  fit->add_option("--classes", fit_options.classes, "object classes file (default: the shipped ontology.yaml, in /etc/scenewatch when installed)");
  fit->add_option("--out", fit_options.out_dir,
                  "write each object's completed model (its class's primitive, whole surface) to DIR as object-N-CLASS.pcd and .ply");
  add_depth_scale_option(fit, fit_options.depth_scale_m);
  add_bag_options(fit, fit_options.bag);
  fit->callback([&] { action = [&] { return run_fit(fit_options); }; });

  DiffOptions diff_options;
  auto* diff = app.add_subcommand(
      "diff",
      "offline: objects added, removed or moved from BEFORE to AFTER (no daemon).\n"
      "BEFORE and AFTER are cloud files (.pcd/.ply) or frames of RGB-D sequences (DIR/frame-NNNNNN, with\n"
      "their poses). Organized clouds of one unmoved camera are compared pixel by pixel; otherwise BEFORE\n"
      "goes into an occupancy map and AFTER is checked against it at its pose. Added: AFTER points in space\n"
      "BEFORE saw free. Removed: BEFORE surfaces AFTER's rays pass through. Occluded or unseen space\n"
      "claims nothing. --json lists each event with the indices of its points in BEFORE and AFTER.");
  diff->add_option("before", diff_options.before, "the earlier observation")->required();
  diff->add_option("after", diff_options.after, "the later observation")->required();
  diff->add_flag("--json", diff_options.json, "print JSON: events with point indices, world boxes, evidence");
  diff->add_option("--config", diff_options.config, "YAML config (its change and background sections are used)");
  diff->add_flag("--force-map", diff_options.force_map, "compare through the occupancy map even for same-camera pairs");
  diff->add_option("--resolution", diff_options.resolution_m, "map voxel edge in metres for the map path")
      ->check(CLI::Range(0.002, 0.2));
  add_depth_scale_option(diff, diff_options.depth_scale_m);
  diff->callback([&] { action = [&] { return run_diff(diff_options); }; });

  ReplayOptions replay_options;
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
  replay->add_option("inputs", replay_options.inputs, "sequence folders, ROS bags, frame ranges or cloud files")->required();
  replay->add_option("--config", replay_options.config, "YAML config, as the daemon's (its pipeline sections are used)");
  replay->add_option("--stride", replay_options.stride, "process every N-th frame of each input")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  replay->add_option("--heatmaps", replay_options.heatmap_dir,
                     "write each frame's image surprise over its colour image as DIR/surprise-NNNNNN.png");
  replay->add_flag("--json", replay_options.json, "one JSON object per event (with its frame), then a summary object");
  add_depth_scale_option(replay, replay_options.depth_scale_m);
  add_bag_options(replay, replay_options.bag);
  replay->add_option("--localization", replay_options.localization,
                     "where frames were taken: given (trust their poses), refine (align the given pose to the memory; "
                     "the default), track (no poses needed); overrides localization.mode")
      ->check(CLI::IsMember({"given", "refine", "track"}));
  replay->add_option("--trajectory", replay_options.trajectory,
                     "write the poses the memory used (aligned frames) as a TUM trajectory: t tx ty tz qx qy qz qw");
  auto* objects_flag = replay->add_flag("--objects", replay_options.objects,
                                        "after each frame, the object list a planner would get (GetObjects): id, size, "
                                        "points, sightings");
  auto* classes_flag =
      replay->add_flag("--classes", replay_options.classes,
                       "with --objects: each object's class and score, as GetObjects with describe gives them (the "
                       "ontology; an object is described again when seen again and its description is older than 2 s)")
          ->needs(objects_flag);
  replay->add_option("--classes-file", replay_options.classes_file,
                     "the object classes for --classes (default: the shipped ontology.yaml, in /etc/scenewatch when installed)")
      ->needs(classes_flag);
  bool scenario_check = false;
  RemoteOptions scenario_remote;
  replay->add_flag("--check", scenario_check, "scenario scripts: exit 1 when an expectation is not met");
  replay->add_option("--host", scenario_remote.host, "scenario scripts: the daemon's host")->capture_default_str();
  replay->add_option("--port", scenario_remote.port, "scenario scripts: the daemon's TCP port")->check(CLI::Range(1, 65535))->capture_default_str();
  replay->add_option("--token-file", scenario_remote.token_file, "scenario scripts: the daemon's access token")->capture_default_str();
  replay->callback([&] {
    const bool script = replay_options.inputs.size() == 1 && std::filesystem::path(replay_options.inputs[0]).extension() == ".yaml";
    if (script) {
      action = [&] { return run_scenario(scenario_remote, replay_options.inputs[0], scenario_check); };
    } else {
      action = [&] { return run_replay(replay_options); };
    }
  });

  SurpriseOptions surprise_options;
  auto* surprise = app.add_subcommand(
      "surprise",
      "image-based Bayesian surprise of an observed RGB-D frame: offline against --reference frames, or "
      "from the daemon's appearance memory when no reference is given");
  surprise->footer(
      "Frames: FILE.pcd|FILE.ply (an organized cloud, same camera as its references; intrinsics are recovered "
      "from its points unless --intrinsics), SEQDIR (every frame of a sequence, with its poses), SEQDIR:N (frame "
      "N, 0-based), SEQDIR:A-B.\n"
      "Examples:\n"
      "  scenewatch surprise after/:40 --reference before/ --out heat.png --raw kl.tiff\n"
      "  scenewatch surprise learn13.pcd --reference learn12.pcd --json\n"
      "  scenewatch surprise --out heat.png          (the daemon's last posed frame)");
  surprise->add_option("observed", surprise_options.observed, "the observed frame (optional with the daemon)");
  surprise->add_option("--reference,-r", surprise_options.references,
                       "reference frames (repeatable); without any, the daemon is asked");
  surprise->add_option("--out,-o", surprise_options.out_png, "write the surprise as a heatmap over the observed image (PNG)");
  surprise->add_option("--raw", surprise_options.raw_tiff, "write the total surprise per pixel, KL in nats, as 32-bit float TIFF (NaN: unknown)");
  surprise->add_option("--expected", surprise_options.expected_png, "offline: write the expected (virtual) image (PNG)");
  surprise->add_option("--panel", surprise_options.panel_png,
                       "offline: write the observed image, the expected image and the surprise heatmap side by side (PNG)");
  surprise->add_option("--mesh", surprise_options.mesh_ply, "offline: write the references' textured mesh (PLY)");
  surprise->add_option("--intrinsics", surprise_options.intrinsics, "3x3 camera matrix file for cloud files");
  surprise->add_option("--config", surprise_options.config, "YAML config (its appearance and surprise sections are used)");
  surprise->add_option("--saturation", surprise_options.saturation, "heatmap scale: nats shown as the hottest colour")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  add_depth_scale_option(surprise, surprise_options.depth_scale_m);
  add_remote_options(surprise, remote);  // --json among them: regions as APPEARANCE_CHANGE events
  surprise->callback([&] {
    action = [&] {
      surprise_options.json = remote.json;
      return run_surprise(surprise_options, remote);
    };
  });

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? kExitOk : kExitUsage;
  }
  return action ? action() : kExitUsage;
}
