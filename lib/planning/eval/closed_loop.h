#pragma once
/// The closed loop of issue 31 on the simulator: from a first view, the planner (or a random
/// choice among the same candidates) picks the next view, the ray caster renders it, the frame is
/// inserted into an occupancy map, and so on. Coverage is the fraction of the target objects' true
/// surface (sampled from the simulator's shapes) that some rendered pixel of that object has hit.
#include <cstdint>
#include <filesystem>
#include <vector>

#include "scenewatch/planning/next_best_view.h"
#include "scenewatch/sim/scenario.h"

namespace scenewatch::planning::eval {

struct ClosedLoopSetup {
  std::vector<int> target_ids;     ///< objects whose surface counts; empty: every object (the table's clutter)
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
};

/// One run: `seed` places the first view at random on the cap (the same for planned and random
/// runs of that seed) and draws random's choices.
Result<ClosedLoopCurve> run_closed_loop(const sim::Scenario& scenario, const ClosedLoopSetup& setup, std::uint64_t seed);

}  // namespace scenewatch::planning::eval
