#pragma once
/// ORB features of a view with their 3D points (back-projected with the view's depth), for
/// relocalization (the seed's homing, D5.1 section 4.1.2). Only keypoints with a usable depth are
/// kept: matches of two views are then 3D-3D correspondences.
#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "scenewatch/core/frame.h"
#include "scenewatch/core/geometry.h"
#include "scenewatch/core/image.h"
#include "scenewatch/core/result.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch::localization {

struct FeatureConfig {
  /// ORB keypoints detected per view (OpenCV's ORB, Rublee et al. ICCV 2011), before those without depth go.
  int max_features = 1000;
  /// ORB's pyramid: scale step and levels (OpenCV's defaults).
  double scale_factor = 1.2;
  int levels = 8;
};

Status validate(const FeatureConfig& config);

/// 256-bit ORB descriptor.
using Descriptor = std::array<std::uint8_t, 32>;

/// The features of one view, strongest keypoint first. Value type; not synchronised.
struct ViewFeatures {
  std::vector<Eigen::Vector3f> points_camera;  ///< the keypoint's 3D point in the view's camera frame
  std::vector<float> pixel_size;               ///< keypoint scale in pixels of the input (its ORB level's)
  std::vector<Descriptor> descriptors;
  std::size_t size() const { return descriptors.size(); }
  bool empty() const { return descriptors.empty(); }
};

/// From a colour image and a depth image in millimetres of one size (a keyframe's).
ViewFeatures extract_features(const ColorImage& color, const DepthImage& depth, const Intrinsics& K, const SensorModel& sensor,
                              const FeatureConfig& config);

/// From an organized frame (its points' z is the depth, their colour the image). Empty when the
/// frame is not organized with intrinsics.
ViewFeatures extract_features(const Frame& frame, const SensorModel& sensor, const FeatureConfig& config);

/// One keyframe's features as saved with the model: the keyframe's pose identifies it on load
/// (keyframe ids are renumbered when a model is loaded).
struct SavedFeatures {
  Pose T_world_camera = Pose::Identity();
  ViewFeatures features;
};

/// Writes the records to one binary file (little-endian, versioned).
Status save_features(const std::filesystem::path& path, const std::vector<SavedFeatures>& records);
/// Reads a file written by save_features; an error naming the file when it is truncated or not one.
Result<std::vector<SavedFeatures>> load_features(const std::filesystem::path& path);

}  // namespace scenewatch::localization
