// scenewatch-bench: prints the figures docs/benchmarks.md quotes, each next to its baseline in the same run.
#include <CLI/CLI.hpp>

#include "bench.h"
#include "scenewatch/core/memory.h"

namespace {
/// The sections in the order main runs them; sensor and memory run only when named.
const std::vector<std::string> kSections = {"octomap", "segmentation", "clutter", "latency", "surprise", "change", "stream",
                                            "sensor", "pipeline", "foreground", "fit", "localization", "nbv", "memory"};
}  // namespace

int main(int argc, char** argv) {
  scenewatch::keep_frame_buffers_in_heap();  // as the daemon runs
  CLI::App app{"scenewatch-bench: time scenewatch against its baselines on real frames (prints tables; not a test)"};
  scenewatch::bench::Options o;
  o.data_dir = SCENEWATCH_DEFAULT_DATA_DIR;
  std::vector<std::string> only;
  app.add_option("--data", o.data_dir, "Folder of the real recordings (../shared/data)")->capture_default_str();
  app.add_option("--repetitions,-n", o.repetitions, "Timed runs per case; medians are reported")->capture_default_str()->check(CLI::Range(1, 1000));
  app.add_option("--only", only, "Run only these sections: octomap, segmentation, clutter, latency, surprise, change, stream, sensor, pipeline, foreground, fit, localization, nbv, memory (memory runs only when named: 1000 frames; sensor, 7000 kitchen frames, only when named)")
      ->check(CLI::IsMember(kSections));
  bool dry_run = false;
  app.add_flag("--dry-run", dry_run, "Check the arguments, print the sections they select and run nothing (scripts/bench --docs --check)");
  CLI11_PARSE(app, argc, argv);
  // Every section when none is named, but the long ones (sensor, memory) only by name.
  auto want = [&](const std::string& s) {
    const bool named = std::find(only.begin(), only.end(), s) != only.end();
    return named || (only.empty() && s != "sensor" && s != "memory");
  };
  if (dry_run) {
    std::printf("scenewatch-bench: would run");
    for (const std::string& s : kSections)
      if (want(s)) std::printf(" %s", s.c_str());
    std::printf(" (-n %d, data %s)\n", o.repetitions, o.data_dir.c_str());
    return 0;
  }
  if (!std::filesystem::exists(o.data_dir)) {
    std::fprintf(stderr, "scenewatch-bench: data folder '%s' not found (pass --data DIR)\n", o.data_dir.c_str());
    return 1;
  }
  int rc = 0;
  if (want("octomap")) rc |= scenewatch::bench::run_octomap(o);
  if (want("segmentation")) rc |= scenewatch::bench::run_segmentation(o);
  if (want("clutter")) rc |= scenewatch::bench::run_clutter(o);
  if (want("latency")) rc |= scenewatch::bench::run_latency(o);
  if (want("surprise")) rc |= scenewatch::bench::run_surprise(o);
  if (want("change")) rc |= scenewatch::bench::run_change(o);
  if (want("stream")) rc |= scenewatch::bench::run_stream(o);
  if (want("sensor")) rc |= scenewatch::bench::run_sensor_model(o);
  if (want("pipeline")) rc |= scenewatch::bench::run_pipeline(o);
  if (want("foreground")) rc |= scenewatch::bench::run_foreground(o);
  if (want("fit")) rc |= scenewatch::bench::run_fit(o);
  if (want("localization")) rc |= scenewatch::bench::run_localization(o);
  if (want("nbv")) rc |= scenewatch::bench::run_nbv(o);
  if (want("memory")) rc |= scenewatch::bench::run_memory(o);
  return rc;
}
