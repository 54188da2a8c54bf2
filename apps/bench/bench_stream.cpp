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

/// A simulator scenario; `frames` > 0: that many frames per phase along the same paths.
std::optional<Recording> simulated(const std::string& scenario, int width, int height, int frames = 0) {
  auto loaded = sim::load_scenario(std::filesystem::path(SCENEWATCH_SOURCE_DIR) / "sample_clouds/scenarios" / (scenario + ".yaml"));
  if (!loaded) return std::nullopt;
  sim::Scenario sc = sim::with_resolution(*loaded, width, height);
  if (frames > 0) sc = sim::with_frames(sc, frames);
  auto simulator = sim::Simulator::create(sc);
  if (!simulator) return std::nullopt;
  auto shared = std::make_shared<sim::Simulator>(std::move(*simulator));
  std::vector<std::pair<std::size_t, int>> index;  // (phase, frame)
  for (std::size_t p = 0; p < shared->phase_count(); ++p)
    for (int f = 0; f < shared->frame_count(p); ++f) index.emplace_back(p, f);
  const Intrinsics K = sc.intrinsics;
  Recording r{"sim " + scenario + " " + std::to_string(width) + "x" + std::to_string(height) +
                  (frames > 0 ? ", " + std::to_string(frames) + " a phase" : std::string()),
              index.size(),
              [shared, index, K](std::size_t i) -> std::optional<Frame> {
                auto frame = sim::as_frame(shared->render(index[i].first, index[i].second), K, i / 30.0);
                if (!frame) return std::nullopt;
                return std::move(*frame);
              }};
  r.z_up = true;
  return r;
}

std::vector<std::size_t> range(std::size_t from, std::size_t to) {  // [from, to)
  std::vector<std::size_t> v;
  for (std::size_t i = from; i < to; ++i) v.push_back(i);
  return v;
}

/// Which frames of a recording of `frames` frames to play, in what order.
using Order = std::function<std::vector<std::size_t>(std::size_t frames)>;

/// Frames of one real recording in the given order, each with the camera it is sent as (empty:
/// the frame's own, unnamed).
std::optional<Recording> reordered(const Options& o, const std::string& name, const std::string& folder, const Order& order_of,
                                   std::vector<std::string> cameras = {}) {
  auto seq = io::open_sequence(o.data_dir / folder);
  if (!seq) {
    std::printf("  (skipped %s: %s)\n", name.c_str(), seq.error().message.c_str());
    return std::nullopt;
  }
  auto shared = std::make_shared<io::Sequence>(std::move(*seq));
  std::vector<std::size_t> order = order_of(shared->frames.size());
  for (std::size_t i : order) {
    if (i >= shared->frames.size()) {
      std::printf("  (skipped %s: %s has %zu frames)\n", name.c_str(), folder.c_str(), shared->frames.size());
      return std::nullopt;
    }
  }
  const std::size_t n = order.size();
  return Recording{name, n, [shared, order = std::move(order), cameras = std::move(cameras)](std::size_t k) -> std::optional<Frame> {
                     auto f = io::load_sequence_frame(*shared, order[k]);
                     if (!f) return std::nullopt;
                     if (k < cameras.size()) f->camera = cameras[k];
                     return std::move(*f);
                   }};
}

/// Every frame in order, or forwards then backwards (every view revisited).
Order every_frame(bool forth_and_back = false) {
  return [forth_and_back](std::size_t n) {
    std::vector<std::size_t> order = range(0, n);
    if (forth_and_back)
      for (std::size_t i = n; i-- > 0;) order.push_back(i);
    return order;
  };
}

/// A fixed list of frames.
Order these_frames(std::vector<std::size_t> order) {
  return [order = std::move(order)](std::size_t) { return order; };
}

struct Variant {
  const char* name;
  std::function<void(pipeline::Config&)> change;
};

/// Events per 100 frames of each recording under each variant, one row each.
void run_table(const std::vector<Recording>& recordings, const std::vector<Variant>& variants) {
  std::printf("%-48s %-28s %6s %7s %8s  %s\n", "recording", "configuration", "frames", "events", "per 100", "by kind");
  for (const auto& r : recordings) {
    for (const auto& v : variants) {
      pipeline::Config config;
      if (r.z_up) config.segmentation.up = Eigen::Vector3d::UnitZ();
      v.change(config);
      pipeline::WorkingMemory memory(config);
      std::map<std::string, int> by_kind;
      std::size_t events = 0, frames = 0;
      for (std::size_t i = 0; i < r.frames; ++i) {
        auto frame = r.frame(i);
        if (!frame) break;
        auto result = memory.process(*frame);
        if (!result) {
          std::printf("  %s frame %zu: %s\n", r.name.c_str(), i, result.error().message.c_str());
          break;
        }
        ++frames;
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
}

}  // namespace

int run_sensor_model(const Options& o) {
  std::printf("\n== The calm stream on the kitchen it was not tuned on (issue 28): redkitchen_long, 250 frames (files 0-498,\n"
              "   every second); remedies tuned on files 0-248 only\n");
  std::vector<std::size_t> interleaved;
  std::vector<std::string> two, one;
  for (std::size_t i = 0; i < 100; ++i) {
    interleaved.push_back(i), two.push_back("a"), one.push_back("one");
    interleaved.push_back(150 + i), two.push_back("b"), one.push_back("one");
  }
  std::vector<Recording> recordings;
  for (auto r : {reordered(o, "long files 0-248 (tuned on)", "redkitchen_long", these_frames(range(0, 125))),
                 reordered(o, "long files 250-498 (held out)", "redkitchen_long", these_frames(range(125, 250))),
                 reordered(o, "long all 250", "redkitchen_long", every_frame()),
                 reordered(o, "long forth and back (500)", "redkitchen_long", every_frame(true)),
                 reordered(o, "long two cameras (0-198 a, 300-498 b)", "redkitchen_long", these_frames(interleaved), two),
                 reordered(o, "long the same sent as one camera", "redkitchen_long", these_frames(interleaved), one)}) {
    if (r) recordings.push_back(std::move(*r));
  }
  run_table(recordings, {
      {"default", [](pipeline::Config&) {}},
      {"no measured pose", [](pipeline::Config& c) { c.change.measure_pose = false; }},
      {"every pixel evidence", [](pipeline::Config& c) { c.change.trusted_pixels_only = false; }},
      {"no per-camera witness", [](pipeline::Config& c) { c.change.witness_per_camera = false; }},
      {"head-on noise only", [](pipeline::Config& c) { c.change.incidence_aware = false; }},
      {"colour not registered", [](pipeline::Config& c) { c.sensor.fit_colour_registration = false; }},
      {"no dark space", [](pipeline::Config& c) { c.change.see_through_dark = false; }},
      {"none of these", [](pipeline::Config& c) {
         c.change.measure_pose = false;
         c.change.trusted_pixels_only = false;
         c.change.witness_per_camera = false;
         c.change.incidence_aware = false;
         c.sensor.fit_colour_registration = false;
         c.change.see_through_dark = false;
       }},
  });
  return 0;
}

int run_stream(const Options& o) {
  std::printf("\n== The event stream: events per 100 frames through WorkingMemory (every kind counted)\n");
  std::vector<Recording> recordings;
  for (auto r : {reordered(o, "redkitchen (7-Scenes, unchanged room, hand-held)", "redkitchen", every_frame()),
                 reordered(o, "redkitchen forth and back (views revisited)", "redkitchen", every_frame(true)),
                 reordered(o, "hrt1 pick_toy_1 (a person picks a toy)", "hrt1/pick_toy_1", every_frame()),
                 reordered(o, "hrt1 pick_toy_2 (the person stays in view)", "hrt1/pick_toy_2", every_frame()),
                 simulated("clutter", 320, 240), simulated("cup_added", 320, 240), simulated("object_moved", 320, 240),
                 simulated("glasses_removed", 320, 240, 71)}) {
    if (r) recordings.push_back(std::move(*r));
  }
  const std::vector<Variant> variants = {
      {"default", [](pipeline::Config&) {}},
      {"no misalignment tolerance", [](pipeline::Config& c) { c.surprise.robust.align_radius_px = 0; }},
      {"no photometric correction", [](pipeline::Config& c) { c.surprise.robust.photometric = false; }},
      {"no familiar-view gate", [](pipeline::Config& c) { c.surprise.familiar_after_frames = 0; }},
      {"no appearance persistence", [](pipeline::Config& c) { c.fusion.persistence_frames = 1; }},
      {"no dark space", [](pipeline::Config& c) { c.change.see_through_dark = false; }},
      {"none of these (every region)", [](pipeline::Config& c) {
         c.surprise.robust.align_radius_px = 0;
         c.surprise.robust.photometric = false;
         c.surprise.familiar_after_frames = 0;
         c.fusion.persistence_frames = 1;
       }},
  };
  run_table(recordings, variants);
  return 0;
}

}  // namespace scenewatch::bench
