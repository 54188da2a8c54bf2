// scenewatch-sim: renders synthetic tabletop RGB-D sequences with exact ground truth.
//   scenewatch-sim render SCENARIO --out DIR [--frames N] [--seed S] [--width W --height H]
//   scenewatch-sim list
//   scenewatch-sim bench [--frames N]
#include <CLI/CLI.hpp>
#include <sched.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "install_layout.h"
#include "scenewatch/io/cloud_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"

namespace fs = std::filesystem;
using namespace scenewatch;

namespace {

/// A scenario argument is a path to a YAML file or the name of a shipped scenario.
Result<sim::Scenario> resolve_scenario(const std::string& arg, const fs::path& scenario_dir) {
  if (fs::exists(arg)) return sim::load_scenario(arg);
  const fs::path shipped = scenario_dir / (arg + ".yaml");
  if (fs::exists(shipped)) return sim::load_scenario(shipped);
  return not_found(arg + ": no such file, and no shipped scenario of that name in " + scenario_dir.string() +
                   " (see 'scenewatch-sim list')");
}

std::vector<fs::path> shipped_scenarios(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (e.path().extension() == ".yaml") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

Result<sim::Scenario> apply_overrides(sim::Scenario sc, std::optional<int> frames, std::optional<std::uint64_t> seed,
                                      std::optional<int> width, std::optional<int> height) {
  if (width.has_value() != height.has_value()) return invalid_argument("--width and --height go together");
  if (width) {
    if (*width < 1 || *height < 1 || *width > 8192 || *height > 8192) {
      return invalid_argument("--width/--height must be in 1..8192");
    }
    sc = sim::with_resolution(std::move(sc), *width, *height);
  }
  if (frames) {
    if (*frames < 1) return invalid_argument("--frames must be at least 1");
    sc = sim::with_frames(std::move(sc), *frames);
  }
  if (seed) sc.seed = *seed;
  return sc;
}

int fail(const Error& e) {
  std::cerr << "scenewatch-sim: " << e.message << "\n";
  return e.code == ErrorCode::kNotFound || e.code == ErrorCode::kInvalidArgument ? 2 : 1;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Pins the process to one CPU so that the figures are one core's.
bool pin_to_one_core() {
  cpu_set_t current;
  CPU_ZERO(&current);
  if (sched_getaffinity(0, sizeof(current), &current) != 0) return false;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &current)) {
      cpu_set_t one;
      CPU_ZERO(&one);
      CPU_SET(cpu, &one);
      return sched_setaffinity(0, sizeof(one), &one) == 0;
    }
  }
  return false;
}

/// CPU time of this thread in milliseconds: what one core spends, whatever else the machine runs.
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

struct BenchRow {
  std::string scenario;
  int frames = 0;
  int items = 0;
  double raycast_ms = 0, sensor_ms = 0, frame_ms = 0, wall_ms = 0, nocull_ms = 0;
};

Result<BenchRow> bench_scenario(const fs::path& path, int frames, int width, int height, bool baseline) {
  auto loaded = sim::load_scenario(path);
  if (!loaded) return loaded.error();
  sim::Scenario sc = sim::with_resolution(std::move(*loaded), width, height);
  auto culled = sim::Simulator::create(sc);
  if (!culled) return culled.error();
  sim::RaycasterConfig no_cull;
  no_cull.cull = false;
  auto brute = sim::Simulator::create(sc, no_cull);
  if (!brute) return brute.error();

  using Clock = std::chrono::steady_clock;
  BenchRow row;
  row.scenario = sc.name;
  row.frames = frames;
  const int phase_frames = culled->frame_count(0);
  std::vector<double> raycast, sensor, total, wall, nocull;
  sim::IdealView view;
  ColorImage color;
  DepthImage depth;
  for (int i = -1; i < frames; ++i) {  // i = -1: warm-up
    const int f = frames > 1 ? std::max(0, i) * (phase_frames - 1) / (frames - 1) : 0;
    const auto w0 = Clock::now();
    const double t0 = thread_cpu_ms();
    culled->render_ideal(0, f, &view);
    const double t1 = thread_cpu_ms();
    culled->apply_sensor(0, f, view, &color, &depth);
    const double t2 = thread_cpu_ms();
    const auto w1 = Clock::now();
    if (baseline) brute->render_ideal(0, f, &view);
    const double t3 = thread_cpu_ms();
    if (i < 0) {
      row.items = static_cast<int>(culled->render_scene(0, f).items.size());
      continue;
    }
    raycast.push_back(t1 - t0);
    sensor.push_back(t2 - t1);
    total.push_back(t2 - t0);
    wall.push_back(std::chrono::duration<double, std::milli>(w1 - w0).count());
    nocull.push_back(t3 - t2);
  }
  row.raycast_ms = median(raycast);
  row.sensor_ms = median(sensor);
  row.frame_ms = median(total);
  row.wall_ms = median(wall);
  row.nocull_ms = median(nocull);
  return row;
}

/// `scenewatch-sim list`: each shipped scenario with its phases, frames and description.
int run_list(const std::string& scenario_dir) {
  const auto files = shipped_scenarios(scenario_dir);
  if (files.empty()) {
    std::cerr << "scenewatch-sim: no scenarios in " << scenario_dir << "\n";
    return 1;
  }
  for (const auto& f : files) {
    auto sc = sim::load_scenario(f);
    if (!sc) {
      std::printf("%-24s (invalid: %s)\n", f.stem().c_str(), sc.error().message.c_str());
      continue;
    }
    int total = 0;
    for (const auto& p : sc->phases) total += p.frames;
    std::printf("%-24s %zu phase(s), %4d frames  %s\n", f.stem().c_str(), sc->phases.size(), total,
                sc->description.c_str());
  }
  return 0;
}

/// The options of `scenewatch-sim render`.
struct RenderOptions {
  std::string scenario_arg, out_dir;
  std::optional<int> frames, width, height;
  std::optional<std::uint64_t> seed;
  std::string pcd_path;
  bool quiet = false;
};

/// `scenewatch-sim render`: writes the scenario's sequences (and, with --pcd, frame 0 as a cloud).
int run_render(const RenderOptions& o, const std::string& scenario_dir) {
  auto loaded = resolve_scenario(o.scenario_arg, scenario_dir);
  if (!loaded) return fail(loaded.error());
  auto sc = apply_overrides(std::move(*loaded), o.frames, o.seed, o.width, o.height);
  if (!sc) return fail(sc.error());
  auto simulator = sim::Simulator::create(std::move(*sc));
  if (!simulator) return fail(simulator.error());
  const bool tty = !o.quiet && ::isatty(STDERR_FILENO);
  sim::ProgressFn progress;
  if (tty) {
    progress = [](const std::string& phase, std::size_t done, std::size_t total) {
      std::fprintf(stderr, "\r%s: frame %zu/%zu", phase.c_str(), done, total);
      if (done == total) std::fprintf(stderr, "\n");
    };
  }
  auto summary = simulator->write(o.out_dir, progress);
  if (!summary) return fail(summary.error());
  for (const auto& d : summary->sequence_dirs) std::printf("%s\n", d.c_str());
  if (!summary->changes_json.empty()) std::printf("%s\n", summary->changes_json.c_str());
  if (!o.pcd_path.empty()) {
    // Rendering is deterministic: frame 0 again gives the images just written.
    const sim::SimFrame frame = simulator->render(0, 0);
    auto cloud = io::rgbd_to_cloud(frame.color, frame.depth, simulator->scenario().intrinsics, io::kDepthMillimetres,
                                   simulator->scenario().sensor.max_depth_m);
    if (!cloud) return fail(cloud.error());
    if (auto st = io::write_pcd(o.pcd_path, **cloud); !st) return fail(st.error());
    std::printf("%s\n", o.pcd_path.c_str());
  }
  return 0;
}

/// The options of `scenewatch-sim bench`.
struct BenchOptions {
  int frames = 30;
  std::vector<std::string> scenarios = {"glasses_removed", "hand_picks_cup_upright", "clutter"};
  int width = 640, height = 480;
  int repeats = 3;
  bool no_baseline = false;
};

/// `scenewatch-sim bench`: a table of median milliseconds per frame, the fastest of the repeats.
int run_bench(const BenchOptions& o, const std::string& scenario_dir) {
  if (o.frames < 1) return fail(invalid_argument("--frames must be at least 1"));
  const bool pinned = pin_to_one_core();
  std::printf("scenewatch-sim bench: %dx%d, %d frames per scenario, best of %d runs, %s\n", o.width, o.height, o.frames,
              std::max(1, o.repeats), pinned ? "pinned to one core" : "NOT pinned (sched_setaffinity failed)");
  std::printf("%-24s %5s %8s %8s %8s %7s %8s %7s %8s %7s\n", "scenario", "items", "raycast", "sensor", "frame", "fps",
              "raycast", "frame", "no-cull", "culling");
  std::printf("%-24s %5s %8s %8s %8s %7s %8s %7s %8s %7s\n", "", "", "cpu ms", "cpu ms", "cpu ms", "", "fps", "wall ms",
              "cpu ms", "speedup");
  for (const auto& name : o.scenarios) {
    const fs::path path = fs::exists(name) ? fs::path(name) : fs::path(scenario_dir) / (name + ".yaml");
    auto row = bench_scenario(path, o.frames, o.width, o.height, !o.no_baseline);
    if (!row) return fail(row.error());
    for (int r = 1; r < o.repeats; ++r) {
      auto again = bench_scenario(path, o.frames, o.width, o.height, !o.no_baseline);
      if (!again) return fail(again.error());
      if (again->frame_ms < row->frame_ms) *row = *again;
    }
    std::printf("%-24s %5d %8.2f %8.2f %8.2f %7.1f %8.1f %7.2f", row->scenario.c_str(), row->items, row->raycast_ms,
                row->sensor_ms, row->frame_ms, 1000.0 / row->frame_ms, 1000.0 / row->raycast_ms, row->wall_ms);
    if (o.no_baseline) std::printf(" %8s %7s\n", "-", "-");
    else std::printf(" %8.2f %6.1fx\n", row->nocull_ms, row->nocull_ms / row->raycast_ms);
  }
  std::printf("Medians per frame of the fastest run. cpu ms = this thread's CPU time; frame = ray casting + sensor\n"
              "model (no PNG encoding); fps = 1000 / cpu ms; no-cull = the same ray caster testing every primitive\n"
              "at every pixel (the baseline for the screen-tile and depth culling).\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"scenewatch-sim: synthetic tabletop RGB-D sequences with exact ground truth"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "scenewatch-sim " SCENEWATCH_VERSION);
  std::string scenario_dir = scenewatch::apps::scenarios_dir().string();
  app.add_option("--scenarios", scenario_dir, "Folder of the shipped scenarios")->capture_default_str();

  auto* render = app.add_subcommand("render", "Render a scenario (a YAML file or a shipped scenario's name)");
  RenderOptions r;
  render->add_option("scenario", r.scenario_arg, "Scenario YAML file or shipped scenario name")->required();
  render->add_option("--out", r.out_dir, "Output folder (one sequence, or one sub-folder per phase)")->required();
  render->add_option("--frames", r.frames, "Frames per phase (keys are rescaled in time)");
  render->add_option("--seed", r.seed, "Random seed (overrides the scenario's)");
  render->add_option("--width", r.width, "Image width (intrinsics scale with it)");
  render->add_option("--height", r.height, "Image height");
  render->add_option("--pcd", r.pcd_path, "Also write frame 0 of the first phase as an organized XYZRGB PCD (camera frame)");
  render->add_flag("--quiet", r.quiet, "No progress output");

  auto* list = app.add_subcommand("list", "List the shipped scenarios");

  auto* bench = app.add_subcommand("bench", "Frames per second at 640x480 on one core (median ms/frame)");
  BenchOptions b;
  bench->add_option("--frames", b.frames, "Frames rendered per scenario")->capture_default_str();
  bench->add_option("--scenario", b.scenarios, "Scenarios to time")->capture_default_str();
  bench->add_option("--width", b.width, "Image width")->capture_default_str();
  bench->add_option("--height", b.height, "Image height")->capture_default_str();
  bench->add_option("--repeat", b.repeats, "Runs per scenario; the fastest run's medians are reported (robust to other load)")
      ->capture_default_str();
  bench->add_flag("--no-baseline", b.no_baseline, "Skip the ray caster without culling");

  CLI11_PARSE(app, argc, argv);

  if (list->parsed()) return run_list(scenario_dir);
  if (render->parsed()) return run_render(r, scenario_dir);
  if (bench->parsed()) return run_bench(b, scenario_dir);
  return 0;
}
