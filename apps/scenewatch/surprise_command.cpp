// scenewatch surprise: the image-based Bayesian surprise of an observed frame, offline against
// reference frames (the appearance memory is built here, no daemon), or from the daemon.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "commands.h"
#include "config_file.h"
#include "format.h"
#include "frame_spec.h"
#include "scenewatch/background/appearance.h"
#include "scenewatch/io/cloud_io.h"
#include "scenewatch/io/image_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/service/client.h"
#include "scenewatch/surprise/surprise_map.h"
#include "subcommand.h"

namespace scenewatch::cli {
namespace {

using nlohmann::json;

struct Outcome {
  surprise::SurpriseMap map;
  std::vector<proto::Event> regions;
  std::size_t keyframes = 0, references_read = 0, reference_views = 0;
  double compute_ms = 0;
  std::optional<ColorImage> observed_color;
  std::optional<ColorImage> expected_color;  ///< offline only: the memory's view from the observed pose
};

// Images of one height side by side, left to right.
ColorImage side_by_side(const std::vector<const ColorImage*>& images) {
  ColorImage out;
  out.height = images.front()->height;
  for (const ColorImage* im : images) out.width += im->width;
  out.rgb.resize(static_cast<std::size_t>(3) * out.width * out.height);
  int left = 0;
  for (const ColorImage* im : images) {
    for (int y = 0; y < out.height; ++y)
      std::copy_n(im->rgb.begin() + static_cast<std::ptrdiff_t>(3) * y * im->width, 3 * im->width,
                  out.rgb.begin() + static_cast<std::ptrdiff_t>(3) * (static_cast<std::ptrdiff_t>(y) * out.width + left));
    left += im->width;
  }
  return out;
}

Status write_outputs(const SurpriseOptions& o, const Outcome& out, std::vector<std::string>& written) {
  if (!o.out_png.empty()) {
    const ColorImage background = out.observed_color.value_or(ColorImage{});
    if (auto st = io::write_color_png(o.out_png, surprise::heatmap_overlay(out.map, background, o.saturation)); !st) return st;
    written.push_back(o.out_png);
  }
  if (!o.panel_png.empty()) {
    // Observed | expected | surprise, the picture of the seed's experiment.
    if (!out.observed_color || !out.expected_color || out.observed_color->height != out.expected_color->height) {
      return invalid_argument("--panel: the observed or the expected image is missing");
    }
    const ColorImage heat = surprise::heatmap_overlay(out.map, *out.observed_color, o.saturation);
    const ColorImage panel = side_by_side({&*out.observed_color, &*out.expected_color, &heat});
    if (auto st = io::write_color_png(o.panel_png, panel); !st) return st;
    written.push_back(o.panel_png);
  }
  if (!o.raw_tiff.empty()) {
    if (auto st = surprise::write_surprise_tiff(o.raw_tiff, out.map); !st) return st;
    written.push_back(o.raw_tiff);
  }
  return {};
}

int print(const SurpriseOptions& o, const Outcome& out, const std::vector<std::string>& written) {
  if (o.json) {
    json regions = json::array();
    for (const auto& e : out.regions) regions.push_back(to_json(e));
    json j = {{"observed", o.observed},         {"width", out.map.width},
              {"height", out.map.height},        {"known_pixels", out.map.known_pixels},
              {"reference_views", out.reference_views}, {"regions", regions},
              {"compute_ms", out.compute_ms},    {"written", written}};
    if (!o.references.empty()) {
      j["references"] = o.references;
      j["reference_frames"] = out.references_read;
      j["keyframes"] = out.keyframes;
    }
    std::cout << j.dump() << std::endl;
    return kExitOk;
  }
  if (!o.references.empty())
    std::cout << "memory: " << out.keyframes << " keyframes from " << out.references_read << " reference frames\n";
  const double total = static_cast<double>(out.map.width) * out.map.height;
  std::printf("%s: %dx%d, %.0f%% of the pixels known, %zu reference views, %.1f ms\n",
              o.observed.empty() ? "last frame" : o.observed.c_str(), out.map.width, out.map.height,
              total > 0 ? 100.0 * out.map.known_pixels / total : 0.0, out.reference_views, out.compute_ms);
  std::printf("%zu surprising region%s\n", out.regions.size(), out.regions.size() == 1 ? "" : "s");
  std::fflush(stdout);
  for (const auto& e : out.regions) std::cout << text(e) << "\n";
  for (const auto& w : written) std::cout << "wrote " << w << "\n";
  std::cout << std::flush;
  return kExitOk;
}

Result<Outcome> offline(const SurpriseOptions& o) {
  auto config = read_config_file(o.config);
  if (!config) return config.error();
  std::optional<Intrinsics> intrinsics;
  if (!o.intrinsics.empty()) {
    auto K = io::read_intrinsics(o.intrinsics);
    if (!K) return K.error();
    intrinsics = *K;
  }
  // The observation first: a bad one should fail before minutes of reference loading.
  std::optional<background::Keyframe> observed;
  {
    auto n = count_frames(o.observed, sequence_options(o.depth_scale_m));
    if (!n) return n.error();
    if (*n != 1) return invalid_argument("'" + o.observed + "' names " + std::to_string(*n) + " frames; the observation must be one (SEQDIR:N)");
    auto st = for_each_frame(o.observed, intrinsics, [&](Frame f) -> Status {
      auto kf = background::keyframe_from_frame(f);
      if (!kf) return kf.error();
      if (!f.has_color) return invalid_argument("'" + o.observed + "' has no colour");
      observed = std::move(*kf);
      return {};
    }, sequence_options(o.depth_scale_m));
    if (!st) return st.error();
  }
  background::AppearanceMemory memory(config->appearance);
  std::size_t total = 0, done = 0;
  for (const auto& spec : o.references) {
    auto n = count_frames(spec, sequence_options(o.depth_scale_m));
    if (!n) return n.error();
    total += *n;
  }
  ProgressBar bar(::isatty(STDERR_FILENO) != 0);
  for (const auto& spec : o.references) {
    auto st = for_each_frame(spec, intrinsics, [&](Frame f) -> Status {
      bar.draw(++done, total, f.source);
      if (!memory.is_new_view(f.pose_or_identity())) return {};
      auto kf = background::keyframe_from_frame(f);
      if (!kf) return kf.error();
      auto added = memory.add(std::move(*kf));
      if (!added) return Error{added.error().code, f.source + ": " + added.error().message};
      return {};
    }, sequence_options(o.depth_scale_m));
    bar.clear();
    if (!st) return st.error();
  }
  Outcome out;
  out.keyframes = memory.size();
  out.references_read = done;
  const auto t0 = std::chrono::steady_clock::now();
  const surprise::SurpriseConfig& sc = config->surprise;
  const surprise::ExpectedView view =
      surprise::render_expected_view(memory, observed->T_world_camera, observed->intrinsics, sc.view);
  auto map = surprise::compute_surprise(view, observed->color, surprise::SurpriseKernel(sc.prior, sc.min_samples), &sc.robust);
  if (!map) return map.error();
  for (const auto& region : surprise::find_regions(*map, view, &observed->depth, sc.regions))
    out.regions.push_back(service::make_event_message(surprise::to_event(region, observed->stamp_s)));
  out.compute_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  out.reference_views = view.reference_views;
  out.map = std::move(*map);
  out.observed_color = observed->color;
  out.expected_color = surprise::expected_color(view);
  if (!o.expected_png.empty()) {
    if (auto st = io::write_color_png(o.expected_png, *out.expected_color); !st) return st.error();
  }
  if (!o.mesh_ply.empty()) {
    if (auto st = io::write_mesh_ply(o.mesh_ply, memory.mesh()); !st) return st.error();
  }
  return out;
}

Result<Outcome> remote(const SurpriseOptions& o, const RemoteOptions& r) {
  std::optional<Frame> observed;
  if (!o.observed.empty()) {
    auto st = for_each_frame(o.observed, std::nullopt, [&](Frame f) -> Status {
      if (observed) return invalid_argument("'" + o.observed + "' names several frames; the observation must be one");
      observed = std::move(f);
      return {};
    }, sequence_options(o.depth_scale_m));
    if (!st) return st.error();
  }
  auto got = fetch_surprise(r, observed ? &*observed : nullptr);
  if (!got) return got.error();
  Outcome out;
  out.map.width = got->width;
  out.map.height = got->height;
  out.map.total = std::move(got->total);
  out.map.known_pixels = got->known_pixels;
  out.regions = std::move(got->regions);
  out.reference_views = got->reference_views;
  out.compute_ms = got->compute_ms;
  if (observed) {
    auto kf = background::keyframe_from_frame(*observed);
    if (kf) out.observed_color = kf->color;
  }
  return out;
}

}  // namespace

int run_surprise(const SurpriseOptions& o, const RemoteOptions& r) {
  if (!o.expected_png.empty() && o.references.empty()) return fail("--expected needs --reference (offline)");
  if (!o.mesh_ply.empty() && o.references.empty()) return fail("--mesh needs --reference (offline)");
  if (!o.panel_png.empty() && o.references.empty()) return fail("--panel needs --reference (offline: the expected image is rendered here)");
  if (!o.references.empty() && o.observed.empty()) return fail("an observed frame is needed with --reference");
  auto out = o.references.empty() ? remote(o, r) : offline(o);
  if (!out) return fail(out.error().message);
  std::vector<std::string> written;
  if (!o.expected_png.empty()) written.push_back(o.expected_png);
  if (!o.mesh_ply.empty()) written.push_back(o.mesh_ply);
  if (auto st = write_outputs(o, *out, written); !st) return fail(st.error().message);
  return print(o, *out, written);
}

void add_surprise_command(CLI::App& app, RemoteOptions& remote, Action& action) {
  auto options = std::make_shared<SurpriseOptions>();
  auto* surprise = app.add_subcommand(
      "surprise",
      "image-based Bayesian surprise of an observed RGB-D frame: offline against --reference frames, or "
      "from the daemon's appearance memory when no reference is given");
  surprise->footer(
      "Frames: FILE.pcd|FILE.ply (an organized cloud, same camera as its references; intrinsics are recovered "
      "from its points unless --intrinsics), SEQDIR (every frame of a sequence, with its poses), SEQDIR:N (frame "
      "N, 0-based), SEQDIR:A-B.\n"
      "Examples:\n"
      "  scenewatch surprise after/:40 --reference before/ --out heat.png --raw kl.tiff\n"
      "  scenewatch surprise learn13.pcd --reference learn12.pcd --json\n"
      "  scenewatch surprise --out heat.png          (the daemon's last posed frame)");
  surprise->add_option("observed", options->observed, "the observed frame (optional with the daemon)");
  surprise->add_option("--reference,-r", options->references,
                       "reference frames (repeatable); without any, the daemon is asked");
  surprise->add_option("--out,-o", options->out_png, "write the surprise as a heatmap over the observed image (PNG)");
  surprise->add_option("--raw", options->raw_tiff, "write the total surprise per pixel, KL in nats, as 32-bit float TIFF (NaN: unknown)");
  surprise->add_option("--expected", options->expected_png, "offline: write the expected (virtual) image (PNG)");
  surprise->add_option("--panel", options->panel_png,
                       "offline: write the observed image, the expected image and the surprise heatmap side by side (PNG)");
  surprise->add_option("--mesh", options->mesh_ply, "offline: write the references' textured mesh (PLY)");
  surprise->add_option("--intrinsics", options->intrinsics, "3x3 camera matrix file for cloud files");
  surprise->add_option("--config", options->config, "YAML config (its appearance and surprise sections are used)");
  surprise->add_option("--saturation", options->saturation, "heatmap scale: nats shown as the hottest colour")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  add_depth_scale_option(surprise, options->depth_scale_m);
  add_remote_options(surprise, remote);  // --json among them: regions as APPEARANCE_CHANGE events
  on_parsed(surprise, action, [&remote, options] {
    options->json = remote.json;
    return run_surprise(*options, remote);
  });
}

}  // namespace scenewatch::cli
