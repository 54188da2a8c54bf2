// Offline: geometric change detection between two observations (no daemon).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "config_file.h"
#include "frame_spec.h"
#include "scenewatch/change/diff.h"
#include "scenewatch/core/event_json.h"
#include "subcommand.h"

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

void add_diff_command(CLI::App& app, Action& action) {
  auto options = std::make_shared<DiffOptions>();
  auto* diff = app.add_subcommand(
      "diff",
      "offline: objects added, removed or moved from BEFORE to AFTER (no daemon).\n"
      "BEFORE and AFTER are cloud files (.pcd/.ply) or frames of RGB-D sequences (DIR/frame-NNNNNN, with\n"
      "their poses). Organized clouds of one unmoved camera are compared pixel by pixel; otherwise BEFORE\n"
      "goes into an occupancy map and AFTER is checked against it at its pose. Added: AFTER points in space\n"
      "BEFORE saw free. Removed: BEFORE surfaces AFTER's rays pass through. Occluded or unseen space\n"
      "claims nothing. --json lists each event with the indices of its points in BEFORE and AFTER.");
  diff->add_option("before", options->before, "the earlier observation")->required();
  diff->add_option("after", options->after, "the later observation")->required();
  diff->add_flag("--json", options->json, "print JSON: events with point indices, world boxes, evidence");
  diff->add_option("--config", options->config, "YAML config (its change and background sections are used)");
  diff->add_flag("--force-map", options->force_map, "compare through the occupancy map even for same-camera pairs");
  diff->add_option("--resolution", options->resolution_m, "map voxel edge in metres for the map path")
      ->check(CLI::Range(0.002, 0.2));
  add_depth_scale_option(diff, options->depth_scale_m);
  on_parsed(diff, action, [options] { return run_diff(*options); });
}

}  // namespace scenewatch::cli
