// Sequence folders: frame-NNNNNN.color.{png,jpg} and frame-NNNNNN.depth.png with per-frame 4x4 poses
// or a TUM trajectory.
#include <algorithm>
#include <system_error>

#include "scenewatch/io/cloud_io.h"
#include "scenewatch/io/image_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/io/sequence.h"

namespace scenewatch::io {
namespace fs = std::filesystem;

namespace {
// Colour as recorded: PNG (7-Scenes, the simulator) or JPEG (many robot recordings, hrt1).
constexpr const char* kColorSuffixes[] = {".color.png", ".color.jpg", ".color.jpeg"};
constexpr double kDefaultFrameRateHz = 30.0;

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

struct FrameName {
  std::string name;   ///< "frame-000150"
  std::string color;  ///< its colour file's name
  bool operator<(const FrameName& o) const { return name < o.name; }
};

std::vector<FrameName> frame_names(const fs::path& dir) {
  std::vector<FrameName> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string file = entry.path().filename().string();
    if (!entry.is_regular_file(ec)) continue;
    for (const std::string suffix : kColorSuffixes) {
      if (ends_with(file, suffix)) names.push_back({file.substr(0, file.size() - suffix.size()), file});
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}
}  // namespace

bool is_sequence_dir(const fs::path& path) {
  std::error_code ec;
  return fs::is_directory(path, ec) && !frame_names(path).empty();
}

Result<Sequence> open_sequence(const fs::path& dir) {
  std::error_code ec;
  const std::string where = "'" + dir.string() + "'";
  if (!fs::exists(dir, ec)) return not_found(where + ": no such directory");
  if (!fs::is_directory(dir, ec)) return invalid_argument(where + ": not a directory");
  Sequence seq;
  seq.dir = dir;
  const auto names = frame_names(dir);
  if (names.empty()) return invalid_argument(where + ": no frame-*.color.png or .color.jpg files; not a sequence folder");
  for (std::size_t i = 1; i < names.size(); ++i) {
    if (names[i].name == names[i - 1].name) {
      return invalid_argument(where + ": " + names[i].name + " has two colour images ('" + names[i - 1].color + "', '" +
                              names[i].color + "'); keep one");
    }
  }

  auto K = read_intrinsics(dir / "camera-intrinsics.txt");
  if (!K) return K.error();
  seq.intrinsics = *K;

  for (const auto& [name, color] : names) {
    SequenceEntry e;
    e.name = name;
    e.color = dir / color;
    e.depth = dir / (name + ".depth.png");
    if (!fs::exists(e.depth, ec)) return invalid_argument("'" + e.depth.string() + "': missing depth image for " + name);
    seq.frames.push_back(std::move(e));
  }

  auto size = read_png_size(seq.frames.front().depth);
  if (!size) return size.error();
  seq.intrinsics.width = size->first;
  seq.intrinsics.height = size->second;

  // Poses: per-frame 4x4 files (7-Scenes) take precedence over a trajectory file.
  const bool per_frame_poses = std::all_of(seq.frames.begin(), seq.frames.end(), [&](const SequenceEntry& e) {
    return fs::exists(dir / (e.name + ".pose.txt"), ec);
  });
  fs::path trajectory;
  for (const char* candidate : {"trajectory.txt", "groundtruth.txt"}) {
    if (fs::exists(dir / candidate, ec)) {
      trajectory = dir / candidate;
      break;
    }
  }
  for (std::size_t i = 0; i < seq.frames.size(); ++i) seq.frames[i].stamp_s = i / kDefaultFrameRateHz;
  if (per_frame_poses) {
    for (auto& e : seq.frames) {
      auto pose = read_pose_matrix(dir / (e.name + ".pose.txt"));
      if (!pose) return pose.error();
      e.T_world_camera = *pose;
    }
  } else if (!trajectory.empty()) {
    auto poses = read_tum(trajectory);
    if (!poses) return poses.error();
    if (poses->size() != seq.frames.size()) {
      return invalid_argument("'" + trajectory.string() + "': " + std::to_string(poses->size()) + " poses for " +
                              std::to_string(seq.frames.size()) + " frames; expected one line per frame, in order");
    }
    for (std::size_t i = 0; i < poses->size(); ++i) {
      seq.frames[i].T_world_camera = (*poses)[i].T_world_camera;
      seq.frames[i].stamp_s = (*poses)[i].stamp_s;
    }
  }
  return seq;
}

Result<Frame> load_sequence_frame(const Sequence& seq, std::size_t index) {
  if (index >= seq.frames.size()) return invalid_argument("frame index " + std::to_string(index) + " out of range");
  const SequenceEntry& e = seq.frames[index];
  auto color = read_color_png(e.color);
  if (!color) return color.error();
  auto depth = read_depth_png(e.depth);
  if (!depth) return depth.error();
  Intrinsics K = seq.intrinsics;
  K.width = depth->width;
  K.height = depth->height;
  auto cloud = rgbd_to_cloud(*color, *depth, K);
  if (!cloud) return Error{cloud.error().code, e.name + ": " + cloud.error().message};
  Frame frame;
  frame.cloud = *cloud;
  frame.T_world_camera = e.T_world_camera;
  frame.intrinsics = K;
  frame.stamp_s = e.stamp_s;
  frame.has_color = true;
  frame.source = e.color.string();
  return frame;
}

Result<Frame> load_cloud_frame(const fs::path& path) {
  auto file = read_cloud(path);
  if (!file) return file.error();
  Frame frame;
  CloudPtr cloud = file->cloud;
  // PCD's VIEWPOINT is the sensor's pose in the cloud's frame. When it is not the identity, the
  // cloud's frame is our world frame: keep that pose and express the points in the camera frame.
  Pose T_world_camera = Pose::Identity();
  T_world_camera.linear() = cloud->sensor_orientation_.cast<double>().normalized().toRotationMatrix();
  T_world_camera.translation() = file->sensor_origin;
  if (!T_world_camera.isApprox(Pose::Identity())) {
    const Eigen::Isometry3f T_camera_world = T_world_camera.inverse().cast<float>();
    for (auto& p : cloud->points) {
      if (is_valid(p)) p.getVector3fMap() = T_camera_world * p.getVector3fMap();
    }
    frame.T_world_camera = T_world_camera;
  }
  cloud->sensor_origin_ = Eigen::Vector4f::Zero();
  cloud->sensor_orientation_ = Eigen::Quaternionf::Identity();
  frame.cloud = cloud;
  frame.has_color = file->has_color;
  frame.source = path.string();
  return frame;
}

}  // namespace scenewatch::io
