#include "scenewatch/sim/sequence_writer.h"

#include <cstdio>
#include <system_error>

#include "scenewatch/io/image_io.h"
#include "scenewatch/io/rgbd.h"

namespace scenewatch::sim {
namespace fs = std::filesystem;

std::string frame_name(int index) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "frame-%06d", index);
  return buf;
}

Result<SequenceWriter> SequenceWriter::create(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return io_error(dir.string() + ": cannot create the folder: " + ec.message());
  if (!fs::is_directory(dir)) return io_error(dir.string() + ": not a folder");
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    const bool frame_file = name.rfind("frame-", 0) == 0 &&
                            (name.size() > 10 && (name.compare(name.size() - 10, 10, ".color.png") == 0 ||
                                                  name.compare(name.size() - 10, 10, ".depth.png") == 0 ||
                                                  name.compare(name.size() - 10, 10, ".label.png") == 0 ||
                                                  name.compare(name.size() - 9, 9, ".pose.txt") == 0));
    const bool meta = name == "trajectory.txt" || name == "camera-intrinsics.txt" || name == "ground_truth.json";
    if (entry.is_regular_file() && (frame_file || meta)) {
      fs::remove(entry.path(), ec);
      if (ec) return io_error(entry.path().string() + ": cannot remove the stale file: " + ec.message());
    }
  }
  if (ec) return io_error(dir.string() + ": cannot list the folder: " + ec.message());
  return SequenceWriter(dir);
}

Status SequenceWriter::write_frame(int index, double stamp_s, const ColorImage& color, const DepthImage& depth,
                                   const LabelImage& labels, const Pose& T_world_camera) {
  const std::string base = frame_name(index);
  if (auto st = io::write_color_png(dir_ / (base + ".color.png"), color); !st) return st;
  if (auto st = io::write_depth_png(dir_ / (base + ".depth.png"), depth); !st) return st;
  if (auto st = io::write_label_png(dir_ / (base + ".label.png"), labels); !st) return st;
  if (auto st = io::write_pose_matrix(dir_ / (base + ".pose.txt"), T_world_camera); !st) return st;
  poses_.emplace_back(stamp_s, T_world_camera);
  return {};
}

Status SequenceWriter::finish(const Intrinsics& K, const SequenceTruth& truth) {
  std::vector<io::StampedPose> trajectory;
  trajectory.reserve(poses_.size());
  for (const auto& [stamp, pose] : poses_) trajectory.push_back({stamp, pose});
  if (auto st = io::write_tum(dir_ / "trajectory.txt", trajectory); !st) return st;
  if (auto st = io::write_intrinsics(dir_ / "camera-intrinsics.txt", K); !st) return st;
  return write_ground_truth(dir_ / "ground_truth.json", truth);
}

}  // namespace scenewatch::sim
