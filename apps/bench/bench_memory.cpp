// Memory over a long run: 1000 posed VGA frames of a moving camera (the simulator's
// glasses_removed, two circles around a set table, stretched to 500 frames each) through
// WorkingMemory::process, with the resident size of this process and the model's own accounting
// (map, keyframes and mesh against the appearance budget) printed as it goes.
#include <cstdio>

#include "bench.h"
#include "scenewatch/core/memory.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"

namespace scenewatch::bench {
namespace {

constexpr int kFramesPerPhase = 500;

}  // namespace

int run_memory(const Options&) {
  std::printf("\n== Memory: %d posed 640x480 frames of a moving camera (simulated glasses_removed) through WorkingMemory::process\n",
              2 * kFramesPerPhase);
  auto loaded = sim::load_scenario(std::filesystem::path(SCENEWATCH_SOURCE_DIR) / "sample_clouds/scenarios/glasses_removed.yaml");
  if (!loaded) {
    std::printf("  (scenario not loaded: %s)\n", loaded.error().message.c_str());
    return 1;
  }
  const sim::Scenario sc = sim::with_frames(sim::with_resolution(*loaded, 640, 480), kFramesPerPhase);
  auto simulator = sim::Simulator::create(sc);
  if (!simulator) return 1;
  pipeline::Config config;
  config.segmentation.up = Eigen::Vector3d::UnitZ();
  pipeline::WorkingMemory memory(config);
  std::printf("   appearance budget %zu MiB, at most %zu keyframes; resident size before the first frame %.0f MiB\n",
              config.appearance.memory_budget_mb, config.appearance.max_keyframes, resident_mib());
  std::printf("   %6s %12s %10s %14s %12s %10s %14s\n", "frames", "resident MiB", "map MiB", "map leaves", "keyframes",
              "keyframe MiB", "median ms/frame");
  std::vector<double> ms;
  std::size_t done = 0;
  for (std::size_t p = 0; p < simulator->phase_count(); ++p)
    for (int f = 0; f < simulator->frame_count(p); ++f) {
      auto frame = sim::as_frame(simulator->render(p, f), sc.intrinsics, done / 30.0);
      if (!frame) return 1;
      auto r = memory.process(*frame);
      if (!r) {
        std::printf("   frame %zu: %s\n", done, r.error().message.c_str());
        return 1;
      }
      ms.push_back(r->total_ms);
      ++done;
      if (done == 1 || done % 250 == 0) {
        const pipeline::Stats s = memory.stats();
        std::printf("   %6zu %12.0f %10.1f %14zu %12zu %10.1f %14.1f\n", done, resident_mib(), s.map_memory_bytes / 1048576.0,
                    s.map_leaf_nodes, s.keyframes, s.appearance_memory_bytes / 1048576.0, median(ms));
        ms.clear();
      }
    }
  return 0;
}

}  // namespace scenewatch::bench
