// Relocalization: ORB matches with every keyframe, the best candidates' 3D-3D RANSAC.
#include "scenewatch/localization/relocalizer.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace scenewatch::localization {
namespace {

// ORB-SLAM's strict matching threshold (Mur-Artal et al. 2015, TH_LOW): above it two 256-bit
// descriptors are not one corner.
constexpr int kMaxHamming = 50;

// Hamming distance of two 256-bit descriptors; the hardware popcount where the CPU has one
// (chosen at load time).
__attribute__((target_clones("popcnt", "default"))) int hamming(const Descriptor& a, const Descriptor& b) {
  int d = 0;
  for (int w = 0; w < 4; ++w) {
    std::uint64_t x, y;
    std::memcpy(&x, a.data() + 8 * w, 8);
    std::memcpy(&y, b.data() + 8 * w, 8);
    d += __builtin_popcountll(x ^ y);
  }
  return d;
}

bool same_pose(const Pose& a, const Pose& b) {
  const auto d = background::view_distance(a, b);
  return d.translation_m < 1e-3 && d.rotation_deg < 0.1;
}

}  // namespace

Status validate(const RelocalizerConfig& c) {
  if (auto st = validate(c.features); !st) return st;
  if (c.ransac.iterations < 10 || c.ransac.iterations > 100000) return invalid_argument("localization.ransac_iterations: must be in [10, 100000]");
  if (c.candidate_keyframes < 1 || c.candidate_keyframes > 20) return invalid_argument("localization.candidate_keyframes: must be in [1, 20]");
  if (!(c.match_ratio > 0 && c.match_ratio <= 1)) return invalid_argument("localization.match_ratio: must be in (0, 1]");
  if (c.min_inliers < 3) return invalid_argument("localization.min_feature_inliers: must be at least 3");
  if (c.retrieval_features < 20) return invalid_argument("localization.retrieval_features: must be at least 20");
  if (!(c.tolerance_sigmas > 0 && c.tolerance_sigmas <= 10)) return invalid_argument("localization.tolerance_sigmas: must be in (0, 10]");
  return {};
}

Relocalizer::Relocalizer(RelocalizerConfig config, SensorModel sensor) : config_(std::move(config)), sensor_(std::move(sensor)) {}

const ViewFeatures& Relocalizer::features(const background::Keyframe& kf) {
  auto it = cache_.find(kf.id);
  if (it == cache_.end())
    it = cache_.emplace(kf.id, extract_features(kf.color, kf.depth, kf.intrinsics, sensor_, config_.features)).first;
  return it->second;
}

// One point's noise, 1 sigma: axial from the sensor model at its depth; lateral from the
// sensor's lateral noise, the colour-depth registration and the keypoint's scale, in pixels at
// its depth.
double Relocalizer::tolerance_m(const Eigen::Vector3f& p, float pixel_size, double focal_px) const {
  const double z = p.z();
  const double lateral_px = std::sqrt(sensor_.lateral_px * sensor_.lateral_px + sensor_.registration_px * sensor_.registration_px +
                                      static_cast<double>(pixel_size) * pixel_size);
  const double lateral_m = lateral_px * z / focal_px, axial_m = sensor_.sigma_z(z);
  return std::sqrt(lateral_m * lateral_m + axial_m * axial_m);
}

std::vector<Correspondence> Relocalizer::correspondences(const ViewFeatures& frame, double frame_focal_px, const ViewFeatures& kf,
                                                         double kf_focal_px, std::size_t frame_limit) const {
  std::vector<Correspondence> pairs;
  if (kf.size() < 2) return pairs;
  for (std::size_t i = 0; i < std::min(frame.size(), frame_limit); ++i) {
    int best = 257, second = 257;
    std::size_t j = 0;
    for (std::size_t k = 0; k < kf.size(); ++k) {
      const int d = hamming(frame.descriptors[i], kf.descriptors[k]);
      if (d < best) {
        second = best;
        best = d;
        j = k;
      } else if (d < second) {
        second = d;
      }
    }
    if (best > kMaxHamming || best >= config_.match_ratio * second) continue;
    const double sa = tolerance_m(frame.points_camera[i], frame.pixel_size[i], frame_focal_px);
    const double sb = tolerance_m(kf.points_camera[j], kf.pixel_size[j], kf_focal_px);
    pairs.push_back({kf.points_camera[j].cast<double>(), frame.points_camera[i].cast<double>(),
                     config_.tolerance_sigmas * std::sqrt(sa * sa + sb * sb)});
  }
  return pairs;
}

std::vector<Hypothesis> Relocalizer::hypotheses(const ViewFeatures& frame, double focal_px,
                                                const std::vector<std::shared_ptr<const background::Keyframe>>& keyframes) {
  struct Candidate {
    std::shared_ptr<const background::Keyframe> keyframe;
    std::vector<Correspondence> pairs;
  };
  // Retrieval: the keyframes sharing most of the frame's strongest features (a view of the same
  // corners); then all of the frame's features are matched with those candidates only.
  std::vector<Candidate> candidates;
  for (const auto& kf : keyframes) {
    auto pairs = correspondences(frame, focal_px, features(*kf), kf->intrinsics.fx, config_.retrieval_features);
    candidates.push_back({kf, std::move(pairs)});
  }
  const std::size_t n = std::min(config_.candidate_keyframes, candidates.size());
  std::partial_sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(n), candidates.end(),
                    [](const Candidate& a, const Candidate& b) { return a.pairs.size() > b.pairs.size(); });
  candidates.resize(n);
  for (auto& c : candidates) c.pairs = correspondences(frame, focal_px, features(*c.keyframe), c.keyframe->intrinsics.fx, frame.size());
  std::vector<Hypothesis> out;
  for (std::size_t c = 0; c < n; ++c) {
    if (candidates[c].pairs.size() < config_.min_inliers) continue;
    const RigidFit fit = fit_rigid_ransac(candidates[c].pairs, config_.ransac);
    if (fit.inliers.size() < config_.min_inliers) continue;
    out.push_back({candidates[c].keyframe->T_world_camera * fit.T_target_source, candidates[c].keyframe, candidates[c].pairs.size(),
                   fit.inliers.size(), fit.rms_m});
  }
  std::sort(out.begin(), out.end(), [](const Hypothesis& a, const Hypothesis& b) { return a.inliers > b.inliers; });
  return out;
}

std::vector<SavedFeatures> Relocalizer::to_save(const std::vector<std::shared_ptr<const background::Keyframe>>& keyframes) const {
  std::vector<SavedFeatures> out;
  for (const auto& kf : keyframes) {
    const auto it = cache_.find(kf->id);
    if (it != cache_.end()) out.push_back({kf->T_world_camera, it->second});
  }
  return out;
}

std::size_t Relocalizer::restore(const std::vector<SavedFeatures>& saved, const std::vector<std::shared_ptr<const background::Keyframe>>& keyframes) {
  cache_.clear();
  std::size_t taken = 0;
  for (const auto& kf : keyframes) {
    for (const auto& record : saved) {
      if (!same_pose(record.T_world_camera, kf->T_world_camera)) continue;
      cache_[kf->id] = record.features;
      ++taken;
      break;
    }
  }
  return taken;
}

}  // namespace scenewatch::localization
