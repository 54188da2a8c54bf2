// The colour-to-depth registration measured from the frames themselves (issue 28's sensor model):
// recovered exactly on rendered scenes, and on real recordings what their sensors are known for.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scenewatch/core/colour_registration.h"
#include "scenewatch/io/sequence.h"
#include "test_data.h"

namespace scenewatch {
namespace {

/// Boxes at different depths before a wall, each face its own colour with some texture; the
/// colour camera sees pixel (u, v) of depth at (cx + s (u - cx) + dx, cy + s (v - cy) + dy), and
/// the cloud carries the colour camera's image on the depth grid, unregistered, as a raw Kinect
/// recording does.
Cloud rendered_scene(const ColourRegistration& truth, const Intrinsics& K) {
  struct Box {
    int u0, v0, u1, v1;
    float z;
    std::uint8_t r, g, b;
  };
  const std::vector<Box> boxes = {{80, 60, 230, 200, 1.2f, 200, 40, 40},   {300, 90, 420, 300, 1.6f, 40, 180, 60},
                                  {460, 200, 600, 420, 0.9f, 50, 70, 210}, {150, 280, 270, 450, 2.1f, 220, 200, 50},
                                  {330, 340, 440, 460, 1.4f, 150, 60, 170}};
  const int w = K.width, h = K.height;
  auto box_at = [&](double u, double v) -> const Box* {
    const Box* nearest = nullptr;
    for (const Box& b : boxes)
      if (u >= b.u0 && u < b.u1 && v >= b.v0 && v < b.v1 && (nearest == nullptr || b.z < nearest->z)) nearest = &b;
    return nearest;
  };
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> texture(-12, 12);
  Cloud cloud(w, h);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      PointT& p = cloud.points[static_cast<std::size_t>(v) * w + u];
      const Box* b = box_at(u, v);
      const float z = b != nullptr ? b->z : 3.0f;
      p.x = static_cast<float>((u - K.cx) * z / K.fx);
      p.y = static_cast<float>((v - K.cy) * z / K.fy);
      p.z = z;
      // The colour image's pixel (u, v) shows the depth pixel that maps onto it.
      const double du = K.cx + (u - truth.shift_x_px - K.cx) / truth.scale;
      const double dv = K.cy + (v - truth.shift_y_px - K.cy) / truth.scale;
      const Box* seen = box_at(du, dv);
      const int t = texture(rng);
      auto c = [&](int base) { return static_cast<std::uint8_t>(std::clamp(base + t, 0, 255)); };
      p.r = c(seen != nullptr ? seen->r : 120);
      p.g = c(seen != nullptr ? seen->g : 120);
      p.b = c(seen != nullptr ? seen->b : 110);
    }
  }
  return cloud;
}

Intrinsics vga() {
  Intrinsics K;
  K.fx = K.fy = 585;
  K.cx = 319.5;
  K.cy = 239.5;
  K.width = 640;
  K.height = 480;
  return K;
}

TEST(ColourRegistration, RecoversAKnownMisregistration) {
  const Intrinsics K = vga();
  for (const ColourRegistration truth : {ColourRegistration{0.9, -6, 2}, ColourRegistration{1.08, 4.5, -3}}) {
    const Cloud cloud = rendered_scene(truth, K);
    const auto fit = fit_colour_registration(cloud, K, SensorModel{});
    ASSERT_TRUE(fit.has_value());
    EXPECT_NEAR(fit->registration.scale, truth.scale, 0.0025) << truth.scale;
    EXPECT_NEAR(fit->registration.shift_x_px, truth.shift_x_px, 0.5) << truth.scale;
    EXPECT_NEAR(fit->registration.shift_y_px, truth.shift_y_px, 0.5) << truth.scale;
    EXPECT_GT(fit->score, 1.5 * fit->identity_score);
    // Applied, the colour of a box's inside is the box's, where before it was its neighbour's.
    const CloudPtr registered = apply_colour_registration(cloud, K, fit->registration);
    const auto again = fit_colour_registration(*registered, K, SensorModel{});
    ASSERT_TRUE(again.has_value());
    EXPECT_LT(again->registration.max_displacement_px(K.width, K.height, K.cx, K.cy), 1.0);
  }
}

TEST(ColourRegistration, ARegisteredSensorIsLeftAlone) {
  const Intrinsics K = vga();
  const auto fit = fit_colour_registration(rendered_scene(ColourRegistration{}, K), K, SensorModel{});
  ASSERT_TRUE(fit.has_value());
  EXPECT_LT(fit->registration.max_displacement_px(K.width, K.height, K.cx, K.cy), 1.0);
}

TEST(ColourRegistration, NothingToFitWithoutContours) {
  const Intrinsics K = vga();
  Cloud wall(K.width, K.height);
  for (std::size_t i = 0; i < wall.size(); ++i) {
    const int u = static_cast<int>(i % K.width), v = static_cast<int>(i / K.width);
    wall.points[i].z = 2.0f;
    wall.points[i].x = static_cast<float>((u - K.cx) * 2.0 / K.fx);
    wall.points[i].y = static_cast<float>((v - K.cy) * 2.0 / K.fy);
    wall.points[i].r = wall.points[i].g = wall.points[i].b = static_cast<std::uint8_t>(u % 256);
  }
  EXPECT_FALSE(fit_colour_registration(wall, K, SensorModel{}).has_value());
  Cloud unorganized = wall;
  unorganized.width = static_cast<std::uint32_t>(wall.size());
  unorganized.height = 1;
  EXPECT_FALSE(fit_colour_registration(unorganized, K, SensorModel{}).has_value());
}

/// The registration a recording's camera settles on (its first frame with contours).
ColourRegistration estimated(const std::filesystem::path& dir) {
  auto seq = io::open_sequence(dir);
  EXPECT_TRUE(seq.ok()) << seq.error().message;
  if (!seq.ok()) return {};
  ColourRegistrationEstimate estimate;
  for (std::size_t i = 0; i < seq->frames.size() && !estimate.settled(); ++i) {
    auto frame = io::load_sequence_frame(*seq, i);
    EXPECT_TRUE(frame.ok()) << frame.error().message;
    if (frame.ok()) estimate.update(*frame->cloud, *frame->intrinsics, SensorModel{});
  }
  EXPECT_TRUE(estimate.current().has_value()) << dir << ": no frame had contours to fit";
  return estimate.current().value_or(ColourRegistration{});
}

TEST(ColourRegistration, SevenScenesColourIsAWiderCameraAside) {
  SCENEWATCH_REQUIRE_DATA("redkitchen_long/frame-000000.color.jpg");
  // 7-Scenes gives the depth camera's focal length, 585 px; its colour camera is a Kinect v1's,
  // about 525 px (525 / 585 = 0.897), a baseline aside. Measured: see below.
  for (const char* dir : {"redkitchen_long", "redkitchen"}) {
    const ColourRegistration r = estimated(test::data_dir() / dir);
    EXPECT_NEAR(r.scale, 0.905, 0.01) << dir;
    EXPECT_NEAR(r.shift_x_px, -5, 2) << dir;
    EXPECT_NEAR(r.shift_y_px, 0, 2) << dir;
  }
}

TEST(ColourRegistration, EveryFrameOfARecordingMeasuresTheSame) {
  SCENEWATCH_REQUIRE_DATA("redkitchen/frame-000150.color.png");
  // A camera keeps its first fit, so each fit must hold: the first eight frames of redkitchen
  // measured 0.9025-0.905 and (-7 to -6, -1 to -0.5) px. Before the three best coarse peaks were
  // each refined, frame 6 fell on a lesser peak (0.8425, (0, 8) px).
  auto seq = io::open_sequence(test::data_dir() / "redkitchen");
  ASSERT_TRUE(seq.ok()) << seq.error().message;
  for (std::size_t i = 0; i < 8; ++i) {
    auto frame = io::load_sequence_frame(*seq, i);
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    const auto fit = fit_colour_registration(*frame->cloud, *frame->intrinsics, SensorModel{});
    ASSERT_TRUE(fit.has_value()) << i;
    EXPECT_NEAR(fit->registration.scale, 0.9035, 0.0026) << i;
    EXPECT_NEAR(fit->registration.shift_x_px, -6.5, 1.0) << i;
    EXPECT_NEAR(fit->registration.shift_y_px, -0.75, 0.75) << i;
    EXPECT_GT(fit->score, 1.8 * fit->identity_score) << i;
  }
}

TEST(ColourRegistration, RegisteredRecordingsStayWithinAPixelOrTwo) {
  SCENEWATCH_REQUIRE_DATA("hrt1/pick_toy_1/frame-000000.color.jpg");
  // hrt1's colour and depth come registered by the driver, to within a few pixels: each of the
  // first eight frames of pick_toy_1 measured 0.99-0.995 and shifts of 0.5-1.5 px; the first
  // frames, which the cameras keep, move a corner pixel by 4.8 px (pick_toy_1) and 3.7 px.
  for (const char* dir : {"hrt1/pick_toy_1", "hrt1/pick_toy_2"}) {
    const ColourRegistration r = estimated(test::data_dir() / dir);
    EXPECT_NEAR(r.scale, 0.9925, 0.005) << dir;
    EXPECT_LT(r.max_displacement_px(640, 480, 319.5, 239.5), 5.0) << dir;
  }
}

}  // namespace
}  // namespace scenewatch
