#pragma once
// A simulator scenario shipped in sample_clouds/scenarios, at a size and frame count of the test's
// choosing, with its simulator (link scenewatch::sim).
#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::test {

struct ShippedScenario {
  sim::Scenario scenario;
  std::optional<sim::Simulator> simulator;  ///< empty when the scenario did not load (the test has failed)
};

/// `name` (e.g. "cup_added") at width x height, `frames` frames per phase (0: as shipped).
inline ShippedScenario shipped_scenario(const std::string& name, int width, int height, int frames = 0) {
  ShippedScenario out;
  auto loaded = sim::load_scenario(source_dir() / "sample_clouds/scenarios" / (name + ".yaml"));
  if (!loaded.ok()) {
    ADD_FAILURE() << loaded.error().message;
    return out;
  }
  out.scenario = sim::with_resolution(*loaded, width, height);
  if (frames > 0) out.scenario = sim::with_frames(out.scenario, frames);
  auto simulator = sim::Simulator::create(out.scenario);
  if (!simulator.ok()) {
    ADD_FAILURE() << simulator.error().message;
    return out;
  }
  out.simulator.emplace(std::move(*simulator));
  return out;
}

}  // namespace scenewatch::test
