// Offline: geometric change detection between two observations (no daemon).
#include <cstdio>
#include <filesystem>
#include <optional>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "config_file.h"
#include "frame_spec.h"
#include "scenewatch/change/diff.h"
#include "scenewatch/core/event_json.h"

namespace scenewatch::cli {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string fixed(double value, int decimals = 3) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

std::string text(const Eigen::Vector3d& v) { return "(" + fixed(v.x()) + ", " + fixed(v.y()) + ", " + fixed(v.z()) + ")"; }

}  // namespace

int run_diff(const DiffOptions& options) {
  change::DiffOptions diff_options;
  if (!options.config.empty()) {
    auto config = read_config_file(options.config);
    if (!config) return fail(config.error().message);
    diff_options.change = config->change;
    diff_options.map = config->background;
    diff_options.segmentation = config->segmentation;
  }
  if (options.resolution_m > 0) diff_options.map.resolution_m = options.resolution_m;
  diff_options.force_map = options.force_map;
  auto before = load_one_frame(options.before, sequence_options(options.depth_scale_m));
  if (!before) return fail("BEFORE: " + before.error().message);
  auto after = load_one_frame(options.after, sequence_options(options.depth_scale_m));
  if (!after) return fail("AFTER: " + after.error().message);
  before->source = options.before;
  after->source = options.after;
  auto result = change::diff(*before, *after, diff_options);
  if (!result) return fail(result.error().message);

  if (options.json) {
    json events = json::array();
    for (const auto& e : result->events) events.push_back(to_json(e));
    std::cout << json{{"before", options.before},
                      {"after", options.after},
                      {"method", change::to_string(result->method)},
                      {"total_ms", result->total_ms},
                      {"events", events}}
                     .dump()
              << "\n";
    return kExitOk;
  }
  std::cout << options.before << " -> " << options.after << " (" << change::to_string(result->method) << ", "
            << fixed(result->total_ms, 1) << " ms): " << result->events.size()
            << (result->events.size() == 1 ? " change" : " changes") << "\n";
  for (const auto& e : result->events) {
    std::cout << "  " << to_string(e.kind) << " at " << text(e.centroid_world) << ", box " << text(e.box_world.min)
              << " - " << text(e.box_world.max);
    if (e.displacement_world) std::cout << ", moved by " << text(*e.displacement_world);
    std::cout << ": " << e.detail << " [" << e.indices_before.size() << " points in BEFORE, " << e.indices_after.size()
              << " in AFTER]\n";
  }
  return kExitOk;
}

}  // namespace scenewatch::cli
