// Bags as frame sources: the container by format, topics by choice, images paired by their header
// stamps (as TUM's associate.py pairs colour and depth: nearest in time, each used once), poses
// from the TF tree at the depth image's stamp.
#include "scenewatch/io/bag.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>

#include <yaml-cpp/yaml.h>

#include "bag/container.h"
#include "bag/ros_messages.h"
#include "scenewatch/io/bag/image_conversion.h"
#include "scenewatch/io/bag/tf_tree.h"
#include "bag/topic_choice.h"
#include "scenewatch/io/rgbd.h"

namespace scenewatch::io {
namespace fs = std::filesystem;
using bag::Container;
using bag::MessageRef;

namespace {

std::string seconds(double t) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6f s", t);
  return b;
}

// "topic /camera/depth, message 3 (the chunk at byte 4117, byte 96 of its data): "
std::string where(const Container& c, std::size_t message, std::size_t ordinal) {
  const MessageRef& m = c.messages()[message];
  return "topic " + c.topics()[m.topic].name + ", message " + std::to_string(ordinal) + " (" + c.locate(m) + ")";
}

Error at(const Container& c, std::size_t message, std::size_t ordinal, const Error& e) {
  return Error{e.code, where(c, message, ordinal) + ": " + e.message};
}

// The .db3 files of a rosbag2 folder, from metadata.yaml (relative_file_paths).
Result<std::vector<std::string>> rosbag2_files(const fs::path& dir, std::string& storage) {
  const fs::path meta = dir / "metadata.yaml";
  try {
    const YAML::Node root = YAML::LoadFile(meta.string());
    const YAML::Node info = root["rosbag2_bagfile_information"];
    if (!info) return invalid_argument(meta.string() + ": no rosbag2_bagfile_information: not a rosbag2 metadata file");
    storage = info["storage_identifier"] ? info["storage_identifier"].as<std::string>() : "sqlite3";
    std::vector<std::string> files;
    if (info["relative_file_paths"]) {
      for (const auto& f : info["relative_file_paths"]) files.push_back((dir / f.as<std::string>()).string());
    }
    if (files.empty()) return invalid_argument(meta.string() + ": relative_file_paths lists no file");
    return files;
  } catch (const YAML::Exception& e) {
    return invalid_argument(meta.string() + ": " + e.what());
  }
}

Result<std::unique_ptr<Container>> open_container(const fs::path& path, std::string& format) {
  std::error_code ec;
  std::string storage;
  std::vector<std::string> files;
  if (fs::is_directory(path, ec)) {
    auto listed = rosbag2_files(path, storage);
    if (!listed) return listed.error();
    files = std::move(*listed);
  } else if (path.extension() == ".db3") {
    storage = "sqlite3";
    files = {path.string()};
  } else if (path.extension() == ".mcap") {
    storage = "mcap";
    files = {path.string()};
  } else {
    format = "ROS 1 bag";
    return bag::open_ros1_bag(path.string());
  }
  if (storage == "sqlite3") {
    format = "rosbag2 SQLite";
    return bag::open_rosbag2_sqlite(files);
  }
  if (storage == "mcap") {
    format = "MCAP";
    if (files.size() != 1) return invalid_argument(path.string() + ": a rosbag2 MCAP bag split into " + std::to_string(files.size()) + " files is not supported");
    return bag::open_mcap(files[0]);
  }
  return invalid_argument(path.string() + ": rosbag2 storage '" + storage + "' is not supported (sqlite3 and mcap are)");
}

// The stamps of one topic's messages (decoding each message's header).
struct Stamped {
  std::size_t message = 0, ordinal = 0;
  double stamp_s = 0.0;
  std::string frame_id;
};

Result<std::vector<Stamped>> stamps_of(Container& c, int topic, bool cloud) {
  std::vector<Stamped> out;
  std::size_t ordinal = 0;
  for (std::size_t i = 0; i < c.messages().size(); ++i) {
    const MessageRef& m = c.messages()[i];
    if (static_cast<int>(m.topic) != topic) continue;
    auto bytes = c.read(m);
    if (!bytes) return at(c, i, ordinal, bytes.error());
    const bag::WireFormat format = c.topics()[m.topic].format;
    bag::MessageHeader h;
    if (cloud) {
      auto msg = bag::decode_point_cloud2(*bytes, format);
      if (!msg) return at(c, i, ordinal, msg.error());
      h = msg->header;
    } else {
      auto msg = bag::decode_image(*bytes, format);
      if (!msg) return at(c, i, ordinal, msg.error());
      h = msg->header;
    }
    out.push_back({i, ordinal++, h.stamp_s, h.frame_id});
  }
  return out;
}

Status read_tf(Container& c, const std::vector<int>& topics, bag::TfTree& tree) {
  std::vector<std::size_t> ordinal(c.topics().size(), 0);
  for (std::size_t i = 0; i < c.messages().size(); ++i) {
    const MessageRef& m = c.messages()[i];
    if (std::find(topics.begin(), topics.end(), static_cast<int>(m.topic)) == topics.end()) continue;
    const std::size_t k = ordinal[m.topic]++;
    auto bytes = c.read(m);
    if (!bytes) return at(c, i, k, bytes.error());
    auto transforms = bag::decode_tf(*bytes, c.topics()[m.topic].format);
    if (!transforms) return at(c, i, k, transforms.error());
    const std::string& name = c.topics()[m.topic].name;
    const bool is_static = name.size() >= 9 && name.compare(name.size() - 9, 9, "tf_static") == 0;
    for (const auto& t : *transforms) tree.add(t, is_static);
  }
  return {};
}

Result<Intrinsics> read_intrinsics(Container& c, int topic) {
  for (std::size_t i = 0; i < c.messages().size(); ++i) {
    if (static_cast<int>(c.messages()[i].topic) != topic) continue;
    auto bytes = c.read(c.messages()[i]);
    if (!bytes) return at(c, i, 0, bytes.error());
    auto info = bag::decode_camera_info(*bytes, c.topics()[static_cast<std::size_t>(topic)].format);
    if (!info) return at(c, i, 0, info.error());
    auto K = bag::to_intrinsics(*info);
    if (!K) return at(c, i, 0, K.error());
    return K;
  }
  return not_found("topic " + c.topics()[static_cast<std::size_t>(topic)].name + " has no message");
}

}  // namespace

bool is_bag(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return fs::exists(path / "metadata.yaml", ec);
  const auto ext = path.extension();
  return fs::is_regular_file(path, ec) && (ext == ".bag" || ext == ".db3" || ext == ".mcap");
}

Result<Recording> open_bag(const fs::path& path, const BagOptions& options) {
  Recording rec;
  rec.path = path;
  auto container = open_container(path, rec.format);
  if (!container) return container.error();
  rec.container = std::shared_ptr<Container>(std::move(*container));
  Container& c = *rec.container;
  auto choice = bag::choose_topics(c, options);
  if (!choice) return Error{choice.error().code, path.string() + ": " + choice.error().message};
  auto name = [&](int topic) { return topic < 0 ? std::string() : c.topics()[static_cast<std::size_t>(topic)].name; };
  rec.color_topic = name(choice->color);
  rec.depth_topic = name(choice->depth);
  rec.info_topic = name(choice->info);
  rec.cloud_topic = name(choice->cloud);
  auto fail = [&](const Error& e) { return Error{e.code, path.string() + ": " + e.message}; };

  if (choice->info >= 0) {
    auto K = read_intrinsics(c, choice->info);
    if (!K) return fail(K.error());
    rec.intrinsics = *K;
  } else if (choice->depth >= 0) {
    return fail(not_found("no sensor_msgs/CameraInfo topic: the depth camera's intrinsics are unknown"));
  }
  const bool cloud = choice->depth < 0;
  auto depths = stamps_of(c, cloud ? choice->cloud : choice->depth, cloud);
  if (!depths) return fail(depths.error());
  if (depths->empty()) return fail(not_found("topic " + (cloud ? rec.cloud_topic : rec.depth_topic) + " has no message"));
  std::vector<Stamped> colors;
  if (choice->color >= 0) {
    auto s = stamps_of(c, choice->color, false);
    if (!s) return fail(s.error());
    colors = std::move(*s);
  }
  bag::TfTree tree;
  if (auto st = read_tf(c, choice->tf, tree); !st) return fail(st.error());
  rec.camera_frame = options.camera_frame.empty() ? depths->front().frame_id : options.camera_frame;
  if (!tree.empty() || !options.world_frame.empty()) {
    if (!tree.has_frame(rec.camera_frame)) {
      return fail(not_found("the camera frame '" + rec.camera_frame + "' (" +
                            (options.camera_frame.empty() ? "the depth messages' header.frame_id" : std::string("--camera-frame")) +
                            ") is not on /tf or /tf_static; name it with --camera-frame"));
    }
    rec.world_frame = options.world_frame.empty() ? tree.root_of(rec.camera_frame) : options.world_frame;
  } else {
    rec.camera_frame.clear();
  }

  // Colour by nearest stamp, each used once (depth images in stamp order).
  std::vector<bool> used(colors.size(), false);
  std::optional<Error> first_pose_error;
  std::size_t first_pose_error_message = 0;
  for (const Stamped& d : *depths) {
    BagFrame f;
    f.depth_message = d.message;
    f.stamp_s = d.stamp_s;
    if (choice->color >= 0) {
      std::optional<std::size_t> best;
      for (std::size_t k = 0; k < colors.size(); ++k) {
        if (used[k]) continue;
        if (!best || std::abs(colors[k].stamp_s - d.stamp_s) < std::abs(colors[*best].stamp_s - d.stamp_s)) best = k;
      }
      if (!best || std::abs(colors[*best].stamp_s - d.stamp_s) > options.max_time_difference_s) {
        ++rec.skipped_without_color;
        continue;
      }
      used[*best] = true;
      f.color_message = colors[*best].message;
    }
    if (!rec.world_frame.empty()) {
      auto T = tree.lookup(rec.world_frame, rec.camera_frame, d.stamp_s, options.tf_tolerance_s);
      if (!T) {
        if (!first_pose_error) first_pose_error = T.error(), first_pose_error_message = d.ordinal;
        ++rec.skipped_without_pose;
        continue;
      }
      f.T_world_camera = *T;
    }
    rec.frames.push_back(f);
  }
  if (rec.frames.empty()) {
    if (first_pose_error) {
      return fail(Error{first_pose_error->code, "missing TF: no depth message has a pose; topic " + rec.depth_topic + rec.cloud_topic +
                                                    ", message " + std::to_string(first_pose_error_message) + ": " +
                                                    first_pose_error->message});
    }
    return fail(not_found("no depth message has a colour image within " + seconds(options.max_time_difference_s) + " on " +
                          rec.color_topic));
  }
  return rec;
}

std::string skipped_summary(const Recording& rec, const BagOptions& options) {
  std::string out;
  if (rec.skipped_without_color > 0) {
    out += std::to_string(rec.skipped_without_color) + " depth images without a colour image on " + rec.color_topic + " within " +
           seconds(options.max_time_difference_s) + " skipped";
  }
  if (rec.skipped_without_pose > 0) {
    out += (out.empty() ? "" : "; ") + std::to_string(rec.skipped_without_pose) + " without a transform '" + rec.world_frame +
           "' -> '" + rec.camera_frame + "' at their time skipped";
  }
  return out;
}

Result<Frame> load_bag_frame(Recording& rec, std::size_t index) {
  if (index >= rec.frames.size()) return invalid_argument("frame index " + std::to_string(index) + " out of range");
  Container& c = *rec.container;
  const BagFrame& f = rec.frames[index];
  const MessageRef& dm = c.messages()[f.depth_message];
  const std::string source = rec.path.string() + ":" + std::to_string(index);
  auto fail = [&](std::size_t message, const Error& e) {
    const MessageRef& m = c.messages()[message];
    return Error{e.code, source + ": topic " + c.topics()[m.topic].name + " (" + c.locate(m) + "): " + e.message};
  };
  auto depth_bytes = c.read(dm);
  if (!depth_bytes) return fail(f.depth_message, depth_bytes.error());
  Frame frame;
  frame.T_world_camera = f.T_world_camera;
  frame.stamp_s = f.stamp_s;
  frame.source = source;
  if (!rec.cloud_topic.empty()) {
    auto msg = bag::decode_point_cloud2(*depth_bytes, c.topics()[dm.topic].format);
    if (!msg) return fail(f.depth_message, msg.error());
    auto points = bag::to_cloud_frame(*msg, rec.intrinsics);
    if (!points) return fail(f.depth_message, points.error());
    frame.cloud = points->cloud;
    frame.has_color = points->has_color;
    frame.intrinsics = points->intrinsics;
    return frame;
  }
  auto msg = bag::decode_image(*depth_bytes, c.topics()[dm.topic].format);
  if (!msg) return fail(f.depth_message, msg.error());
  std::vector<std::uint8_t> color_bytes;  // the colour message points into it
  std::optional<bag::ImageMessage> color;
  if (f.color_message) {
    const MessageRef& cm = c.messages()[*f.color_message];
    auto bytes = c.read(cm);
    if (!bytes) return fail(*f.color_message, bytes.error());
    color_bytes = std::move(*bytes);
    auto cmsg = bag::decode_image(color_bytes, c.topics()[cm.topic].format);
    if (!cmsg) return fail(*f.color_message, cmsg.error());
    color = std::move(*cmsg);
  }
  bool color_at_fault = false;
  auto rgbd = bag::to_rgbd_cloud(*msg, color ? &*color : nullptr, *rec.intrinsics, rec.info_topic, &color_at_fault);
  if (!rgbd) return fail(color_at_fault ? *f.color_message : f.depth_message, rgbd.error());
  frame.cloud = rgbd->cloud;
  frame.intrinsics = rgbd->intrinsics;
  frame.has_color = rgbd->has_color;
  return frame;
}

}  // namespace scenewatch::io
