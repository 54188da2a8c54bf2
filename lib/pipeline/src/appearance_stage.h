#pragma once
// The pipeline's appearance path: expected view at the frame's pose, Bayesian surprise, regions
// as APPEARANCE_CHANGE events, then the keyframe memory is updated. Thread safe: process() and
// the writers are serialised by the working memory; readers (surprise of an observation, the
// last map, the mesh) take a shared lock.
#include <filesystem>
#include <map>
#include <memory>
#include <shared_mutex>

#include "scenewatch/background/appearance.h"
#include "scenewatch/core/result.h"
#include "scenewatch/pipeline/surprise_result.h"
#include "scenewatch/surprise/surprise_map.h"

namespace scenewatch::pipeline {

class AppearanceStage {
 public:
  AppearanceStage(const background::AppearanceConfig& appearance, const surprise::SurpriseConfig& surprise);

  /// A frame with a pose, intrinsics and an organized colour cloud: its surprise against the
  /// memory (when the memory has keyframes; the expected view with the `known` surfaces splatted
  /// in), then the keyframe update. Other frames are skipped (null result). Events come without ids.
  /// `camera` names the frame's camera: a change is adopted after `adopt_after_frames` frames of
  /// one camera in a row that saw it.
  std::shared_ptr<const SurpriseResult> process(const Frame& frame,
                                                const std::vector<std::shared_ptr<const surprise::KnownSurface>>& known = {},
                                                std::uint32_t camera = 0);
  /// Up to n keyframes seeing towards a pose, nearest first (for localization).
  std::vector<std::shared_ptr<const background::Keyframe>> nearest(const Pose& T_world_camera, std::size_t n) const;
  /// Every keyframe (for relocalization and the keyframe features saved with the model).
  std::vector<std::shared_ptr<const background::Keyframe>> all_keyframes() const;
  /// Forgets what is kept of a camera that is no longer followed.
  void forget_camera(std::uint32_t camera);

  /// The surprise of an observation against the memory; nothing changes.
  Result<std::shared_ptr<const SurpriseResult>> evaluate(const Frame& observation) const;
  std::shared_ptr<const SurpriseResult> last() const;

  Status write_mesh(const std::filesystem::path& path) const;
  Status save(const std::filesystem::path& dir) const;
  /// Replaces the keyframes by those in dir; on error nothing changes.
  Status load(const std::filesystem::path& dir);
  void reset();
  std::size_t keyframes() const;
  std::size_t triangles() const;
  std::size_t memory_bytes() const;

 private:
  Result<std::shared_ptr<SurpriseResult>> compute(const Frame& frame, const background::Keyframe& observed,
                                                  const std::vector<std::shared_ptr<const surprise::KnownSurface>>& known = {}) const;
  /// A keyframe within twice the keyframe spacing, taken at least familiar_after_frames before.
  /// The caller holds mutex_.
  bool familiar(const Pose& T_world_camera) const;

  background::AppearanceConfig appearance_config_;
  surprise::SurpriseConfig config_;
  surprise::SurpriseKernel kernel_;
  mutable std::shared_mutex mutex_;
  background::AppearanceMemory memory_;
  std::shared_ptr<const SurpriseResult> last_;
  std::map<std::uint32_t, int> changed_streak_;  ///< per camera: its consecutive frames with regions (writer only)
  std::uint64_t frames_ = 0;  ///< posed colour frames seen (writer only)
  std::map<std::uint64_t, std::uint64_t> added_at_;  ///< keyframe id -> frames_ when it was taken
};

}  // namespace scenewatch::pipeline
