// The refinement alone, against exact answers: a noisy half cylinder of known axis and radius,
// started from a wrong guess, as the camera sees a can (one side only).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "scenewatch/ontology/cylinder_refinement.h"

namespace scenewatch::ontology {
namespace {

struct HalfCylinder {
  std::vector<Eigen::Vector3d> points, normals;
};

// Points on the arc [-90, 90] degrees about a tilted axis, with Gaussian radial noise.
HalfCylinder half_cylinder(const Eigen::Vector3d& center, const Eigen::Vector3d& axis, double radius, double height,
                           double noise_m, double arc_deg = 180.0) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-arc_deg / 2 * M_PI / 180, arc_deg / 2 * M_PI / 180), along(-height / 2, height / 2);
  std::normal_distribution<double> noise(0.0, noise_m);
  const Eigen::Vector3d a = axis.normalized();
  const Eigen::Vector3d u = a.cross(Eigen::Vector3d::UnitX()).normalized(), v = a.cross(u);
  HalfCylinder out;
  for (int i = 0; i < 3000; ++i) {
    const double t = angle(rng);
    const Eigen::Vector3d radial = std::cos(t) * u + std::sin(t) * v;
    out.points.push_back(center + along(rng) * a + (radius + noise(rng)) * radial);
    out.normals.push_back(radial);
  }
  return out;
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * 180.0 / M_PI;
}

TEST(CylinderRefinementTest, RecoversAxisAndRadiusOfAHalfCylinderFromAWrongGuess) {
  const Eigen::Vector3d center(0.1, -0.05, 1.0), axis = Eigen::Vector3d(0.1, 1.0, 0.2).normalized();
  const HalfCylinder view = half_cylinder(center, axis, 0.033, 0.10, 0.001);
  // 5 mm too wide, 6 degrees off, 4 mm beside the true axis.
  const Eigen::Vector3d wrong_axis = (axis + Eigen::Vector3d(0.1, 0.0, 0.0)).normalized();
  const CylinderGuess guess{center + Eigen::Vector3d(0.004, 0, 0), wrong_axis, 0.038};
  FitConfig config;
  config.refine_band_m = 0.012;
  const auto fit = refine_cylinder(view.points, view.normals, guess, false, config);
  ASSERT_TRUE(fit.has_value());
  std::printf("half cylinder: radius %.2f mm (true 33.00), axis error %.2f deg, rms %.2f mm, coverage %.0f deg\n",
              fit->radius_m * 1000, angle_deg(fit->axis, axis), fit->rms_m * 1000, fit->coverage_deg);
  EXPECT_NEAR(fit->radius_m, 0.033, 0.0005);
  EXPECT_LT(angle_deg(fit->axis, axis), 0.5);
  EXPECT_NEAR(fit->rms_m, 0.001, 0.0002);
  EXPECT_NEAR(fit->height_m, 0.10, 0.005);
  EXPECT_NEAR(fit->coverage_deg, 180.0, 5.0);
  EXPECT_LT((fit->center - center).norm(), 0.002);
  EXPECT_FALSE(fit->axis_fixed);
}

TEST(CylinderRefinementTest, FixedAxisKeepsTheAxisAndFitsTheCircle) {
  const Eigen::Vector3d center(0, 0, 0.8), up = Eigen::Vector3d::UnitZ();
  const HalfCylinder view = half_cylinder(center, up, 0.042, 0.033, 0.0015, 120.0);
  const CylinderGuess guess{center + Eigen::Vector3d(-0.003, 0.002, 0), up, 0.035};
  const auto fit = refine_cylinder(view.points, view.normals, guess, true, FitConfig{});
  ASSERT_TRUE(fit.has_value());
  EXPECT_TRUE(fit->axis_fixed);
  EXPECT_DOUBLE_EQ(fit->axis.dot(up), 1.0);
  EXPECT_NEAR(fit->radius_m, 0.042, 0.001);
  EXPECT_NEAR(fit->coverage_deg, 120.0, 5.0);
}

TEST(CylinderRefinementTest, UprightGuessFromACircleFitIsNearTheTruth) {
  const Eigen::Vector3d center(0.2, 0.1, 0.7), up = Eigen::Vector3d::UnitZ();
  const HalfCylinder view = half_cylinder(center, up, 0.05, 0.14, 0.001);
  const auto guess = upright_guess(view.points, view.normals, up, FitConfig{});
  ASSERT_TRUE(guess.has_value());
  EXPECT_NEAR(guess->radius_m, 0.05, 0.003);
  EXPECT_LT(((guess->point - center) - (guess->point - center).dot(up) * up).norm(), 0.003);
}

TEST(CylinderRefinementTest, TooFewPointsNearTheGuessGiveNothing) {
  const HalfCylinder view = half_cylinder(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.03, 0.1, 0.001);
  // A guess 5 cm too wide: no point lies in its 1 cm band.
  const CylinderGuess guess{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.08};
  EXPECT_FALSE(refine_cylinder(view.points, view.normals, guess, false, FitConfig{}).has_value());
  EXPECT_FALSE(refine_cylinder(view.points, view.normals, CylinderGuess{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), -1.0},
                               false, FitConfig{}).has_value());
}

TEST(CylinderRefinementTest, CoverageOfKnownArcs) {
  std::vector<Eigen::Vector3d> quarter, full;
  for (int d = 0; d <= 90; ++d) quarter.emplace_back(std::cos(d * M_PI / 180), std::sin(d * M_PI / 180), 0);
  for (int d = 0; d < 360; d += 10) full.emplace_back(std::cos(d * M_PI / 180), std::sin(d * M_PI / 180), 0);
  EXPECT_NEAR(angular_coverage_deg(quarter, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()), 90.0, 1e-6);
  EXPECT_NEAR(angular_coverage_deg(full, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()), 350.0, 1e-6);
}

}  // namespace
}  // namespace scenewatch::ontology
