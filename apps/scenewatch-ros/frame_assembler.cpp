#include "frame_assembler.h"

#include <cmath>

namespace scenewatch::ros {
namespace {

constexpr std::size_t kMaxUnpaired = 8;  ///< images kept per stream while their partner is awaited
constexpr double kTfHistoryS = 10.0;     ///< /tf kept this long behind the newest image

}  // namespace

io::bag::ImageMessage image_view(const RawImage& image) {
  io::bag::ImageMessage m;
  m.header.stamp_s = image.stamp_s;
  m.header.frame_id = image.frame_id;
  m.width = image.width;
  m.height = image.height;
  m.step = image.step;
  m.encoding = image.encoding;
  m.big_endian = image.big_endian;
  m.data = image.data.data();
  m.size = image.data.size();
  return m;
}

io::bag::PointCloud2Message cloud_view(const RawCloud& cloud) {
  io::bag::PointCloud2Message m;
  m.header.stamp_s = cloud.stamp_s;
  m.header.frame_id = cloud.frame_id;
  m.width = cloud.width;
  m.height = cloud.height;
  m.fields = cloud.fields;
  m.big_endian = cloud.big_endian;
  m.point_step = cloud.point_step;
  m.row_step = cloud.row_step;
  m.data = cloud.data.data();
  m.size = cloud.data.size();
  return m;
}

FrameAssembler::FrameAssembler(const BridgeConfig& config, BridgeStats& stats, std::function<void(FrameJob)> emit,
                               std::function<void(const std::string&)> log)
    : config_(config), stats_(stats), emit_(std::move(emit)), log_(std::move(log)) {}

void FrameAssembler::drop(const std::string& reason, double stamp_s, const std::string& why) {
  const auto n = stats_.count("dropped." + reason);
  if (worth_logging(n)) log_("dropped the frame of " + seconds(stamp_s) + " s (" + reason + ", " + std::to_string(n) + " so far): " + why);
}

void FrameAssembler::drop_without_color(double stamp_s) {
  drop("no_color", stamp_s, "no colour image on " + config_.color_topic + " within " + seconds(config_.sync_tolerance_s) +
                                " s of its stamp");
}

void FrameAssembler::set_intrinsics(Result<Intrinsics> intrinsics) {
  if (!intrinsics) {
    const auto n = stats_.count("bad_camera_info");
    if (worth_logging(n)) log_("ignored a CameraInfo on " + config_.info_topic + ": " + intrinsics.error().message);
    return;
  }
  intrinsics_ = *intrinsics;
}

void FrameAssembler::add_depth(RawImage image) {
  stats_.count("depth_in");
  depths_.push_back(std::move(image));
  if (depths_.size() > kMaxUnpaired) {
    drop_without_color(depths_.front().stamp_s);
    depths_.pop_front();
  }
  try_pair();
}

void FrameAssembler::add_color(RawImage image) {
  stats_.count("color_in");
  colors_.push_back(std::move(image));
  if (colors_.size() > kMaxUnpaired) colors_.pop_front();  // colour without depth is no frame: not counted
  try_pair();
}

void FrameAssembler::add_cloud(RawCloud cloud) {
  stats_.count("cloud_in");
  FrameJob job;
  job.arrived = cloud.arrived;
  job.cloud = std::move(cloud);
  job.intrinsics = intrinsics_;
  place(std::move(job));
}

void FrameAssembler::try_pair() {
  while (!depths_.empty()) {
    RawImage& depth = depths_.front();
    std::optional<RawImage> color;
    if (!config_.color_topic.empty()) {
      auto best = colors_.end();
      for (auto it = colors_.begin(); it != colors_.end(); ++it) {
        if (std::abs(it->stamp_s - depth.stamp_s) > config_.sync_tolerance_s) continue;
        if (best == colors_.end() || std::abs(it->stamp_s - depth.stamp_s) < std::abs(best->stamp_s - depth.stamp_s)) best = it;
      }
      if (best == colors_.end()) {
        // Its colour may still come; a newer colour image than this depth says it will not.
        const bool passed = !colors_.empty() && colors_.back().stamp_s > depth.stamp_s + config_.sync_tolerance_s;
        if (!passed) return;
        drop_without_color(depth.stamp_s);
        depths_.pop_front();
        continue;
      }
      color = std::move(*best);
      colors_.erase(colors_.begin(), best + 1);  // older colour images have no depth partner any more
    }
    FrameJob job;
    job.arrived = color && color->arrived > depth.arrived ? color->arrived : depth.arrived;
    job.depth = std::move(depth);
    job.color = std::move(color);
    depths_.pop_front();
    if (!intrinsics_) {
      drop("no_camera_info", job.depth.stamp_s, "no CameraInfo received on " + config_.info_topic + " yet");
      continue;
    }
    job.intrinsics = intrinsics_;
    place(std::move(job));
  }
}

void FrameAssembler::place(FrameJob job) {
  const double stamp = job.stamp_s();
  tf_.forget_before(stamp - kTfHistoryS);
  auto pose = lookup_pose(job);
  if (pose) {
    job.T_world_camera = *pose;
    if (waiting_) drop("no_tf", waiting_->stamp_s(), waiting_error_ + " (a newer frame found its TF first)");
    waiting_.reset();
    emit_(std::move(job));
    return;
  }
  if (config_.without_tf == WithoutTf::kTrack) {
    stats_.count("sent_without_tf");
    emit_(std::move(job));
    return;
  }
  if (waiting_) drop("no_tf", waiting_->stamp_s(), waiting_error_);
  waiting_error_ = pose.error().message;
  waiting_ = std::move(job);
}

void FrameAssembler::retry_waiting() {
  if (!waiting_) return;
  if (Clock::now() - waiting_->arrived > std::chrono::duration<double>(config_.tf_wait_s)) {
    drop("no_tf", waiting_->stamp_s(), waiting_error_ + " (waited " + seconds(config_.tf_wait_s) + " s)");
    waiting_.reset();
    return;
  }
  auto pose = lookup_pose(*waiting_);
  if (!pose) {
    waiting_error_ = pose.error().message;
    return;
  }
  waiting_->T_world_camera = *pose;
  FrameJob job = std::move(*waiting_);
  waiting_.reset();
  emit_(std::move(job));
}

Result<Pose> FrameAssembler::lookup_pose(const FrameJob& job) const {
  const std::string& camera = config_.camera_frame.empty() ? job.frame_id() : config_.camera_frame;
  return tf_.lookup(pose_frame(config_), camera, job.stamp_s(), config_.tf_tolerance_s);
}

void FrameAssembler::add_transform(const io::bag::StampedTransform& t, bool is_static) {
  tf_.add(t, is_static);
  retry_waiting();
}

}  // namespace scenewatch::ros
