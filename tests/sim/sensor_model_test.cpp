// The sensor model against its own parameters: noise level, quantization, holes, reproducibility.
#include <gtest/gtest.h>

#include <cmath>

#include "scenewatch/sim/sensor_model.h"

namespace scenewatch::sim {
namespace {

IdealView flat_view(int w, int h, float z, float cos_inc = 1.0f) {
  IdealView v;
  v.width = w;
  v.height = h;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  v.depth_m.assign(n, z);
  v.opaque_depth_m.assign(n, z);
  v.cos_incidence.assign(n, cos_inc);
  v.opaque_cos_incidence.assign(n, cos_inc);
  v.transparent.assign(n, 0);
  v.rgb.assign(3 * n, 100.0f);
  v.labels.assign(n, 10);
  return v;
}

TEST(SensorModel, DepthNoiseMatchesSigmaAndQuantization) {
  SensorConfig c;
  c.disparity_step_px = 0.0;  // noise alone first
  const SensorModel sensor(c, 1);
  for (double z : {0.8, 1.5, 3.0}) {
    const IdealView v = flat_view(200, 200, static_cast<float>(z));
    ColorImage color;
    DepthImage depth;
    sensor.apply(v, 525.0, 0, &color, &depth);
    double sum = 0, sum2 = 0;
    for (auto mm : depth.depth_mm) {
      ASSERT_GT(mm, 0);
      const double e = mm / 1000.0 - z;
      sum += e;
      sum2 += e * e;
    }
    const double n = static_cast<double>(depth.depth_mm.size());
    const double sigma = std::sqrt(sum2 / n - (sum / n) * (sum / n));
    const double expected = std::sqrt(std::pow(sensor.depth_sigma_m(z), 2) + 1e-6 / 12.0);  // + mm rounding
    EXPECT_NEAR(sigma, expected, 0.05 * expected) << "z = " << z;
    EXPECT_NEAR(sum / n, 0.0, 0.1 * expected);
  }
  // Kinect-like sigma grows with z^2.
  EXPECT_GT(sensor.depth_sigma_m(3.0), 5 * sensor.depth_sigma_m(0.8));

  // Disparity quantization: without noise, depths snap to the disparity steps.
  SensorConfig q;
  q.noise = true;
  q.depth_sigma_base_m = 0;
  q.depth_sigma_quad = 0;
  q.color_sigma = 0;
  const SensorModel quant(q, 1);
  const IdealView v = flat_view(4, 4, 2.0f);
  ColorImage color;
  DepthImage depth;
  quant.apply(v, 525.0, 0, &color, &depth);
  const double fb = 525.0 * q.baseline_m;
  const double step = quant.quantization_step_m(2.0, 525.0);
  EXPECT_NEAR(step, 4.0 * 0.125 / fb, 1e-12);
  const double expected_z = fb / (std::round(fb / 2.0 / 0.125) * 0.125);
  EXPECT_EQ(depth.depth_mm[0], static_cast<std::uint16_t>(std::lround(expected_z * 1000)));
}

TEST(SensorModel, HolesAtGrazingAnglesOnGlassAndOutOfRange) {
  const SensorModel sensor(SensorConfig{}, 5);
  ColorImage color;
  DepthImage depth;
  // 87 degrees: beyond grazing_end_deg, always a hole.
  sensor.apply(flat_view(50, 50, 1.0f, static_cast<float>(std::cos(87 * M_PI / 180))), 525, 0, &color, &depth);
  for (auto mm : depth.depth_mm) EXPECT_EQ(mm, 0);
  // 78 degrees: half-way into the band, about half the pixels are holes.
  sensor.apply(flat_view(100, 100, 1.0f, static_cast<float>(std::cos(78 * M_PI / 180))), 525, 0, &color, &depth);
  int holes = 0;
  for (auto mm : depth.depth_mm) holes += mm == 0;
  EXPECT_NEAR(holes / 10000.0, 0.5, 0.05);
  // Out of range.
  sensor.apply(flat_view(10, 10, 0.3f), 525, 0, &color, &depth);
  for (auto mm : depth.depth_mm) EXPECT_EQ(mm, 0);
  sensor.apply(flat_view(10, 10, 6.0f), 525, 0, &color, &depth);
  for (auto mm : depth.depth_mm) EXPECT_EQ(mm, 0);
  // Glass: a hole by default, the depth behind it when asked.
  IdealView glass = flat_view(10, 10, 1.0f);
  glass.transparent.assign(100, 1);
  glass.opaque_depth_m.assign(100, 2.0f);
  sensor.apply(glass, 525, 0, &color, &depth);
  for (auto mm : depth.depth_mm) EXPECT_EQ(mm, 0);
  SensorConfig behind;
  behind.transparent_depth = TransparentDepth::kBehind;
  SensorModel(behind, 5).apply(glass, 525, 0, &color, &depth);
  for (auto mm : depth.depth_mm) EXPECT_NEAR(mm, 2000, 40);
}

TEST(SensorModel, SameSeedSameBytesOtherSeedOtherBytes) {
  const IdealView v = flat_view(64, 48, 1.2f);
  ColorImage c1, c2, c3;
  DepthImage d1, d2, d3;
  SensorModel(SensorConfig{}, 9).apply(v, 525, 3, &c1, &d1);
  SensorModel(SensorConfig{}, 9).apply(v, 525, 3, &c2, &d2);
  SensorModel(SensorConfig{}, 10).apply(v, 525, 3, &c3, &d3);
  EXPECT_EQ(c1.rgb, c2.rgb);
  EXPECT_EQ(d1.depth_mm, d2.depth_mm);
  EXPECT_NE(c1.rgb, c3.rgb);
  EXPECT_NE(d1.depth_mm, d3.depth_mm);
  // Another frame of the same run draws other noise.
  SensorModel(SensorConfig{}, 9).apply(v, 525, 4, &c3, &d3);
  EXPECT_NE(d1.depth_mm, d3.depth_mm);
}

TEST(SensorModel, PoseNoiseIsReproducibleAndOfTheRightSize) {
  SensorConfig c;
  c.pose_sigma_m = 0.01;
  c.pose_sigma_deg = 1.0;
  const SensorModel sensor(c, 2);
  const Pose T = Pose::Identity();
  double sum2 = 0;
  for (int f = 0; f < 2000; ++f) {
    const Pose a = sensor.reported_pose(T, static_cast<std::uint64_t>(f));
    const Pose b = sensor.reported_pose(T, static_cast<std::uint64_t>(f));
    ASSERT_TRUE(a.isApprox(b));
    sum2 += a.translation().squaredNorm();
  }
  EXPECT_NEAR(std::sqrt(sum2 / 2000 / 3), 0.01, 0.001);
  EXPECT_TRUE(SensorModel(SensorConfig{}, 2).reported_pose(T, 0).isApprox(T));
}

}  // namespace
}  // namespace scenewatch::sim
