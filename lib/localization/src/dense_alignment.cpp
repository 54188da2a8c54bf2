// Dense RGB-D alignment: point-to-plane plus photometric Gauss-Newton, coarse to fine.
#include "scenewatch/localization/dense_alignment.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <Eigen/Dense>
#include <Eigen/Geometry>

namespace scenewatch::localization {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

constexpr double kHuber = 1.345;      // 95 % efficiency on Gaussian residuals
constexpr double kInlierSigmas = 3.0;
constexpr double kGateSigmas = 4.0;

double huber_weight(double e) {
  const double a = std::abs(e);
  return a <= kHuber ? 1.0 : kHuber / a;
}

// The same weight for a residual r of variance sigma2, compared in squares: the square root (a
// long-latency instruction in the pass's chain) is taken only beyond Huber's corner, where the
// weight needs sigma itself.
double huber_weight(double r, double sigma2) {
  return r * r <= kHuber * kHuber * sigma2 ? 1.0 : kHuber * std::sqrt(sigma2) / std::abs(r);
}

// The normal equations of a least-squares pass: H = sum w J J^T and b = sum w r J. A pass adds
// one term per pixel. Each row of H is kept as two vectors of four doubles (GCC's vector
// extension), so the AVX2 clone of the pass adds a term in 12 vector multiply-adds where the
// 21 distinct entries of the symmetric H and the 6 of b took 27 scalar ones; rows 4 and 5 keep
// only their right half, all that the upper triangle needs.
struct NormalEquations {
  using D4 = double __attribute__((vector_size(32)));
  D4 h[6][2] = {};
  D4 b[2] = {};
  void add(const double (&J)[6], double r, double w) {
    add_information(J, w);
    const double wr = w * r;
    b[0] += wr * D4{J[0], J[1], J[2], J[3]};
    b[1] += wr * D4{J[4], J[5], 0, 0};
  }
  /// H alone.
  void add_information(const double (&J)[6], double w) {
    const D4 left{J[0], J[1], J[2], J[3]}, right{J[4], J[5], 0, 0};
    for (int i = 0; i < 4; ++i) {
      const double wi = w * J[i];
      h[i][0] += wi * left;
      h[i][1] += wi * right;
    }
    for (int i = 4; i < 6; ++i) h[i][1] += (w * J[i]) * right;
  }
  /// The upper triangle, mirrored.
  Mat6 H() const {
    Mat6 m;
    for (int i = 0; i < 6; ++i)
      for (int j = i; j < 6; ++j) m(i, j) = m(j, i) = h[i][j / 4][j % 4];
    return m;
  }
  Vec6 rhs() const { return Vec6(b[0][0], b[0][1], b[0][2], b[0][3], b[1][0], b[1][1]); }
};

// J = (n, q x n) for a point q and a direction n: the derivative of n . q under a twist.
void point_jacobian(const Eigen::Vector3d& q, const Eigen::Vector3d& n, double (&J)[6]) {
  J[0] = n.x();
  J[1] = n.y();
  J[2] = n.z();
  J[3] = q.y() * n.z() - q.z() * n.y();
  J[4] = q.z() * n.x() - q.x() * n.z();
  J[5] = q.x() * n.y() - q.y() * n.x();
}

// Where a point falls between four pixels, for sampling several images there.
struct Bilinear {
  std::size_t i;  ///< the top-left pixel
  std::size_t width;
  float ax, ay;
  Bilinear(int width_px, float x, float y) : width(static_cast<std::size_t>(width_px)) {
    const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
    ax = x - x0;
    ay = y - y0;
    i = static_cast<std::size_t>(y0) * width + x0;
  }
  /// The three channels of a shade image, each sampled alike.
  RgbdLevel::Shade operator()(const std::vector<RgbdLevel::Shade>& img) const {
    const RgbdLevel::Shade &a = img[i], &b = img[i + 1], &c = img[i + width], &d = img[i + width + 1];
    const auto mix = [&](float RgbdLevel::Shade::*f) {
      return (1 - ay) * ((1 - ax) * a.*f + ax * b.*f) + ay * ((1 - ax) * c.*f + ax * d.*f);
    };
    return {mix(&RgbdLevel::Shade::intensity), mix(&RgbdLevel::Shade::grad_x), mix(&RgbdLevel::Shade::grad_y)};
  }
};

// The magnitudes of a pass's photometric residuals (intensities in [0, 1]), binned finely enough
// that their median is read to 1/4096 of the intensity range, a sixteenth of one grey level of an
// 8-bit image: counting them costs one increment a pixel, where keeping them and selecting the
// median took a push and a partial sort of tens of thousands of values every pass.
class ResidualHistogram {
 public:
  static constexpr int kBins = 4096;
  void add(double abs_r) {
    // 1 and beyond (and a NaN, which no intensity should give) count in the last bin.
    const int b = abs_r < 1.0 ? static_cast<int>(abs_r * kBins) : kBins - 1;
    ++bins_[static_cast<std::size_t>(b)];
    ++count_;
  }
  std::size_t size() const { return count_; }
  /// The value of rank size() / 2, interpolated within its bin.
  double median() const {
    const std::size_t rank = count_ / 2;
    std::size_t below = 0;
    for (int b = 0; b < kBins; ++b) {
      const std::size_t n = bins_[static_cast<std::size_t>(b)];
      if (below + n > rank) return (b + (static_cast<double>(rank - below) + 0.5) / n) / kBins;
      below += n;
    }
    return 1.0;
  }

 private:
  std::vector<std::uint32_t> bins_ = std::vector<std::uint32_t>(kBins, 0);
  std::size_t count_ = 0;
};

struct Pass {
  NormalEquations system;       // geometric and photometric
  NormalEquations information;  // geometric inliers, unweighted by Huber, 1 / sigma^2
  std::size_t valid = 0, correspondences = 0, inliers = 0;
  double inlier_sq = 0.0, depth_sum = 0.0;
  ResidualHistogram photometric_abs;  // |r| of the photometric terms, for their robust spread
};

struct LevelInput {
  const RgbdLevel& ref;
  const RgbdLevel& cur;
  double gate_m;
  double photometric_sigma;
};

// A batch of a pass's pixels, staged. The pass was one long chain of dependent steps per pixel
// (the current depth, the projection, the reference's depth and normal at it, its shade), too long
// for the processor to start the next pixel's loads before this pixel's arithmetic was done, so
// each pixel waited out its own memory latencies in turn. Staged, each step runs over the whole
// batch: the projections first, then every lookup into the reference (whose addresses are all
// known by then, so their loads overlap), then the arithmetic. The same operations in the same
// order as one pixel at a time, so the same sums to the last bit.
struct Staged {
  static constexpr int kSize = 64;
  int n = 0;
  // Projected: the current pixel, its point in the reference's frame and where it falls there.
  std::size_t ic[kSize], ir[kSize];
  int iu[kSize], iv[kSize];  // the nearest reference pixel, ir's column and row
  float zc[kSize], qx[kSize], qy[kSize], qz[kSize], x[kSize], y[kSize];
  // Looked up: the reference's depth and normal at the nearest pixel, its shade there and
  // interpolated, the current intensity.
  float zr[kSize], cur_intensity[kSize];
  Eigen::Vector3f normal[kSize];
  RgbdLevel::Shade nearest[kSize], at[kSize];
};

[[gnu::always_inline]] inline void look_up(Staged& b, const RgbdLevel& ref, const RgbdLevel& cur, bool photometric) {
  for (int k = 0; k < b.n; ++k) {
    b.zr[k] = ref.depth_m[b.ir[k]];
    b.normal[k] = ref.normals[b.ir[k]];
  }
  if (!photometric) return;
  for (int k = 0; k < b.n; ++k) {
    b.nearest[k] = ref.shade[b.ir[k]];
    b.at[k] = Bilinear(ref.width, b.x[k], b.y[k])(ref.shade);
    b.cur_intensity[k] = cur.intensity[b.ic[k]];
  }
}

// The terms of a staged batch, added to the pass's sums in the batch's order.
[[gnu::always_inline]] inline void add_terms(const Staged& b, const LevelInput& in, const SensorModel& sensor,
                                             const AlignmentConfig& config, const PixelRays& ref_rays, bool quality_pass,
                                             Pass& p) {
  const float fx = static_cast<float>(in.ref.intrinsics.fx), fy = static_cast<float>(in.ref.intrinsics.fy);
  const double wphoto = config.photometric_weight;
  const float min_grad = static_cast<float>(config.min_gradient);
  for (int k = 0; k < b.n; ++k) {
    const Eigen::Vector3f q(b.qx[k], b.qy[k], b.qz[k]);
    const Eigen::Vector3d qd = q.cast<double>();
    // Geometric: the reference surface at the nearest pixel, its plane.
    const float zr = b.zr[k];
    if (zr > 0 && std::isfinite(b.normal[k].x())) {
      const Eigen::Vector3f d = q - ref_rays.point(b.iu[k], b.iv[k], zr);
      const float zc = b.zc[k];
      const double sz_c = sensor.sigma_z(zc), sz_r = sensor.sigma_z(zr);
      // Compared in squares, as huber_weight(r, sigma2): no square root on this path.
      const double sigma2 = sz_c * sz_c + sz_r * sz_r;
      const double gate2 = std::max(in.gate_m * in.gate_m, kGateSigmas * kGateSigmas * sigma2);
      if (static_cast<double>(d.squaredNorm()) <= gate2) {
        const Eigen::Vector3d n = b.normal[k].cast<double>();
        const double r = n.dot(d.cast<double>());
        double J[6];
        point_jacobian(qd, n, J);
        const double info = 1.0 / sigma2;
        if (!quality_pass) p.system.add(J, r, info * huber_weight(r, sigma2));
        ++p.correspondences;
        p.depth_sum += zr;
        const double r2 = r * r;
        if (r2 <= kInlierSigmas * kInlierSigmas * sigma2) {
          ++p.inliers;
          p.inlier_sq += r2;
          if (quality_pass) p.information.add_information(J, info);
        }
      }
    }
    // Photometric: the reference intensity where the point projects, where it has texture.
    if (wphoto <= 0) continue;
    const RgbdLevel::Shade& nearest = b.nearest[k];
    if (std::abs(nearest.grad_x) < min_grad && std::abs(nearest.grad_y) < min_grad) continue;
    const RgbdLevel::Shade& at = b.at[k];
    const double r = at.intensity - b.cur_intensity[k];
    const double bgx = at.grad_x, bgy = at.grad_y;
    const double iz = 1.0 / qd.z();
    // Gradient through the projection: a = dpi/dq^T grad.
    const Eigen::Vector3d a(bgx * fx * iz, bgy * fy * iz, -(bgx * fx * qd.x() + bgy * fy * qd.y()) * iz * iz);
    double J[6];
    point_jacobian(qd, a, J);
    const double s = in.photometric_sigma;
    p.system.add(J, r, wphoto * huber_weight(r / s) / (s * s));
    p.photometric_abs.add(std::abs(r));
  }
}

// One pass over the current level's pixels at the pose T_rc: every `stride`-th pixel of a row,
// the first one shifted by the row's number (so the rows' samples interleave), in staged batches.
// Compiled twice, for AVX2 + FMA and for the x86-64 baseline; the loader picks the clone the CPU
// supports (GCC function multi-versioning), so the binary stays portable. The clones round
// differently (FMA fuses a multiply and an add), by far less than the sensor's noise. The quality
// pass at the final pose (`quality_pass`) sums the geometric inliers' information, for the
// covariance, instead of the normal equations, which no step follows.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
__attribute__((target_clones("avx2,fma", "default")))
#endif
Pass linearise(const LevelInput& in, const Pose& T_rc, const SensorModel& sensor, const AlignmentConfig& config,
               bool quality_pass = false, int stride = 1) {
  Pass p;
  const RgbdLevel& ref = in.ref;
  const RgbdLevel& cur = in.cur;
  const Eigen::Matrix3f R = T_rc.linear().cast<float>();
  const Eigen::Vector3f t = T_rc.translation().cast<float>();
  const float fx = static_cast<float>(ref.intrinsics.fx), fy = static_cast<float>(ref.intrinsics.fy);
  const float cx = static_cast<float>(ref.intrinsics.cx), cy = static_cast<float>(ref.intrinsics.cy);
  const double wphoto = config.photometric_weight;
  const PixelRays cur_rays(cur), ref_rays(ref);
  Staged b;
  int v = 0, u = 0;
  while (v < cur.height) {
    // Stage the next batch of pixels that project into the reference image.
    b.n = 0;
    while (v < cur.height && b.n < Staged::kSize) {
      for (; u < cur.width && b.n < Staged::kSize; u += stride) {
        const std::size_t ic = static_cast<std::size_t>(v) * cur.width + u;
        const float zc = cur.depth_m[ic];
        if (zc <= 0) continue;
        ++p.valid;
        const Eigen::Vector3f q = R * cur_rays.point(u, v, zc) + t;
        if (q.z() <= 0) continue;
        const float x = fx * q.x() / q.z() + cx, y = fy * q.y() / q.z() + cy;
        if (!(x >= 0 && y >= 0 && x < ref.width - 1 && y < ref.height - 1)) continue;
        const int iu = static_cast<int>(x + 0.5f), iv = static_cast<int>(y + 0.5f);
        const int k = b.n++;
        b.ic[k] = ic;
        b.ir[k] = static_cast<std::size_t>(iv) * ref.width + iu;
        b.iu[k] = iu;
        b.iv[k] = iv;
        b.zc[k] = zc;
        b.qx[k] = q.x();
        b.qy[k] = q.y();
        b.qz[k] = q.z();
        b.x[k] = x;
        b.y[k] = y;
      }
      if (u >= cur.width) {
        ++v;
        u = v % stride;
      }
    }
    look_up(b, ref, cur, wphoto > 0);
    add_terms(b, in, sensor, config, ref_rays, quality_pass, p);
  }
  return p;
}

double robust_spread(const ResidualHistogram& abs_residuals, double fallback) {
  if (abs_residuals.size() < 100) return fallback;
  // 1.4826 x MAD; at least one grey level of an 8-bit image.
  return std::max(1.4826 * abs_residuals.median(), 1.0 / 255.0);
}

}  // namespace

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Mat6 twist_adjoint(const Pose& T) {
  Mat6 A = Mat6::Zero();
  const Eigen::Matrix3d R = T.linear();
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>() = skew(T.translation()) * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

Pose twist_exp(const Vec6& xi) {
  const Eigen::Vector3d v = xi.head<3>(), w = xi.tail<3>();
  const double theta = w.norm();
  Pose T = Pose::Identity();
  if (theta < 1e-12) {
    T.translation() = v;
    return T;
  }
  const Eigen::Vector3d axis = w / theta;
  T.linear() = Eigen::AngleAxisd(theta, axis).toRotationMatrix();
  const Eigen::Matrix3d K = skew(axis);
  const Eigen::Matrix3d V = Eigen::Matrix3d::Identity() + (1 - std::cos(theta)) / theta * K +
                            (theta - std::sin(theta)) / theta * K * K;
  T.translation() = V * v;
  return T;
}

Status validate(const AlignmentConfig& c) {
  if (c.iterations.empty() || c.iterations.size() > 6)
    return invalid_argument("localization.iterations: one to six levels, got " + std::to_string(c.iterations.size()));
  for (int it : c.iterations)
    if (it < 0 || it > 100) return invalid_argument("localization.iterations: each in [0, 100], got " + std::to_string(it));
  if (!(c.max_correspondence_m > 0 && c.max_correspondence_m <= 1.0))
    return invalid_argument("localization.max_correspondence_m: must be in (0, 1] m");
  if (!(c.photometric_weight >= 0 && c.photometric_weight <= 100))
    return invalid_argument("localization.photometric_weight: must be in [0, 100]");
  if (!(c.min_gradient >= 0 && c.min_gradient < 1)) return invalid_argument("localization.min_gradient: must be in [0, 1)");
  if (c.strides.size() > 6)
    return invalid_argument("localization.strides: at most six levels, got " + std::to_string(c.strides.size()));
  for (int s : c.strides)
    if (s < 1 || s > 4)
      return invalid_argument("localization.strides: each 1 to 4 (every pixel to every fourth), got " + std::to_string(s));
  if (!(c.converged_m > 0) || !(c.converged_deg > 0))
    return invalid_argument("localization.converged_m / converged_deg: must be > 0");
  return {};
}

Alignment align(const RgbdPyramid& reference, const RgbdPyramid& current, const Pose& prior, const SensorModel& sensor,
                const AlignmentConfig& config) {
  Alignment out;
  out.T_reference_current = prior;
  const int levels = static_cast<int>(std::min({reference.levels.size(), current.levels.size(), config.iterations.size()}));
  if (levels == 0) return out;
  Pose T = prior;
  const double converged_rad = config.converged_deg * M_PI / 180.0;
  for (int l = levels - 1; l >= 0; --l) {
    LevelInput in{reference.levels[l], current.levels[l], config.max_correspondence_m * std::pow(0.5, levels - 1 - l), 0.1};
    const int iterations = config.iterations[config.iterations.size() - 1 - l];
    AlignmentConfig level_config = config;
    if (l == 0 && !config.photometric_on_finest_level) level_config.photometric_weight = 0;
    const int stride = config.stride_at(l);
    for (int it = 0; it < iterations; ++it) {
      Pass pass = linearise(in, T, sensor, level_config, false, stride);
      ++out.iterations;
      in.photometric_sigma = robust_spread(pass.photometric_abs, in.photometric_sigma);
      if (pass.correspondences < 60) break;
      const Vec6 delta = pass.system.H().ldlt().solve(-pass.system.rhs());
      if (!delta.allFinite()) break;
      T = twist_exp(delta) * T;
      if (delta.head<3>().norm() < config.converged_m && delta.tail<3>().norm() < converged_rad) break;
    }
  }
  // Quality at the final pose, on the finest level.
  LevelInput fine{reference.levels[0], current.levels[0], config.max_correspondence_m * std::pow(0.5, levels - 1), 0.1};
  AlignmentConfig geometric = config;
  geometric.photometric_weight = 0;
  const Pass last = linearise(fine, T, sensor, geometric, true);
  out.T_reference_current = T;
  out.valid_pixels = last.valid;
  out.inliers = last.inliers;
  out.inlier_fraction = last.valid ? static_cast<double>(last.inliers) / last.valid : 0.0;
  out.residual_m = last.inliers ? std::sqrt(last.inlier_sq / last.inliers) : 0.0;
  if (last.inliers >= 6) {
    const Mat6 info = last.information.H();
    // Information per motion, rotation scaled by the mean depth so both are metres.
    const double depth = last.correspondences ? last.depth_sum / last.correspondences : 1.0;
    out.mean_depth_m = depth;
    Mat6 S = Mat6::Identity();
    S.bottomRightCorner<3, 3>() *= 1.0 / depth;
    const Mat6 normalised = S * info * S / static_cast<double>(last.inliers);
    Eigen::SelfAdjointEigenSolver<Mat6> eig(normalised);
    out.conditioning = eig.eigenvalues()(0) / std::max(eig.eigenvalues()(5), 1e-30);
    Eigen::FullPivLU<Mat6> lu(info);
    if (lu.isInvertible()) out.covariance = lu.inverse();
  }
  return out;
}

}  // namespace scenewatch::localization
