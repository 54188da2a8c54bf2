// The whole frame: posed VGA RGB-D sequences through WorkingMemory::process as the daemon runs
// them, with the time per stage, then the same frames streamed into the real scenewatchd over
// TCP (frames per second sustained, one client sending the next frame when the reply comes).
// Stages that run beside each other (segmentation on one core; image surprise and change
// detection on the other) are shown each with its own time; "frame" is the wall time of process().
#include <sys/resource.h>

#include <cstdio>
#include <deque>
#include <map>
#include <optional>

#include "bench.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"

#ifdef SCENEWATCH_BENCH_HAS_SERVICE
#include "bench_daemon.h"
#include "scenewatch/service/client.h"
#endif

namespace scenewatch::bench {
namespace {

struct Sequence {
  std::string name;
  std::vector<Frame> frames;
  std::vector<double> decode_ms;
  bool z_up = false;
};

std::optional<Sequence> real_sequence(const Options& o, const std::string& name, const std::string& folder) {
  auto seq = io::open_sequence(o.data_dir / folder);
  if (!seq) return std::nullopt;
  Sequence s{name, {}, {}, false};
  for (std::size_t i = 0; i < seq->frames.size(); ++i) {
    std::optional<Frame> f;
    s.decode_ms.push_back(time_ms([&] {
      auto loaded = io::load_sequence_frame(*seq, i);
      if (loaded) f = std::move(*loaded);
    }));
    if (!f) return std::nullopt;
    s.frames.push_back(std::move(*f));
  }
  return s;
}

std::optional<Sequence> simulated_sequence(const std::string& scenario_name) {
  auto loaded = sim::load_scenario(std::filesystem::path(SCENEWATCH_SOURCE_DIR) / "sample_clouds/scenarios" /
                                   (scenario_name + ".yaml"));
  if (!loaded) return std::nullopt;
  const sim::Scenario sc = sim::with_resolution(*loaded, 640, 480);
  auto simulator = sim::Simulator::create(sc);
  if (!simulator) return std::nullopt;
  Sequence s{"sim " + scenario_name + " 640x480", {}, {}, true};
  for (std::size_t p = 0; p < simulator->phase_count(); ++p)
    for (int f = 0; f < simulator->frame_count(p); ++f) {
      const sim::SimFrame rendered = simulator->render(p, f);
      std::optional<Frame> frame;
      s.decode_ms.push_back(time_ms([&] {
        auto converted = sim::as_frame(rendered, sc.intrinsics, s.frames.size() / 30.0);
        if (converted) frame = std::move(*converted);
      }));
      if (!frame) return std::nullopt;
      s.frames.push_back(std::move(*frame));
    }
  return s;
}

// CPU time of this process (all threads, user + system), ms.
double cpu_ms() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  auto ms = [](const timeval& t) { return t.tv_sec * 1e3 + t.tv_usec * 1e-3; };
  return ms(u.ru_utime) + ms(u.ru_stime);
}

struct OfflineRun {
  double median_frame_ms = 0, p90_frame_ms = 0, cpu_per_frame_ms = 0;
  std::size_t events = 0;
  double cores_busy = 0;
  std::map<std::string, std::vector<double>> stage_ms;  // by stage, ordered by its numbered name
};

// The frames through one working memory per configuration, interleaved frame by frame: frame i
// goes through every memory before frame i+1 goes through any, so that what the machine does
// meanwhile (another process, the clock, the caches) falls on every configuration alike. Run one
// after the other, the same configuration had differed by up to 1.2x between two runs (hrt1).
std::optional<std::vector<OfflineRun>> offline(const Sequence& s, const std::vector<pipeline::Config>& configs) {
  std::vector<std::unique_ptr<pipeline::WorkingMemory>> memories;
  for (const auto& c : configs) memories.push_back(std::make_unique<pipeline::WorkingMemory>(c));
  std::vector<OfflineRun> runs(configs.size());
  std::vector<double> wall_ms(configs.size(), 0.0), cpu(configs.size(), 0.0);
  for (const auto& f : s.frames)
    for (std::size_t c = 0; c < configs.size(); ++c) {
      const double cpu0 = cpu_ms();
      auto r = memories[c]->process(f);
      cpu[c] += cpu_ms() - cpu0;
      if (!r) {
        std::printf("  %s: %s\n", s.name.c_str(), r.error().message.c_str());
        return std::nullopt;
      }
      auto& ms = runs[c].stage_ms;
      ms["1 segmentation"].push_back(r->segment_ms);
      ms["2 image surprise + keyframes"].push_back(r->surprise_ms);
      ms["3 change detection"].push_back(r->change_ms);
      ms["4 map insertion"].push_back(r->insert_ms);
      ms["0 hands (before the others)"].push_back(r->hands_ms);
      ms["5 foreground (registration, promotion)"].push_back(r->foreground_ms);
      ms["6 the three parts side by side"].push_back(r->parallel_ms);
      ms["7 after (foreground, fusion, tracker, publish)"].push_back(r->after_ms);
      ms["9 frame (process)"].push_back(r->total_ms);
      wall_ms[c] += r->total_ms;
      runs[c].events += r->events.size();
    }
  for (std::size_t c = 0; c < configs.size(); ++c) {
    auto& run = runs[c];
    const auto& frame_ms = run.stage_ms["9 frame (process)"];
    run.median_frame_ms = median(frame_ms);
    run.p90_frame_ms = quantile(frame_ms, 0.9);
    run.cpu_per_frame_ms = cpu[c] / static_cast<double>(s.frames.size());
    run.cores_busy = wall_ms[c] > 0 ? cpu[c] / wall_ms[c] : 0.0;
  }
  return runs;
}

// The defaults' stages, with the median of each without the sensor model's remedies beside them.
void print_stages(const Sequence& s, const OfflineRun& now, const OfflineRun& without) {
  std::printf("-- %s: %zu frames, %zu events; decoding (PNG + cloud, before process) median %.1f ms\n", s.name.c_str(),
              s.frames.size(), now.events, median(s.decode_ms));
  std::printf("   %-46s %10s %10s %14s\n", "stage", "median ms", "p90 ms", "remedies off");
  for (const auto& [stage, v] : now.stage_ms) {
    const auto off = without.stage_ms.find(stage);
    std::printf("   %-46s %10.1f %10.1f %14.1f\n", stage.substr(2).c_str(), median(v), quantile(v, 0.9),
                off != without.stage_ms.end() ? median(off->second) : 0.0);
  }
  const double m = now.median_frame_ms;
  std::printf("   => %.1f frames/s offline (median frame); target 15 (66 ms), goal 30 (33 ms)\n", m > 0 ? 1000.0 / m : 0.0);
  std::printf("   CPU per frame, all threads: %.1f ms (mean), %.2f cores busy during process()\n", now.cpu_per_frame_ms,
              now.cores_busy);
}

// The defaults, after the same frames with every pixel segmented and inserted (the strides of
// issue 11 at 1), in the same run.
void offline_side_by_side(const Sequence& s) {
  pipeline::Config config;
  if (s.z_up) config.segmentation.up = Eigen::Vector3d::UnitZ();
  pipeline::Config every_pixel = config;
  every_pixel.tracking.segmentation_stride_px = 1;
  every_pixel.background.insert_stride_px = 1;
  pipeline::Config no_sensor_remedies = config;  // issue 28's additions switched off
  no_sensor_remedies.change.measure_pose = false;
  no_sensor_remedies.change.trusted_pixels_only = false;
  no_sensor_remedies.change.witness_per_camera = false;
  no_sensor_remedies.change.incidence_aware = false;
  no_sensor_remedies.sensor.fit_colour_registration = false;
  no_sensor_remedies.change.see_through_dark = false;
  const auto runs = offline(s, {config, no_sensor_remedies, every_pixel});
  if (!runs) return;
  const OfflineRun* now = &(*runs)[0];
  const OfflineRun* without = &(*runs)[1];
  const OfflineRun* before = &(*runs)[2];
  print_stages(s, *now, *without);
  std::printf("   without the sensor model's remedies (measured pose, trusted pixels, per-camera witness, incidence, colour registration, dark space), same run: "
              "frame median %.1f ms (p90 %.1f), CPU %.1f ms per frame, %zu events; the defaults take %.2fx its time "
              "(median), %.2fx its CPU\n",
              without->median_frame_ms, without->p90_frame_ms, without->cpu_per_frame_ms, without->events,
              without->median_frame_ms > 0 ? now->median_frame_ms / without->median_frame_ms : 0.0,
              without->cpu_per_frame_ms > 0 ? now->cpu_per_frame_ms / without->cpu_per_frame_ms : 0.0);
  std::printf("   every pixel segmented and inserted, same run: frame median %.1f ms (p90 %.1f), CPU %.1f ms per frame, "
              "%zu events; the defaults %.2fx faster (median), %.2fx less CPU\n",
              before->median_frame_ms, before->p90_frame_ms, before->cpu_per_frame_ms, before->events,
              now->median_frame_ms > 0 ? before->median_frame_ms / now->median_frame_ms : 0.0,
              now->cpu_per_frame_ms > 0 ? before->cpu_per_frame_ms / now->cpu_per_frame_ms : 0.0);
}

#ifdef SCENEWATCH_BENCH_HAS_SERVICE
// One daemon for one sequence; it stops (and saves into model_dir) when this returns. The client
// keeps `window` frames in flight: 1 sends each frame after the reply to the one before, 2 sends
// the next frame while the one before is processed (as `scenewatch ingest` does).
void stream(const Sequence& s, const std::filesystem::path& model_dir, std::size_t window) {
  Daemon daemon;
  if (!daemon.start(model_dir, s.z_up ? "demo.yaml" : "scenewatchd.yaml")) {
    std::printf("   (scenewatchd did not start: build it first)\n");
    return;
  }
  auto client = service::Client::connect("127.0.0.1", daemon.port());
  if (!client) return;
  client->set_token(daemon.token());
  std::vector<proto::Request> requests(s.frames.size());
  for (std::size_t i = 0; i < s.frames.size(); ++i) *requests[i].mutable_ingest_frame() = service::make_ingest_frame(s.frames[i]);
  std::size_t events = 0;
  bool ok = true;
  const double wall = time_ms([&] {
    std::deque<std::uint64_t> in_flight;
    std::size_t next = 0;
    while (ok && (next < requests.size() || !in_flight.empty())) {
      while (next < requests.size() && in_flight.size() < window) {
        auto id = client->start(requests[next++]);
        if (!id) {
          ok = false;
          return;
        }
        in_flight.push_back(*id);
      }
      auto reply = client->wait_for(in_flight.front(), 120);
      in_flight.pop_front();
      if (!reply || !service::status_of(*reply).ok()) {
        ok = false;
        return;
      }
      events += static_cast<std::size_t>(reply->ingest().events_size());
    }
  });
  if (!ok) {
    std::printf("   over TCP: an ingest failed\n");
    return;
  }
  proto::Request stats;
  stats.mutable_stats();
  auto reply = client->call(stats, 30);
  const double process_ms = reply && reply->has_stats() ? reply->stats().mean_frame_ms() : 0.0;
  std::printf("   over TCP into scenewatchd, %s: %.1f frames/s sustained, %zu events (the daemon's process() %.1f ms mean)\n",
              window == 1 ? "frame after reply        " : "two frames in flight     ", 1000.0 * s.frames.size() / wall, events,
              process_ms);
}

void over_tcp(const Sequence& s) {
  const auto model_dir = std::filesystem::temp_directory_path() / ("scenewatch-bench-pipeline-" + std::to_string(::getpid()));
  for (std::size_t window : {1, 2}) {
    stream(s, model_dir, window);
    std::error_code ec;
    std::filesystem::remove_all(model_dir, ec);  // the daemon saved into it when it stopped
  }
}
#else
void over_tcp(const Sequence&) { std::printf("   over TCP: built without the service module; skipped\n"); }
#endif

}  // namespace

int run_pipeline(const Options& o) {
  std::printf("\n== The whole frame: posed VGA RGB-D through WorkingMemory::process, then over TCP\n");
  for (const auto& s : {real_sequence(o, "7-Scenes redkitchen (50 frames, hand-held)", "redkitchen"), simulated_sequence("cup_added"),
                 real_sequence(o, "hrt1 pick_toy_1 (40 frames, a person picks a toy)", "hrt1/pick_toy_1")}) {
    if (!s) {
      std::printf("  (a sequence could not be loaded; skipped)\n");
      continue;
    }
    offline_side_by_side(*s);
    over_tcp(*s);
  }
  return 0;
}

}  // namespace scenewatch::bench
