// The flags several commands share, how a command tells main what to run, and how it fails.
#include "subcommand.h"

#include <iostream>

namespace scenewatch::cli {

int fail(const std::string& message) {
  std::cerr << "scenewatch: " << message << std::endl;
  return kExitError;
}

void on_parsed(CLI::App* command, Action& action, Action run) {
  command->callback([&action, run = std::move(run)] { action = run; });
}

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

void add_bag_options(CLI::App* command, io::BagOptions& bag) {
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

void add_depth_scale_option(CLI::App* command, std::optional<double>& depth_scale_m) {
  command->add_option("--depth-scale", depth_scale_m,
                      "metres per depth unit of RGB-D sequence folders (0.001 = mm, 0.0002 = TUM's 1/5000 m, "
                      "0.0001 = 0.1 mm); default: the folder's depth-scale.txt, else its layout's unit")
      ->check(CLI::Range(1e-7, 1.0));
}

void add_daemon_command(CLI::App& app, const std::string& name, const std::string& description, RemoteOptions& remote,
                        Action& action, int (*run)(const RemoteOptions&)) {
  auto* command = app.add_subcommand(name, description);
  add_remote_options(command, remote);
  on_parsed(command, action, [&remote, run] { return run(remote); });
}

}  // namespace scenewatch::cli
