#pragma once
/// Per-pixel Bayesian surprise of an observed colour image against an expected view, and the
/// regions of high surprise as events.
#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "scenewatch/core/event.h"
#include "scenewatch/core/image.h"
#include "scenewatch/core/result.h"
#include "scenewatch/surprise/bayes.h"
#include "scenewatch/surprise/expected_view.h"
#include "scenewatch/surprise/robust.h"

namespace scenewatch::surprise {

/// KL in nats per pixel, row-major; NaN where unknown (too few samples, no expected surface).
struct SurpriseMap {
  int width = 0, height = 0;
  std::array<std::vector<float>, kChannels> channel;
  std::vector<float> total;  ///< sum over the three channels (independent pathways)
  std::size_t known_pixels = 0;
  Photometric photometric;  ///< the correction applied to the observation (identity when none)
};

/// The surprise of `observed` (same size as the view) per channel and in total. With `robust`,
/// the observation is first mapped into the memory's photometry and misalignment is tolerated
/// (robust.h); without, the plain per-pixel comparison of the seed.
Result<SurpriseMap> compute_surprise(const ExpectedView& view, const ColorImage& observed, const SurpriseKernel& kernel,
                                     const RobustConfig* robust = nullptr);

/// How the map becomes regions: hysteresis on the total, a morphological opening, connected
/// components, and a size filter.
struct RegionConfig {
  double threshold_high = 12.0;  ///< total KL (nats) that starts a region
  double threshold_low = 6.0;    ///< total KL that a region may grow through
  int open_radius_px = 1;        ///< opening of the low mask (0: none)
  int min_area_px = 40;          ///< regions smaller than this are noise
  /// Rejects regions narrower than this many pixels, per 640 pixels of image width.
  int min_extent_px = 6;
};

Status validate(const RegionConfig& config);

struct SurpriseRegion {
  PixelRegion region;
  std::array<double, kChannels> peak{}, mean{};  ///< KL per channel over the region's pixels
  double peak_total = 0, mean_total = 0;
  Aabb box_world;                  ///< from the region's pixels at their observed or expected depth
  Eigen::Vector3d centroid_world = Eigen::Vector3d::Zero();
  std::size_t points_3d = 0;       ///< pixels with a depth that went into the box
  std::vector<std::uint32_t> pixels;  ///< row-major indices
};

/// Regions of high surprise. `observed_depth` (optional, same size) places the regions in 3D
/// together with the expected depth: each pixel at the nearer of the two.
std::vector<SurpriseRegion> find_regions(const SurpriseMap& map, const ExpectedView& view,
                                         const DepthImage* observed_depth, const RegionConfig& config);

/// Everything the image-based surprise needs, as the `surprise:` config section.
struct SurpriseConfig {
  bool enabled = true;
  ExpectedViewConfig view;
  Prior prior;
  /// Fewer reference samples at a pixel: unknown. 1 lets a static camera (one keyframe) work,
  /// with the prior alone setting the colour noise.
  int min_samples = 1;
  RegionConfig regions;
  RobustConfig robust;  ///< photometric correction and misalignment tolerance
  /// In a stream, appearance alone reports a change only from a view the memory knows from at
  /// least this many frames ago (a keyframe within twice the keyframe spacing); elsewhere surprise
  /// is evidence for geometric changes only. 0: every view.
  int familiar_after_frames = 15;
  /// After this many consecutive frames with APPEARANCE_CHANGE regions from a view the memory
  /// already holds, the frame replaces the nearest keyframe: the change is remembered and stops
  /// being reported. 0: never (the memory keeps the first sight of every place).
  int adopt_after_frames = 5;
};
Status validate(const SurpriseConfig& config);

/// An APPEARANCE_CHANGE event (level MISMATCH) with the region's evidence.
Event to_event(const SurpriseRegion& region, double stamp_s);

/// A colour heatmap of the total surprise laid over the observed image (unknown pixels grey,
/// the scale saturates at `saturation` nats).
ColorImage heatmap_overlay(const SurpriseMap& map, const ColorImage& observed, double saturation = 24.0);

/// Writes the total surprise as a one-channel 32-bit float TIFF (NaN where unknown).
Status write_surprise_tiff(const std::filesystem::path& path, const SurpriseMap& map);

}  // namespace scenewatch::surprise
