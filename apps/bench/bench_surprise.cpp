// Surprise: the KL stage alone at 640x480 x 3 channels, the fast kernel (one division and one
// branch-free log per pixel, constants per n tabulated) against the closed form evaluated
// literally per pixel (Boost lgamma and digamma, double); and the whole appearance path at VGA:
// expected depth from the mesh, 7 reference views sampled, KL, regions.
#include <cmath>
#include <cstdio>
#include <random>

#include "bench.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "scenewatch/surprise/surprise_map.h"

namespace scenewatch::bench {
namespace {

using namespace scenewatch::surprise;

void kl_stage(const Options& o) {
  const std::size_t n = 640 * 480;
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> level(-0.5f, 1.0f), spread(0.0f, 0.01f);
  std::uniform_int_distribution<int> samples(2, kMaxSamples);
  std::vector<std::uint8_t> count(n);
  std::array<std::vector<float>, kChannels> mean, ssd, obs, out;
  for (int c = 0; c < kChannels; ++c) {
    mean[c].resize(n);
    ssd[c].resize(n);
    obs[c].resize(n);
    out[c].resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      mean[c][i] = level(rng);
      ssd[c][i] = spread(rng);
      obs[c][i] = level(rng);
    }
  }
  for (auto& k : count) k = static_cast<std::uint8_t>(samples(rng));
  const Prior prior;
  const SurpriseKernel kernel(prior, 2);
  std::vector<float> total(n);
  const float* means[kChannels] = {mean[0].data(), mean[1].data(), mean[2].data()};
  const float* ssds[kChannels] = {ssd[0].data(), ssd[1].data(), ssd[2].data()};
  const float* observed[kChannels] = {obs[0].data(), obs[1].data(), obs[2].data()};
  float* outs[kChannels] = {out[0].data(), out[1].data(), out[2].data()};
  std::vector<double> fast, literal;
  double checksum_fast = 0, checksum_literal = 0;
  for (int r = 0; r < o.repetitions; ++r) {
    fast.push_back(time_ms([&] {
      kernel.run_channels(kChannels, count.data(), means, ssds, observed, outs, total.data(), n);
    }));
    checksum_fast = 0;
    for (int c = 0; c < kChannels; ++c) for (float v : out[c]) checksum_fast += v;
    literal.push_back(time_ms([&] {
      checksum_literal = 0;
      for (int c = 0; c < kChannels; ++c) {
        for (std::size_t i = 0; i < n; ++i) {
          const double a = prior.a0 + 0.5 * count[i], b = prior.b0 + 0.5 * ssd[c][i];
          const double d = obs[c][i] - mean[c][i];
          checksum_literal += gamma_kl(a + 0.5, b + 0.5 * d * d, a, b);
        }
      }
    }));
  }
  std::printf("\n## Surprise: KL stage, 640x480 x 3 channels, one core (median of %d)\n\n", o.repetitions);
  std::printf("| kernel | ms per frame | frames/s | ratio |\n|---|---:|---:|---:|\n");
  std::printf("| scenewatch (tabulated constants, float, fast log) | %.2f | %.0f | %.1fx |\n", median(fast), 1000 / median(fast),
              median(literal) / median(fast));
  std::printf("| closed form per pixel (Boost lgamma/digamma, double) | %.2f | %.0f | 1.0x |\n", median(literal),
              1000 / median(literal));
  std::printf("| seed D5.1 (GPU pixel shader, 320x240, Stirling approximations) | %.1f | 14 | - |\n", 1000.0 / 14);
  std::printf("\nSum of KL over the frame: %.6g (fast) vs %.6g (closed form), relative difference %.2e.\n", checksum_fast,
              checksum_literal, std::abs(checksum_fast - checksum_literal) / checksum_literal);
}

int appearance_path(const Options& o) {
  auto loaded = sim::load_scenario(std::filesystem::path(SCENEWATCH_SOURCE_DIR) / "sample_clouds/scenarios/glasses_removed.yaml");
  if (!loaded) {
    std::fprintf(stderr, "bench surprise: %s\n", loaded.error().message.c_str());
    return 1;
  }
  auto simulator = sim::Simulator::create(*loaded);  // 640x480
  if (!simulator) {
    std::fprintf(stderr, "bench surprise: %s\n", simulator.error().message.c_str());
    return 1;
  }
  const Intrinsics K = loaded->intrinsics;
  // References: the first circle's frames around the observation's bearing, every keyframe kept.
  background::AppearanceMemory memory;
  for (int f = 0; f < simulator->frame_count(0); f += 1) {
    const sim::FrameTruth truth = simulator->frame_truth(0, f);
    if (!memory.is_new_view(truth.T_world_camera_reported)) continue;
    const sim::SimFrame frame = simulator->render(0, f);
    background::Keyframe kf;
    kf.color = frame.color;
    kf.depth = frame.depth;
    kf.T_world_camera = truth.T_world_camera_reported;
    kf.intrinsics = K;
    (void)memory.add(std::move(kf));
  }
  const SurpriseKernel kernel;
  const RegionConfig regions;
  std::vector<double> depth_ms, sample_ms, kl_ms, region_ms, total_ms;
  std::size_t views = 0, known = 0, found = 0;
  const int frames[] = {30, 60, 90, 120, 150, 180};
  for (int r = 0; r < o.repetitions; ++r) {
    for (int f : frames) {
      const sim::SimFrame observed = simulator->render(1, f);
      const Pose pose = observed.truth.T_world_camera_reported;
      background::DepthMap depth;
      std::vector<std::shared_ptr<const background::Keyframe>> refs;
      ExpectedView view;
      Result<SurpriseMap> map = SurpriseMap{};
      std::vector<SurpriseRegion> out;
      const double t_depth = time_ms([&] {
        refs = memory.nearest(pose, kMaxSamples);
        const std::size_t nd = std::min<std::size_t>(refs.size(), static_cast<std::size_t>(memory.config().depth_views));
        depth = memory.render_depth(pose, K, {refs.begin(), refs.begin() + static_cast<std::ptrdiff_t>(nd)});
      });
      const double t_sample = time_ms([&] { view = sample_expected_view(depth, refs, pose, K); });
      const double t_kl = time_ms([&] { map = compute_surprise(view, observed.color, kernel); });
      const double t_regions = time_ms([&] { out = find_regions(*map, view, &observed.depth, regions); });
      depth_ms.push_back(t_depth);
      sample_ms.push_back(t_sample);
      kl_ms.push_back(t_kl);
      region_ms.push_back(t_regions);
      total_ms.push_back(t_depth + t_sample + t_kl + t_regions);
      views = view.reference_views;
      known = map->known_pixels;
      found = out.size();
    }
  }
  std::printf("\n## Surprise: expected view + surprise at 640x480 with %zu reference views, one core\n\n", views);
  std::printf("glasses_removed, memory of %zu keyframes (%zu mesh triangles, %.0f MB); 6 observations of the second circle x %d.\n\n",
              memory.size(), memory.triangle_count(), memory.memory_bytes() / 1048576.0, o.repetitions);
  std::printf("| stage | median ms | p90 ms |\n|---|---:|---:|\n");
  std::printf("| expected depth (mesh patches of 3 nearest keyframes) | %.2f | %.2f |\n", median(depth_ms), quantile(depth_ms, 0.9));
  std::printf("| colour samples from 7 keyframes (depth-consistency test) | %.2f | %.2f |\n", median(sample_ms), quantile(sample_ms, 0.9));
  std::printf("| KL, 3 channels (incl. opponent conversion) | %.2f | %.2f |\n", median(kl_ms), quantile(kl_ms, 0.9));
  std::printf("| regions (hysteresis, opening, components, boxes) | %.2f | %.2f |\n", median(region_ms), quantile(region_ms, 0.9));
  std::printf("| **total** | **%.2f** | %.2f |\n", median(total_ms), quantile(total_ms, 0.9));
  std::printf("\nLast frame: %zu known pixels of %d, %zu regions.\n", known, K.width * K.height, found);
  return 0;
}

}  // namespace

int run_surprise(const Options& o) {
  kl_stage(o);
  return appearance_path(o);
}

}  // namespace scenewatch::bench
