// The event stream: events per 100 frames on unchanged scenes and on scenes with one change,
// through WorkingMemory as the daemon runs it, with the default configuration and with each of
// the calm stream's remedies switched off in turn (the figure before and after for each cause).
#include <cstdio>
#include <map>
#include <optional>

#include "bench.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"

namespace scenewatch::bench {
namespace {

using FrameSource = std::function<std::optional<Frame>(std::size_t)>;

struct Recording {
  std::string name;
  std::size_t frames = 0;
  FrameSource frame;
  bool z_up = false;  ///< the simulator's world has z up
};

/// A real recording; `forth_and_back` plays it forwards, then backwards (every view revisited).
std::optional<Recording> real(const Options& o, const std::string& name, const std::string& folder,
                              bool forth_and_back = false) {
  auto seq = io::open_sequence(o.data_dir / folder);
  if (!seq) {
    std::printf("  (skipped %s: %s)\n", name.c_str(), seq.error().message.c_str());
    return std::nullopt;
  }
  auto shared = std::make_shared<io::Sequence>(std::move(*seq));
  const std::size_t n = shared->frames.size();
  return Recording{name, forth_and_back ? 2 * n : n, [shared, n](std::size_t i) -> std::optional<Frame> {
                     auto f = io::load_sequence_frame(*shared, i < n ? i : 2 * n - 1 - i);
                     if (!f) return std::nullopt;
                     return std::move(*f);
                   }};
}

std::optional<Recording> simulated(const std::string& scenario, int width, int height) {
  auto loaded = sim::load_scenario(std::filesystem::path(SCENEWATCH_SOURCE_DIR) / "sample_clouds/scenarios" / (scenario + ".yaml"));
  if (!loaded) return std::nullopt;
  const sim::Scenario sc = sim::with_resolution(*loaded, width, height);
  auto simulator = sim::Simulator::create(sc);
  if (!simulator) return std::nullopt;
  auto shared = std::make_shared<sim::Simulator>(std::move(*simulator));
  std::vector<std::pair<std::size_t, int>> index;  // (phase, frame)
  for (std::size_t p = 0; p < shared->phase_count(); ++p)
    for (int f = 0; f < shared->frame_count(p); ++f) index.emplace_back(p, f);
  const Intrinsics K = sc.intrinsics;
  Recording r{"sim " + scenario + " " + std::to_string(width) + "x" + std::to_string(height), index.size(),
              [shared, index, K](std::size_t i) -> std::optional<Frame> {
                auto frame = sim::as_frame(shared->render(index[i].first, index[i].second), K, i / 30.0);
                if (!frame) return std::nullopt;
                return std::move(*frame);
              }};
  r.z_up = true;
  return r;
}

struct Variant {
  const char* name;
  std::function<void(pipeline::Config&)> change;
};

}  // namespace

int run_stream(const Options& o) {
  std::printf("\n== The event stream: events per 100 frames through WorkingMemory (every kind counted)\n");
  std::vector<Recording> recordings;
  for (auto r : {real(o, "redkitchen (7-Scenes, unchanged room, hand-held)", "redkitchen"),
                 real(o, "redkitchen forth and back (views revisited)", "redkitchen", true),
                 real(o, "hrt1 pick_toy_1 (a person picks a toy)", "hrt1/pick_toy_1"),
                 real(o, "hrt1 pick_toy_2 (the person stays in view)", "hrt1/pick_toy_2"),
                 simulated("clutter", 320, 240), simulated("cup_added", 320, 240), simulated("object_moved", 320, 240)}) {
    if (r) recordings.push_back(std::move(*r));
  }
  const std::vector<Variant> variants = {
      {"default", [](pipeline::Config&) {}},
      {"no misalignment tolerance", [](pipeline::Config& c) { c.surprise.robust.align_radius_px = 0; }},
      {"no photometric correction", [](pipeline::Config& c) { c.surprise.robust.photometric = false; }},
      {"no familiar-view gate", [](pipeline::Config& c) { c.surprise.familiar_after_frames = 0; }},
      {"no appearance persistence", [](pipeline::Config& c) { c.fusion.persistence_frames = 1; }},
      {"none of these (every region)", [](pipeline::Config& c) {
         c.surprise.robust.align_radius_px = 0;
         c.surprise.robust.photometric = false;
         c.surprise.familiar_after_frames = 0;
         c.fusion.persistence_frames = 1;
       }},
  };
  std::printf("%-48s %-28s %6s %7s %8s  %s\n", "recording", "configuration", "frames", "events", "per 100", "by kind");
  for (const auto& r : recordings) {
    for (const auto& v : variants) {
      pipeline::Config config;
      if (r.z_up) config.segmentation.up = Eigen::Vector3d::UnitZ();
      v.change(config);
      pipeline::WorkingMemory memory(config);
      std::map<std::string, int> by_kind;
      std::size_t events = 0, frames = 0;
      std::vector<double> ms;
      for (std::size_t i = 0; i < r.frames; ++i) {
        auto frame = r.frame(i);
        if (!frame) break;
        auto result = memory.process(*frame);
        if (!result) {
          std::printf("  %s frame %zu: %s\n", r.name.c_str(), i, result.error().message.c_str());
          break;
        }
        ++frames;
        ms.push_back(result->total_ms);
        for (const auto& e : result->events) {
          ++events;
          ++by_kind[to_string(e.kind)];
        }
      }
      std::string kinds;
      for (const auto& [k, n] : by_kind) kinds += k + " " + std::to_string(n) + "  ";
      std::printf("%-48s %-28s %6zu %7zu %8.1f  %s\n", r.name.c_str(), v.name, frames, events,
                  frames ? 100.0 * events / frames : 0.0, kinds.c_str());
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace scenewatch::bench
