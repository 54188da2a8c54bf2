#include "scenewatch/change/pose_agreement.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

namespace scenewatch::change {
namespace {

constexpr std::size_t kMinSamples = 100;
// Residuals beyond this many metres are occlusions or changes, not misalignment.
constexpr double kWindowM = 0.15;
// Surfaces seen more obliquely than this give no normal worth fitting to (cos 75 degrees).
constexpr double kMinCosIncidence = 0.26;
// The normal's central differences span this much surface ...
constexpr double kNormalBaselineM = 0.04;
// ... and at most this many pixels.
constexpr int kMaxNormalBaselinePx = 16;
constexpr int kRounds = 3;
// Correspondences found anew this many times (ICP's outer loop).
constexpr int kIterations = 3;
// A step that moves a point kFarM away by less than kConvergedFraction of a voxel has converged.
constexpr double kFarM = 3.0;
constexpr double kConvergedFraction = 0.01;

struct Sample {
  Eigen::Vector3d world = Eigen::Vector3d::Zero();  // the observed point, placed with the given pose
  Eigen::Matrix<double, 6, 1> J;  // d(residual) / d(rotation, translation) of the camera
  double e = 0.0;                  // point-to-plane residual, metres
  double sigma = 0.0;              // its noise, metres
};

// The frame's own surface normal at pixel (u, v), facing the camera; none at edges and holes.
// Central differences over kNormalBaselineM: over a few pixels, depth noise at range would tilt
// the normals at random, and noisy normals bias the fitted motion towards zero.
bool normal_at(const Cloud& cloud, int u, int v, const DepthValidity& trusted, double focal_px, Eigen::Vector3d& n) {
  const double z = cloud.points[static_cast<std::size_t>(v) * cloud.width + u].z;
  const int b = std::clamp(static_cast<int>(std::lround(kNormalBaselineM * focal_px / z)), 2, kMaxNormalBaselinePx);
  if (!trusted.has(u - b, v) || !trusted.has(u + b, v) || !trusted.has(u, v - b) || !trusted.has(u, v + b)) return false;
  auto at = [&](int x, int y) { return cloud.points[static_cast<std::size_t>(y) * cloud.width + x].getVector3fMap().cast<double>(); };
  n = (at(u + b, v) - at(u - b, v)).cross(at(u, v + b) - at(u, v - b));
  const double len = n.norm();
  if (!(len > 0)) return false;
  n /= len;
  if (n.dot(at(u, v)) > 0) n = -n;
  return true;
}

// The map's surface along a ray near `range`: the middle of the first run of occupied voxels in
// the window (noise and a slanted surface make a surface a few voxels thick along a ray).
bool surface_along(const background::DenseGrid& grid, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                   double range, double& surface) {
  const double step = 0.5 * grid.resolution;
  // Walked in voxel units: a step adds half a voxel along the ray, with no division per sample.
  const Eigen::Vector3d q0 = (origin + (range - kWindowM) * dir - grid.origin) / grid.resolution;
  const Eigen::Vector3d dq = 0.5 * dir;
  const int steps = static_cast<int>(std::floor(2 * kWindowM / step + 1e-9));
  double entry = -1, exit = -1;
  for (int n = 0; n <= steps; ++n) {
    const Eigen::Vector3d q = q0 + n * dq;
    const long i = static_cast<long>(std::floor(q.x())), j = static_cast<long>(std::floor(q.y())),
               k = static_cast<long>(std::floor(q.z()));
    const bool inside = i >= 0 && j >= 0 && k >= 0 && i < grid.nx && j < grid.ny && k < grid.nz;
    const double s = range - kWindowM + n * step;
    if (inside && grid.at((k * grid.ny + j) * grid.nx + i) == background::Occupancy::kOccupied) {
      if (entry < 0) entry = s;
      exit = s;
    } else if (entry >= 0) {
      break;
    }
  }
  if (entry < 0) return false;
  surface = 0.5 * (entry + exit);
  return true;
}

// A trusted pixel with a normal of its own: what does not depend on the pose, found once.
struct Pixel {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  // the observed point, camera frame
  Eigen::Vector3d n = Eigen::Vector3d::Zero();  // its surface normal, camera frame, facing the camera
  double sigma = 0.0;                           // its noise with the map's quantization, metres
};

std::vector<Pixel> pixels_of(const Cloud& cloud, const DepthValidity& trusted, double focal_px, const SensorModel& sensor,
                             double resolution, int step_px) {
  const double quantization2 = resolution * resolution / 12.0;
  std::vector<Pixel> out;
  const int w = static_cast<int>(cloud.width), h = static_cast<int>(cloud.height);
  for (int v = step_px / 2; v < h; v += step_px)
    for (int u = step_px / 2; u < w; u += step_px) {
      if (!trusted.has(u, v)) continue;
      Pixel px;
      if (!normal_at(cloud, u, v, trusted, focal_px, px.n)) continue;
      const PointT& p = cloud.points[static_cast<std::size_t>(v) * w + u];
      px.p = p.getVector3fMap().cast<double>();
      px.sigma = std::sqrt(std::pow(sensor.sigma_z(p.z), 2) + quantization2);
      out.push_back(px);
    }
  return out;
}

// The samples of a frame placed with pose T: rays of its pixels that meet a map surface.
std::vector<Sample> collect(const background::DenseGrid& grid, const std::vector<Pixel>& pixels, const Pose& T) {
  const Eigen::Vector3d origin = T.translation();
  std::vector<Sample> samples;
  samples.reserve(pixels.size());
  for (const Pixel& px : pixels) {
    const Eigen::Vector3d ray = T * px.p - origin;
    const double range = ray.norm();
    if (!(range > kWindowM)) continue;
    const Eigen::Vector3d dir = ray / range;
    const Eigen::Vector3d n = T.linear() * px.n;
    if (-n.dot(dir) < kMinCosIncidence) continue;
    double surface = 0;
    if (!surface_along(grid, origin, dir, range, surface)) continue;
    Sample s;
    s.world = origin + ray;
    // Point-to-plane: the observed point's offset from the map's surface point on its ray,
    // along the normal. A camera motion (rotation w about its centre, translation t) moves the
    // point by w x ray + t.
    s.e = (range - surface) * n.dot(dir);
    s.J.head<3>() = ray.cross(n);
    s.J.tail<3>() = n;
    s.sigma = px.sigma;
    samples.push_back(s);
  }
  return samples;
}

// One robust least-squares step (Huber weights, refitted kRounds times): the camera motion that
// best explains the samples' residuals. False when the samples do not constrain all six motions
// (a frame that sees one plane).
bool fit_motion(const std::vector<Sample>& samples, Eigen::Matrix<double, 6, 1>& delta, double& rms) {
  delta.setZero();
  double sum_e2 = 0, sum_w = 0;
  for (int round = 0; round < kRounds; ++round) {
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    sum_e2 = sum_w = 0;
    for (const Sample& s : samples) {
      const double e = s.e + s.J.dot(delta);
      const double huber = 2.0 * s.sigma;
      const double weight = (std::abs(e) <= huber ? 1.0 : huber / std::abs(e)) / (s.sigma * s.sigma);
      A += weight * s.J * s.J.transpose();
      b += weight * s.J * s.e;
      sum_e2 += weight * s.e * s.e;
      sum_w += weight;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(A);
    if (!(eig.eigenvalues()(0) > 1e-6 * eig.eigenvalues()(5))) return false;
    delta = -A.ldlt().solve(b);
  }
  rms = std::sqrt(sum_e2 / sum_w);
  return true;
}

}  // namespace

double PoseAgreement::shift_at(const Eigen::Vector3d& p_world) const { return (correction * p_world - p_world).norm(); }

PoseAgreement pose_agreement(const background::DenseGrid& grid, const Cloud& cloud, const Pose& T, const Intrinsics& K,
                             const DepthValidity& trusted, const SensorModel& sensor, int step_px) {
  const double focal_px = std::min(K.fx, K.fy);
  PoseAgreement out;
  if (cloud.height <= 1 || grid.size() == 0 || trusted.width != static_cast<int>(cloud.width)) return out;
  // ICP's outer loop: correspondences found again along the rays of the corrected pose.
  Pose corrected = T;
  std::vector<Sample> first;
  const std::vector<Pixel> pixels = pixels_of(cloud, trusted, focal_px, sensor, grid.resolution, step_px);
  for (int iteration = 0; iteration < kIterations; ++iteration) {
    std::vector<Sample> samples = collect(grid, pixels, corrected);
    if (iteration == 0) out.samples = samples.size();
    Eigen::Matrix<double, 6, 1> delta;
    double rms = 0;
    if (samples.size() < kMinSamples || !fit_motion(samples, delta, rms)) {
      if (iteration == 0) return out;  // nothing measured
      break;
    }
    if (iteration == 0) {
      out.rms_residual_m = rms;
      first = std::move(samples);
    }
    // The motion moves world points: p -> R p' + t with p' = p - origin, about the camera centre.
    Pose motion = Pose::Identity();
    const double angle = delta.head<3>().norm();
    if (angle > 0) motion.linear() = Eigen::AngleAxisd(angle, delta.head<3>() / angle).toRotationMatrix();
    const Eigen::Vector3d origin = corrected.translation();
    motion.translation() = origin - motion.linear() * origin + delta.tail<3>();
    corrected = motion * corrected;
    // Converged: this step moved the points it was fitted on by well under the map's resolution,
    // so new correspondences along the corrected rays would be the same ones.
    if (delta.tail<3>().norm() + delta.head<3>().norm() * kFarM < kConvergedFraction * grid.resolution) break;
  }
  // The misalignment: the motion that takes the frame from its given pose to the corrected one.
  out.correction = corrected * T.inverse();
  out.translation_m = (T.translation() - corrected.translation()).norm();
  out.rotation_deg = Eigen::AngleAxisd(out.correction.linear()).angle() * 180.0 / M_PI;
  double sum = 0;
  for (const Sample& s : first) sum += std::pow(out.shift_at(s.world), 2);
  out.rms_shift_m = std::sqrt(sum / static_cast<double>(first.size()));
  return out;
}

}  // namespace scenewatch::change
