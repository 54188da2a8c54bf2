#include "appearance_stage.h"

#include <mutex>

#include "scenewatch/io/cloud_io.h"
#include "timing.h"

namespace scenewatch::pipeline {
namespace {

// The frame as an image (colour, depth, pose, intrinsics): keyframe_from_frame checks that it is
// organized and has intrinsics; the image path also needs colour.
Result<background::Keyframe> as_image(const Frame& frame) {
  if (!frame.has_color) {
    const std::string where = frame.source.empty() ? std::string("frame") : "frame from '" + frame.source + "'";
    return invalid_argument(where + ": surprise needs colour");
  }
  return background::keyframe_from_frame(frame);
}

}  // namespace

AppearanceStage::AppearanceStage(const background::AppearanceConfig& appearance, const surprise::SurpriseConfig& surprise)
    : appearance_config_(appearance), config_(surprise), kernel_(surprise.prior, surprise.min_samples), memory_(appearance) {}

Result<std::shared_ptr<SurpriseResult>> AppearanceStage::compute(const Frame& frame, const background::Keyframe& observed,
                                                                 const std::vector<std::shared_ptr<const surprise::KnownSurface>>& known) const {
  const auto t0 = Clock::now();
  const Pose pose = frame.pose_or_identity();
  auto result = std::make_shared<SurpriseResult>();
  surprise::ExpectedView view = surprise::render_expected_view(memory_, pose, *frame.intrinsics, config_.view);
  // Described objects' completed surfaces: their sides the keyframes never saw (issue 13).
  for (const auto& surface : known) result->known_surface_pixels += surprise::splat_surface(view, *surface, config_.view.depth_tolerance_m);
  auto map = surprise::compute_surprise(view, observed.color, kernel_, &config_.robust);
  if (!map) return map.error();
  for (const auto& region : surprise::find_regions(*map, view, &observed.depth, config_.regions)) {
    result->events.push_back(surprise::to_event(region, frame.stamp_s));
  }
  result->map = std::move(*map);
  result->reference_views = view.reference_views;
  result->T_world_camera = pose;
  result->intrinsics = *frame.intrinsics;
  result->stamp_s = frame.stamp_s;
  result->ms = ms_since(t0);
  return result;
}

bool AppearanceStage::familiar(const Pose& T_world_camera) const {
  for (const auto& kf : memory_.keyframes()) {
    auto it = added_at_.find(kf->id);
    const std::uint64_t added = it == added_at_.end() ? 0 : it->second;  // loaded from disk: old
    if (frames_ - added < static_cast<std::uint64_t>(config_.familiar_after_frames)) continue;
    const background::ViewDistance d = background::view_distance(kf->T_world_camera, T_world_camera);
    if (d.translation_m <= 2 * appearance_config_.keyframe_min_translation_m &&
        d.rotation_deg <= 2 * appearance_config_.keyframe_min_rotation_deg)
      return true;
  }
  return false;
}

std::shared_ptr<const SurpriseResult> AppearanceStage::process(const Frame& frame,
                                                              const std::vector<std::shared_ptr<const surprise::KnownSurface>>& known,
                                                              std::uint32_t camera) {
  if (!appearance_config_.enabled && !config_.enabled) return nullptr;
  // Without a pose the camera frame would be taken as the world: keyframes from a moving camera
  // would then be placed wrongly, so only posed frames take part.
  if (!frame.T_world_camera) return nullptr;
  auto observed = as_image(frame);
  if (!observed) return nullptr;
  std::shared_ptr<const SurpriseResult> result;
  {
    std::shared_lock<std::shared_mutex> read(mutex_);
    if (config_.enabled && memory_.size() > 0) {
      auto computed = compute(frame, *observed, known);
      if (computed) {
        (*computed)->familiar_view = familiar(observed->T_world_camera);
        result = std::move(*computed);
      }
    }
  }
  std::unique_lock<std::shared_mutex> write(mutex_);
  if (result) last_ = result;
  int& streak = changed_streak_[camera];
  streak = (result && !result->events.empty()) ? streak + 1 : 0;
  ++frames_;
  if (!appearance_config_.enabled) return result;
  if (config_.adopt_after_frames > 0 && streak >= config_.adopt_after_frames &&
      !memory_.is_new_view(observed->T_world_camera)) {
    // The change held for long enough from a view the memory holds: remember it.
    if (auto id = memory_.replace_nearest(std::move(*observed))) added_at_[*id] = frames_;
    streak = 0;
  } else if (memory_.is_new_view(observed->T_world_camera)) {
    // A new view becomes a keyframe (what AppearanceMemory::consider does, keeping the id).
    if (auto id = memory_.add(std::move(*observed))) added_at_[*id] = frames_;
  }
  // Forget the frames of evicted keyframes.
  if (added_at_.size() > 2 * memory_.size() + 16) {
    std::map<std::uint64_t, std::uint64_t> live;
    for (const auto& kf : memory_.keyframes()) {
      auto it = added_at_.find(kf->id);
      if (it != added_at_.end()) live.insert(*it);
    }
    added_at_.swap(live);
  }
  return result;
}

void AppearanceStage::forget_camera(std::uint32_t camera) {
  std::unique_lock<std::shared_mutex> write(mutex_);
  changed_streak_.erase(camera);
}

Result<std::shared_ptr<const SurpriseResult>> AppearanceStage::evaluate(const Frame& observation) const {
  auto observed = as_image(observation);
  if (!observed) return observed.error();
  std::shared_lock<std::shared_mutex> read(mutex_);
  if (memory_.size() == 0) return not_found("the appearance memory has no keyframes yet: ingest posed RGB-D frames first");
  auto computed = compute(observation, *observed);
  if (!computed) return computed.error();
  return std::shared_ptr<const SurpriseResult>(std::move(*computed));
}

std::shared_ptr<const SurpriseResult> AppearanceStage::last() const {
  std::shared_lock<std::shared_mutex> read(mutex_);
  return last_;
}

Status AppearanceStage::write_mesh(const std::filesystem::path& path) const {
  ColoredMesh mesh;
  {
    std::shared_lock<std::shared_mutex> read(mutex_);
    mesh = memory_.mesh();
  }
  if (mesh.empty()) return not_found("the appearance memory has no mesh yet: ingest posed RGB-D frames first");
  return io::write_mesh_ply(path, mesh);
}

Status AppearanceStage::save(const std::filesystem::path& dir) const {
  std::shared_lock<std::shared_mutex> read(mutex_);
  if (auto st = memory_.save(dir / "keyframes"); !st) return st;
  const ColoredMesh mesh = memory_.mesh();
  if (!mesh.empty()) return io::write_mesh_ply(dir / "mesh.ply", mesh);
  return {};
}

Status AppearanceStage::load(const std::filesystem::path& dir) {
  background::AppearanceMemory loaded(appearance_config_);
  if (auto st = loaded.load(dir / "keyframes"); !st) return st;
  std::unique_lock<std::shared_mutex> write(mutex_);
  memory_ = std::move(loaded);
  last_.reset();
  added_at_.clear();  // loaded keyframes count as old: their views are familiar
  return {};
}

void AppearanceStage::reset() {
  std::unique_lock<std::shared_mutex> write(mutex_);
  memory_.clear();
  last_.reset();
  changed_streak_.clear();
  added_at_.clear();
}

std::vector<std::shared_ptr<const background::Keyframe>> AppearanceStage::nearest(const Pose& T_world_camera, std::size_t n) const {
  std::shared_lock<std::shared_mutex> read(mutex_);
  return memory_.nearest(T_world_camera, n);
}

std::vector<std::shared_ptr<const background::Keyframe>> AppearanceStage::all_keyframes() const {
  std::shared_lock<std::shared_mutex> read(mutex_);
  return memory_.keyframes();
}

std::size_t AppearanceStage::keyframes() const {
  std::shared_lock<std::shared_mutex> read(mutex_);
  return memory_.size();
}
std::size_t AppearanceStage::triangles() const {
  std::shared_lock<std::shared_mutex> read(mutex_);
  return memory_.triangle_count();
}
std::size_t AppearanceStage::memory_bytes() const {
  std::shared_lock<std::shared_mutex> read(mutex_);
  return memory_.memory_bytes();
}

}  // namespace scenewatch::pipeline
