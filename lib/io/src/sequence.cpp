// Sequence folders: frame-NNNNNN.color.{png,jpg} and frame-NNNNNN.depth.png with per-frame 4x4 poses
// or a TUM trajectory; or the TUM RGB-D benchmark's rgb.txt, depth.txt and groundtruth.txt.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <system_error>

#include "scenewatch/core/files.h"
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


constexpr const char* kTumColorList = "rgb.txt";
constexpr const char* kTumDepthList = "depth.txt";
constexpr const char* kTumGroundTruth = "groundtruth.txt";
constexpr const char* kDepthScaleFile = "depth-scale.txt";

bool has_file(const fs::path& path) {
  std::error_code ec;
  return fs::exists(path, ec);
}

// The depth unit: the caller's, else depth-scale.txt, else the layout's.
Status read_scale(const fs::path& dir, const SequenceOptions& options, double layout_unit_m, Sequence& seq) {
  if (options.depth_scale_m) {
    if (auto st = validate_depth_scale(*options.depth_scale_m, "--depth-scale"); !st) return st;
    seq.depth_scale_m = *options.depth_scale_m;
    return {};
  }
  seq.depth_scale_m = layout_unit_m;
  if (!has_file(dir / kDepthScaleFile)) return {};
  auto scale = read_depth_scale(dir / kDepthScaleFile);
  if (!scale) return scale.error();
  seq.depth_scale_m = *scale;
  return {};
}

Status fill_image_size(Sequence& seq) {
  auto size = read_png_size(seq.frames.front().depth);
  if (!size) return size.error();
  seq.intrinsics.width = size->first;
  seq.intrinsics.height = size->second;
  return {};
}

// frame-NNNNNN.color.{png,jpg} + .depth.png, poses per frame or one trajectory line per frame.
Result<Sequence> open_frames_layout(const fs::path& dir, const SequenceOptions& options) {
  std::error_code ec;
  const std::string where = "'" + dir.string() + "'";
  Sequence seq;
  seq.dir = dir;
  seq.layout = SequenceLayout::kFrames;
  const auto names = frame_names(dir);
  for (std::size_t i = 1; i < names.size(); ++i) {
    if (names[i].name == names[i - 1].name) {
      return invalid_argument(where + ": " + names[i].name + " has two colour images ('" + names[i - 1].color + "', '" +
                              names[i].color + "'); keep one");
    }
  }

  auto K = read_intrinsics(dir / "camera-intrinsics.txt");
  if (!K) return K.error();
  seq.intrinsics = *K;
  if (auto st = read_scale(dir, options, kDepthMillimetres, seq); !st) return st.error();

  for (const auto& [name, color] : names) {
    SequenceEntry e;
    e.name = name;
    e.color = dir / color;
    e.depth = dir / (name + ".depth.png");
    if (!fs::exists(e.depth, ec)) return invalid_argument("'" + e.depth.string() + "': missing depth image for " + name);
    seq.frames.push_back(std::move(e));
  }
  if (auto st = fill_image_size(seq); !st) return st.error();

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

// A TUM image list, sorted by time, every listed file checked to exist.
Result<std::vector<StampedFile>> read_image_list(const fs::path& dir, const char* list_name) {
  const fs::path list = dir / list_name;
  if (!has_file(list)) {
    return not_found(quoted(list) + ": missing; a TUM RGB-D folder has rgb.txt, depth.txt and (for poses) groundtruth.txt");
  }
  auto files = read_tum_list(list);
  if (!files) return files.error();
  for (const auto& f : *files) {
    if (!has_file(dir / f.file)) {
      return not_found(quoted(list) + " line " + std::to_string(f.line) + ": '" + f.file.string() + "' does not exist");
    }
  }
  std::stable_sort(files->begin(), files->end(), [](const StampedFile& a, const StampedFile& b) { return a.stamp_s < b.stamp_s; });
  return files;
}

// Index of the stamp nearest to t in a sorted list, or -1 when none is within max_dt.
template <typename T, typename StampOf>
std::ptrdiff_t nearest(const std::vector<T>& sorted, double t, double max_dt, StampOf stamp_of) {
  auto it = std::lower_bound(sorted.begin(), sorted.end(), t, [&](const T& x, double v) { return stamp_of(x) < v; });
  std::ptrdiff_t best = -1;
  double best_dt = max_dt;
  for (auto c : {it, it == sorted.begin() ? it : std::prev(it)}) {
    if (c == sorted.end()) continue;
    const double dt = std::abs(stamp_of(*c) - t);
    if (dt <= best_dt) {
      best_dt = dt;
      best = c - sorted.begin();
    }
  }
  return best;
}

Result<Sequence> open_tum_layout(const fs::path& dir, const SequenceOptions& options) {
  if (!(options.max_time_difference_s >= 0)) return invalid_argument("the association tolerance must be >= 0 s");
  Sequence seq;
  seq.dir = dir;
  seq.layout = SequenceLayout::kTum;
  auto colors = read_image_list(dir, kTumColorList);
  if (!colors) return colors.error();
  auto depths = read_image_list(dir, kTumDepthList);
  if (!depths) return depths.error();
  if (has_file(dir / "camera-intrinsics.txt")) {
    auto K = read_intrinsics(dir / "camera-intrinsics.txt");
    if (!K) return K.error();
    seq.intrinsics = *K;
  } else {
    seq.intrinsics.fx = seq.intrinsics.fy = 525.0;  // TUM's default for the ROS driver's registered images
    seq.intrinsics.cx = 319.5;
    seq.intrinsics.cy = 239.5;
  }
  if (auto st = read_scale(dir, options, kDepthTum, seq); !st) return st.error();
  std::optional<std::vector<StampedPose>> poses;
  if (has_file(dir / kTumGroundTruth)) {
    auto read = read_tum(dir / kTumGroundTruth);
    if (!read) return read.error();
    poses = std::move(*read);
    std::stable_sort(poses->begin(), poses->end(), [](const auto& a, const auto& b) { return a.stamp_s < b.stamp_s; });
  }

  // Colour to depth as TUM's associate.py: the candidate pairs within the tolerance, closest first,
  // each image used once.
  const double tol = options.max_time_difference_s;
  struct Pair {
    double dt;
    std::size_t color, depth;
  };
  std::vector<Pair> candidates;
  for (std::size_t c = 0; c < colors->size(); ++c) {
    const double t = (*colors)[c].stamp_s;
    auto it = std::lower_bound(depths->begin(), depths->end(), t - tol,
                               [](const StampedFile& f, double v) { return f.stamp_s < v; });
    for (; it != depths->end() && it->stamp_s <= t + tol; ++it) {
      candidates.push_back({std::abs(it->stamp_s - t), c, static_cast<std::size_t>(it - depths->begin())});
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const Pair& a, const Pair& b) { return a.dt < b.dt; });
  std::vector<std::ptrdiff_t> depth_of(colors->size(), -1);
  std::vector<bool> depth_used(depths->size(), false);
  for (const Pair& p : candidates) {
    if (depth_of[p.color] >= 0 || depth_used[p.depth]) continue;
    depth_of[p.color] = static_cast<std::ptrdiff_t>(p.depth);
    depth_used[p.depth] = true;
  }

  for (std::size_t c = 0; c < colors->size(); ++c) {
    if (depth_of[c] < 0) {
      ++seq.skipped_without_depth;
      continue;
    }
    const StampedFile& depth = (*depths)[static_cast<std::size_t>(depth_of[c])];
    SequenceEntry e;
    e.name = (*colors)[c].file.stem().string();
    e.color = dir / (*colors)[c].file;
    e.depth = dir / depth.file;
    e.stamp_s = depth.stamp_s;  // the points come from the depth image
    if (poses) {
      const auto k = nearest(*poses, depth.stamp_s, tol, [](const StampedPose& p) { return p.stamp_s; });
      if (k < 0) {
        ++seq.skipped_without_pose;
        continue;
      }
      e.T_world_camera = (*poses)[static_cast<std::size_t>(k)].T_world_camera;
    }
    seq.frames.push_back(std::move(e));
  }
  if (seq.frames.empty()) {
    std::ostringstream os;
    os << "'" << dir.string() << "': no frame has colour, depth" << (poses ? " and pose" : "") << " within " << tol
       << " s of each other (" << skipped_summary(seq, options) << ")";
    return invalid_argument(os.str());
  }
  if (auto st = fill_image_size(seq); !st) return st.error();
  return seq;
}

}  // namespace

bool is_sequence_dir(const fs::path& path) {
  std::error_code ec;
  return fs::is_directory(path, ec) && (!frame_names(path).empty() || has_file(path / kTumColorList));
}

Result<Sequence> open_sequence(const fs::path& dir, const SequenceOptions& options) {
  std::error_code ec;
  const std::string where = "'" + dir.string() + "'";
  if (!fs::exists(dir, ec)) return not_found(where + ": no such directory");
  if (!fs::is_directory(dir, ec)) return invalid_argument(where + ": not a directory");
  if (!frame_names(dir).empty()) return open_frames_layout(dir, options);
  if (has_file(dir / kTumColorList)) return open_tum_layout(dir, options);
  return invalid_argument(where + ": no frame-*.color.png or .color.jpg files and no TUM rgb.txt; not a sequence folder");
}

std::string skipped_summary(const Sequence& seq, const SequenceOptions& options) {
  std::ostringstream os;
  const auto say = [&](std::size_t n, const char* what) {
    if (n == 0) return;
    if (os.tellp() > 0) os << "; ";
    os << n << (n == 1 ? " colour image" : " colour images") << " without " << what << " within "
       << options.max_time_difference_s << " s skipped";
  };
  say(seq.skipped_without_depth, "a depth image");
  say(seq.skipped_without_pose, "a ground-truth pose");
  return os.str();
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
  auto cloud = rgbd_to_cloud(*color, *depth, K, seq.depth_scale_m);
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
