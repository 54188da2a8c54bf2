#pragma once
/// The closed loop of issue 31 on the simulator: from a first view, the planner (or a random
/// choice among the same candidates) picks the next view, the ray caster renders it, the frame is
/// inserted into an occupancy map, and so on. Coverage is the fraction of the target objects' true
/// surface (sampled from the simulator's shapes) that some rendered pixel of that object has hit.
/// What the planner aims at is the setup's choice: the true box, or what a robot would know (the box
/// of what it has seen, or the ontology's completion of it).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "scenewatch/ontology/class_library.h"
#include "scenewatch/planning/next_best_view.h"
#include "scenewatch/sim/scenario.h"

namespace scenewatch::planning::eval {

/// What the planner is told the target is. The candidates and the coverage are the same for all.
enum class PlannedTarget {
  kTruthBox,     ///< the targets' true box (the simulator's): an oracle a robot does not have
  kObservedBox,  ///< the box of the target's points seen so far, grown by a voxel
  kCompletion,   ///< the ontology's completed primitive of the points seen so far (its unseen side,
                 ///< less the face it stands on) when a class fits them, else the observed box
};
const char* to_string(PlannedTarget target);

struct ClosedLoopSetup {
  std::vector<int> target_ids;     ///< objects whose surface counts; empty: every object (the table's clutter)
  PlannedTarget planned_target = PlannedTarget::kTruthBox;
  const ontology::ClassLibrary* classes = nullptr;  ///< kCompletion: the classes (config/ontology.yaml)
  int views = 10;                  ///< views chosen after the first
  bool random = false;             ///< random candidate instead of the planner's best
  Measure measure = Measure::kRearSideEntropy;
  int image_width = 160, image_height = 120;  ///< the rendered frames (the scenario's intrinsics, scaled)
  double resolution_m = 0.02;      ///< the map's voxels
  double cap_radius_m = 0.7;       ///< candidates on a cap above the target's centre
  double cap_polar_deg = 70.0;
  int candidates = 48;
  double surface_cell_m = 0.01;    ///< a true-surface sample counts as seen when a pixel of its object hits its cell
};

/// Coverage after the first view (index 0) and after each chosen view (1..views).
struct ClosedLoopCurve {
  std::vector<double> coverage;
  std::size_t surface_samples = 0;
  int completed_steps = 0;  ///< kCompletion: the planning steps a class fitted (the others took the observed box)
  std::string last_class;   ///< kCompletion: the class of the last step's description ("unknown": none fitted)
};

/// One run: `seed` places the first view at random on the cap (the same for planned and random
/// runs of that seed) and draws random's choices.
Result<ClosedLoopCurve> run_closed_loop(const sim::Scenario& scenario, const ClosedLoopSetup& setup, std::uint64_t seed);

}  // namespace scenewatch::planning::eval
