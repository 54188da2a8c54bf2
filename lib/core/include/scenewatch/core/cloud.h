#pragma once
/// Point clouds are PCL's: one concrete point type, XYZRGB, across the project.
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdint>
#include <vector>

namespace scenewatch {

using PointT = pcl::PointXYZRGB;
using Cloud = pcl::PointCloud<PointT>;
using CloudPtr = Cloud::Ptr;
using CloudConstPtr = Cloud::ConstPtr;

/// True when the point has finite coordinates.
inline bool is_valid(const PointT& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

/// Number of points with finite coordinates.
std::size_t count_valid(const Cloud& cloud);

}  // namespace scenewatch
