// scenewatch-ros: the ROS 2 bridge of scenewatchd over DDS (issue 32). A Cyclone DDS participant
// that speaks ROS 2's conventions on one side, a client of the daemon's TCP API on the other.
#include <CLI/CLI.hpp>

#include <malloc.h>

#include <csignal>
#include <cstdlib>
#include <iostream>
#include <mutex>
#include <optional>
#include <thread>

#include "bridge_config.h"
#include "daemon_link.h"
#include "dds_node.h"
#include "frame_assembler.h"

namespace {

using namespace scenewatch::ros;

std::atomic<bool> g_stop{false};

void on_signal(int) { g_stop = true; }

constexpr const char* kDescription =
    "scenewatch-ros - the ROS 2 bridge of scenewatchd over DDS (Eclipse Cyclone DDS).\n"
    "\n"
    "A DDS participant that is a ROS 2 peer (topics rt/<name>, types <pkg>::msg::dds_::<Type>_, CDR\n"
    "little-endian): run it beside a camera driver whose ROS 2 uses rmw_cyclonedds_cpp, on the same\n"
    "ROS_DOMAIN_ID. It reads sensor_msgs/Image depth (16UC1 mm or 32FC1 m) and colour (rgb8, bgr8,\n"
    "rgba8, bgra8, mono8) with sensor_msgs/CameraInfo, or an organized sensor_msgs/PointCloud2\n"
    "(--cloud-topic), and the camera pose from /tf and /tf_static,\n"
    "sends each frame to scenewatchd (IngestFrame), and publishes under --namespace:\n"
    "  events          scenewatch_msgs/msg/EventArray      reliable, keep last 10\n"
    "  objects         vision_msgs/msg/Detection3DArray    reliable, keep last 10 (after every frame)\n"
    "  octomap_binary  octomap_msgs/msg/Octomap            reliable, transient local (binary, id OcTree)\n"
    "  markers         visualization_msgs/msg/MarkerArray  reliable, keep last 10 (after every frame; for RViz:\n"
    "                  a DELETEALL, then planes, objects, labels, hands, person, events; --no-markers)\n"
    "  surprise        sensor_msgs/msg/Image 32FC1         best effort, keep last 5 (after every frame the memory\n"
    "                  predicts: the image surprise in nats per pixel, NaN where unknown, in the camera's frame;\n"
    "                  --no-surprise)\n"
    "and, with --publish-odom-tf, --world-frame -> --odom-frame on /tf (reliable, keep last 100).\n"
    "Images, clouds and camera info are read best effort, keep last 5; /tf reliable; /tf_static transient local.\n"
    "Prints 'ready' on stdout once its DDS entities exist, and a stats line on exit (SIGINT, SIGTERM).\n"
    "Exit codes: 0 stopped by a signal, 1 error (message on stderr), 2 usage.";

/// The command line: every flag writes into `config`; --without-tf into `without_tf`.
void add_options(CLI::App& app, BridgeConfig& config, std::string& without_tf) {
  app.set_version_flag("--version", "scenewatch-ros " SCENEWATCH_VERSION);
  app.add_option("--domain", config.domain_id, "DDS domain = ROS_DOMAIN_ID (default: $ROS_DOMAIN_ID, else 0)")
      ->check(CLI::Range(0, 232))
      ->capture_default_str();
  app.add_option("--depth-topic", config.depth_topic, "depth sensor_msgs/Image, registered to colour: 16UC1 in mm or 32FC1 in m")
      ->capture_default_str();
  app.add_option("--color-topic", config.color_topic, "colour sensor_msgs/Image of the same size and stamps; \"\" for depth only (grey points)")
      ->capture_default_str();
  app.add_option("--info-topic", config.info_topic, "sensor_msgs/CameraInfo of the depth images (K and size are used)")
      ->capture_default_str();
  app.add_option("--cloud-topic", config.cloud_topic,
                 "take frames from this organized sensor_msgs/PointCloud2 (FLOAT32 x, y, z in the optical frame, optional rgb) "
                 "instead of --depth-topic and --color-topic; the pinhole from --info-topic when it publishes, else estimated "
                 "from the cloud");
  // A duration in seconds, >= 0 (> 0 when `positive`).
  auto seconds_option = [&app](const char* flag, double& value, const char* help, bool positive = false) {
    app.add_option(flag, value, help)->check(positive ? CLI::Validator(CLI::PositiveNumber) : CLI::Validator(CLI::NonNegativeNumber))->capture_default_str();
  };
  app.add_option("--world-frame", config.world_frame, "TF frame of the daemon's world: poses are T_world_camera")->capture_default_str();
  app.add_flag("--publish-odom-tf", config.publish_odom_tf,
               "publish --world-frame -> --odom-frame on /tf after each frame: the daemon's T_world_odom (its localization's "
               "correction of the given poses); camera poses are then looked up in --odom-frame");
  app.add_option("--odom-frame", config.odom_frame, "the robot's odometry TF frame, for --publish-odom-tf")->capture_default_str();
  app.add_option("--camera-frame", config.camera_frame, "the depth camera's optical TF frame (default: the depth images' header.frame_id)");
  seconds_option("--tf-tolerance", config.tf_tolerance_s,
                 "seconds between an image stamp and the nearest /tf sample that still give its pose (between two samples: interpolated)");
  seconds_option("--sync-tolerance", config.sync_tolerance_s,
                 "seconds between a colour and a depth stamp that still make one frame");
  seconds_option("--tf-wait", config.tf_wait_s,
                 "seconds a frame waits for its TF to arrive before it is dropped");
  app.add_option("--without-tf", without_tf,
                 "a frame with no TF in time: 'drop' it (counted, logged), or 'track': send it without a pose for the daemon's "
                 "tracking to place (localization TRACK; the daemon must have a memory to track against)")
      ->check(CLI::IsMember({"drop", "track"}))
      ->capture_default_str();
  app.add_option("--namespace", config.output_namespace, "ROS namespace of the published topics")->capture_default_str();
  app.add_option("--camera-name", config.camera_name, "IngestFrame.camera: which camera the frames come from (\"\": the daemon's default)");
  app.add_option("--host", config.host, "scenewatchd's host")->capture_default_str();
  app.add_option("--port", config.port, "scenewatchd's TCP port")->check(CLI::Range(1, 65535))->capture_default_str();
  app.add_option("--token-file", config.token_file, "the daemon's access token (default: ~/.scenewatch/token)");
  seconds_option("--call-timeout", config.call_timeout_s,
                 "seconds a daemon reply may take before the connection is made again", true);
  seconds_option("--max-backoff", config.max_backoff_s,
                 "longest wait between reconnection attempts, seconds (from 0.1 s, doubling)", true);
  app.add_option("--queue-frames", config.queue_frames,
                 "frames waiting for the daemon; beyond, the oldest is dropped (counted, logged) so small topics never wait behind big images")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  seconds_option("--map-period", config.map_period_s,
                 "seconds between two octomap messages at most (the last frame's map is sent once the stream pauses)");
  app.add_flag("--no-markers", [&config](std::int64_t) { config.markers = false; },
               "publish no MarkerArray (saves a GetHands call per frame)");
  app.add_flag("--no-surprise", [&config](std::int64_t) { config.surprise = false; },
               "publish no surprise heatmap (saves a GetSurpriseMap call per frame)");
  app.add_option("--marker-events", config.marker_events, "the newest events drawn as markers (yellow boxes)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  seconds_option("--stats-period", config.stats_period_s,
                 "seconds between two stats lines on stdout (0: only at exit)");
}

/// What CLI11 cannot check alone; the usage message, or none.
std::optional<std::string> usage_error(const BridgeConfig& config) {
  for (const auto& [flag, topic] : {std::pair<const char*, const std::string*>{"--depth-topic", &config.depth_topic},
                                    {"--info-topic", &config.info_topic}, {"--color-topic", &config.color_topic},
                                    {"--cloud-topic", &config.cloud_topic}}) {
    if (topic->empty() && (topic == &config.color_topic || topic == &config.cloud_topic)) continue;  // depth only; images
    if (auto name = dds_topic_name(*topic); !name) return std::string(flag) + ": " + name.error().message;
  }
  if (config.world_frame.empty()) return std::string("--world-frame must name a TF frame");
  if (config.publish_odom_tf && (config.odom_frame.empty() || config.odom_frame == config.world_frame)) {
    return std::string("--publish-odom-tf needs an --odom-frame other than --world-frame");
  }
  return std::nullopt;
}

/// Where the daemon's answers go: the DDS writers (markers and /tf only when asked).
Outputs outputs_to(DdsNode& dds, const BridgeConfig& config, std::function<void(const std::string&)> log) {
  Outputs outputs;
  outputs.events = [&dds](const std::vector<scenewatch::proto::Event>& events) { dds.write_events(events); };
  outputs.objects = [&dds](const scenewatch::proto::ObjectsReply& objects, double stamp_s) { dds.write_objects(objects, stamp_s); };
  outputs.map = [&dds](const scenewatch::proto::MapReply& map, double stamp_s) { dds.write_map(map, stamp_s); };
  if (config.publish_odom_tf) outputs.odom = [&dds](const scenewatch::proto::Pose& T, double stamp_s) { dds.write_odom(T, stamp_s); };
  if (config.markers) outputs.markers = [&dds](const MarkerScene& scene, double stamp_s) { dds.write_markers(scene, stamp_s); };
  if (config.surprise) {
    outputs.surprise = [&dds](const scenewatch::proto::SurpriseMapReply& map, double stamp_s, const std::string& frame) {
      dds.write_surprise(map, stamp_s, frame);
    };
  }
  outputs.log = std::move(log);
  return outputs;
}

/// Prints the stats line every `period_s` seconds until the stop signal (none when period_s <= 0).
std::thread stats_printer(BridgeStats& stats, double period_s) {
  if (period_s <= 0) return {};
  return std::thread([&stats, period_s] {
    auto next = Clock::now() + std::chrono::duration<double>(period_s);
    while (!g_stop) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      if (Clock::now() < next) continue;
      std::cout << stats.line() << std::endl;
      next += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period_s));
    }
  });
}

}  // namespace

/// Every frame moves megabytes through buffers of the same few sizes (a VGA frame's images, the
/// request). glibc gives blocks over its mmap threshold fresh pages each time and returns them on
/// free, and the page faults of touching them cost more than the copies: measured at VGA, 9.4 ms
/// to write a 1.5 MB request and 4.2 ms to build it, against 0.9 and 2.0 ms with the blocks kept
/// in the heap (docs/ros2.md). So the blocks stay: up to 32 MiB from the heap, and up to 128 MiB of
/// free heap kept rather than trimmed. An environment's own GLIBC_TUNABLES still win.
void keep_large_blocks() {
  if (std::getenv("GLIBC_TUNABLES") != nullptr) return;
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 128 << 20);
}

int main(int argc, char** argv) {
  keep_large_blocks();
  BridgeConfig config;
  if (const char* domain = std::getenv("ROS_DOMAIN_ID"); domain != nullptr && *domain != '\0') {
    config.domain_id = static_cast<std::uint32_t>(std::strtoul(domain, nullptr, 10));
  }
  CLI::App app{kDescription};
  std::string without_tf = "drop";
  add_options(app, config, without_tf);
  CLI11_PARSE(app, argc, argv);
  config.without_tf = without_tf == "track" ? WithoutTf::kTrack : WithoutTf::kDrop;
  if (auto usage = usage_error(config)) {
    std::cerr << "scenewatch-ros: " << *usage << "\n";
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGPIPE, SIG_IGN);

  BridgeStats stats;
  std::mutex log_mutex;
  auto log = [&](const std::string& line) {
    std::lock_guard<std::mutex> lock(log_mutex);
    std::cerr << "scenewatch-ros: " << line << std::endl;
  };
  auto node = DdsNode::create(config, stats);
  if (!node) {
    std::cerr << "scenewatch-ros: " << node.error().message << "\n";
    return 1;
  }
  DdsNode& dds = **node;
  Outputs outputs = outputs_to(dds, config, log);
  DaemonLink link(config, stats, outputs);
  FrameAssembler assembler(config, stats, [&](FrameJob job) { link.push(std::move(job)); }, log);
  link.start();
  std::cout << "ready" << std::endl;

  std::thread stats_thread = stats_printer(stats, config.stats_period_s);
  dds.run(assembler, g_stop);
  link.stop();
  if (stats_thread.joinable()) stats_thread.join();
  std::cout << stats.line() << std::endl;
  return 0;
}
