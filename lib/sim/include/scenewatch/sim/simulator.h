#pragma once
/// The simulator's facade: animates every phase of a scenario, renders frames through the ray
/// caster and the sensor model, and writes the sequences with their ground truth.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "scenewatch/core/frame.h"
#include "scenewatch/core/image.h"
#include "scenewatch/core/result.h"
#include "scenewatch/sim/animation.h"
#include "scenewatch/sim/ground_truth.h"
#include "scenewatch/sim/raycaster.h"
#include "scenewatch/sim/scenario.h"
#include "scenewatch/sim/sensor_model.h"

namespace scenewatch::sim {

/// One rendered frame.
struct SimFrame {
  ColorImage color;
  DepthImage depth;
  LabelImage labels;
  FrameTruth truth;
};

/// The frame as a posed RGB-D sensor delivers it: the organized colour cloud of `rendered`, its
/// reported pose and the intrinsics `K` (what a client sends, what the working memory takes).
Result<Frame> as_frame(const SimFrame& rendered, const Intrinsics& K, double stamp_s);

/// Where a run wrote its sequences.
struct RunSummary {
  std::vector<std::filesystem::path> sequence_dirs;  ///< one per phase
  std::filesystem::path changes_json;                ///< empty for a single phase
  std::size_t frames_written = 0;
};

/// Called after each written frame: phase name, frames done in the run, frames in the run.
using ProgressFn = std::function<void(const std::string& phase, std::size_t done, std::size_t total)>;

/// Simulates one scenario. Owns a ray caster with scratch buffers: NOT thread safe.
class Simulator {
 public:
  /// Validates the scenario and animates its phases (the end of one phase, with the changes,
  /// is the start of the next).
  static Result<Simulator> create(Scenario scenario, RaycasterConfig raycaster = {});

  /// The scenario.
  const Scenario& scenario() const { return scenario_; }
  /// Number of phases (sequences).
  std::size_t phase_count() const { return animators_.size(); }
  /// Frames of a phase.
  int frame_count(std::size_t phase) const { return scenario_.phases[phase].frames; }

  /// The scene to draw at a frame: table, objects and hand placed for that time.
  RenderScene render_scene(std::size_t phase, int frame) const;
  /// Ground truth of a frame (true and reported camera pose, object and hand poses, contacts).
  FrameTruth frame_truth(std::size_t phase, int frame) const;
  /// Ground truth of a whole phase, with contacts and manipulations analysed (no rendering).
  SequenceTruth sequence_truth(std::size_t phase) const;
  /// Ground truth of the changes between consecutive phases.
  std::vector<ChangeTruth> changes() const;

  /// Renders the ideal (noise-free) view of a frame.
  void render_ideal(std::size_t phase, int frame, IdealView* view);
  /// Applies the sensor model to an ideal view of a frame.
  void apply_sensor(std::size_t phase, int frame, const IdealView& view, ColorImage* color, DepthImage* depth) const;
  /// Renders a frame as the sensor sees it, with its ground truth.
  SimFrame render(std::size_t phase, int frame);

  /// Writes the run: a single phase into `out_dir` itself, several phases into
  /// out_dir/<phase name>/ plus out_dir/changes.json.
  Result<RunSummary> write(const std::filesystem::path& out_dir, const ProgressFn& progress = {});

 private:
  Simulator(Scenario scenario, RaycasterConfig raycaster);
  std::uint64_t frame_key(std::size_t phase, int frame) const;

  Scenario scenario_;
  std::vector<Animator> animators_;
  std::vector<RenderItem> static_items_;  ///< the table
  Raycaster raycaster_;
  SensorModel sensor_;
  IdealView view_;
};

}  // namespace scenewatch::sim
