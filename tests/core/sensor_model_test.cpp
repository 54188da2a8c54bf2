// The sensor model every piece of change evidence is measured against (issue 28): its noise
// figures against their sources, its profiles, and which pixels of a depth image it trusts.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "scenewatch/core/depth_validity.h"
#include "scenewatch/core/sensor_model.h"

namespace scenewatch {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(SensorModel, StructuredLightIsNguyensKinectModel) {
  const SensorModel s;
  // Nguyen, Izadi & Lovell 2012, eq. (2), head-on: 0.0012 + 0.0019 (z - 0.4)^2.
  for (double z : {0.5, 1.0, 2.0, 3.0, 4.0}) EXPECT_NEAR(s.sigma_z(z), 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4), 1e-12) << z;
  // Khoshelham & Elberink 2012 put it at about 1.4 mm z^2 and 4 cm at 5 m: within 20 % over 1.5-4 m.
  for (double z : {1.5, 2.0, 3.0, 4.0}) EXPECT_NEAR(s.sigma_z(z) / (0.0014 * z * z), 1.0, 0.2) << z;
  // The angle term: nothing head-on, more at grazing incidence, finite at 90 degrees.
  EXPECT_DOUBLE_EQ(s.sigma_z(2.0, 0.0), s.sigma_z(2.0));
  EXPECT_GT(s.sigma_z(2.0, 80 * kPi / 180), 1.5 * s.sigma_z(2.0));
  EXPECT_TRUE(std::isfinite(s.sigma_z(2.0, kPi / 2)));
  EXPECT_DOUBLE_EQ(s.lateral_sigma_px(0.0), 0.8);
  EXPECT_GT(s.lateral_sigma_px(80 * kPi / 180), 0.8);
  // At 3 sigma the band around edges is 3 px (0.8 x 3 rounded up).
  EXPECT_EQ(s.edge_band_px(3.0), 3);
}

TEST(SensorModel, PoseUncertaintyGrowsWithRange) {
  SensorModel s;
  EXPECT_EQ(s.pose_sigma_at(2.0), 0.0);  // default: only what each frame shows (change::pose_agreement)
  s.pose_sigma_m = 0.01;
  s.pose_sigma_deg = 0.5;
  EXPECT_NEAR(s.pose_sigma_at(0.0), 0.01, 1e-12);
  EXPECT_NEAR(s.pose_sigma_at(2.0), std::hypot(0.01, 2.0 * 0.5 * kPi / 180), 1e-12);
  EXPECT_NEAR(s.pose_sigma_px(2.0, 525), 525 * s.pose_sigma_at(2.0) / 2.0, 1e-9);
}

TEST(SensorModel, ProfilesAndValidation) {
  for (const char* name : {"structured_light", "active_stereo", "time_of_flight", "explicit"}) {
    auto p = sensor_profile(name);
    ASSERT_TRUE(p.ok()) << name;
    EXPECT_EQ(p->profile, name);
    EXPECT_TRUE(validate(*p).ok()) << name;
  }
  // The RealSense D435's 4.7 mm z^2 against Kinect's smaller figure at 2 m; ToF flatter with range.
  EXPECT_NEAR(sensor_profile("active_stereo")->sigma_z(2.0), 0.0047 * 4, 1e-12);
  EXPECT_LT(sensor_profile("time_of_flight")->sigma_z(3.0), SensorModel{}.sigma_z(3.0));
  auto unknown = sensor_profile("kinect9");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().message.find("structured_light"), std::string::npos) << unknown.error().message;
  SensorModel bad;
  bad.pose_sigma_deg = -1;
  auto st = validate(bad);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("sensor.pose_sigma_deg"), std::string::npos) << st.error().message;
  bad = SensorModel{};
  bad.min_range_m = 5;
  EXPECT_FALSE(validate(bad).ok());
}

// A 40 x 30 image: a wall at 2 m with a box at 1 m in its middle (columns 15-24), and a hole.
std::vector<float> wall_with_box_and_hole(int w, int h) {
  std::vector<float> z(static_cast<std::size_t>(w) * h, 2.0f);
  for (int v = 0; v < h; ++v)
    for (int u = 15; u < 25; ++u) z[static_cast<std::size_t>(v) * w + u] = 1.0f;
  z[static_cast<std::size_t>(5) * w + 5] = std::numeric_limits<float>::quiet_NaN();
  return z;
}

TEST(DepthValidity, BorderEdgesAndHolesAsTheModelSays) {
  const int w = 40, h = 30;
  SensorModel s;
  s.border_px = 2;
  const DepthValidity d = depth_validity(wall_with_box_and_hole(w, h), w, h, 525.0, s, 3.0);
  ASSERT_EQ(d.bits.size(), static_cast<std::size_t>(w * h));
  EXPECT_EQ(d.valid, static_cast<std::size_t>(w * h - 1));
  // The border.
  EXPECT_FALSE(d.has(1, 15));
  EXPECT_FALSE(d.has(38, 15));
  EXPECT_TRUE(d.has(1, 15, DepthValidity::kInRange));
  // The depth edge at columns 14|15 and 24|25: a 3 px band on both sides (marked pixels 14 and 15,
  // then 3 more each way: 11 to 18), the wall between untouched.
  EXPECT_TRUE(d.has(10, 15));
  for (int u = 11; u <= 18; ++u) EXPECT_FALSE(d.has(u, 15)) << u;
  EXPECT_TRUE(d.has(19, 15) || d.has(20, 15));
  EXPECT_TRUE(d.has(12, 15, DepthValidity::kInRange | DepthValidity::kInterior | DepthValidity::kOffHole));
  // The hole and its band.
  EXPECT_FALSE(d.has(5, 5, DepthValidity::kInRange));
  EXPECT_FALSE(d.has(8, 8));
  EXPECT_TRUE(d.has(9, 9));
  // A slanted surface is no edge: depth rising 1 cm per pixel at 2 m (about 70 degrees at f 525).
  std::vector<float> slope(static_cast<std::size_t>(w) * h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) slope[static_cast<std::size_t>(v) * w + u] = 2.0f + 0.01f * u;
  const DepthValidity ds = depth_validity(slope, w, h, 525.0, s, 3.0);
  EXPECT_EQ(ds.trusted, static_cast<std::size_t>((w - 4) * (h - 4)));
}

TEST(DepthValidity, OutOfRangeIsNoMeasurement) {
  const int w = 10, h = 10;
  SensorModel s;
  s.border_px = 0;
  std::vector<float> z(100, 5.0f);  // beyond the structured-light range (4.5 m)
  z[55] = 1.0f;
  const DepthValidity d = depth_validity(z, w, h, 525.0, s, 3.0);
  EXPECT_EQ(d.valid, 1u);
  EXPECT_TRUE(d.has(5, 5, DepthValidity::kInRange));
  EXPECT_FALSE(d.has(0, 0, DepthValidity::kInRange));
}

}  // namespace
}  // namespace scenewatch
