// Simulated Kinect views (noise, disparity quantization) of cylinders of exactly known size at
// about 1 m: the points of the object come from the simulator's labels (no segmentation), in the
// world frame where the true axis is z.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "scenewatch/io/rgbd.h"
#include "scenewatch/ontology/fit.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::ontology {
namespace {

struct Truth {
  int phase, frame;
  std::uint16_t object_id;  // its pixels are labelled 10 id .. 10 id + 9
  double radius_m;  // sample_clouds/scenarios/cup_added.yaml
};

struct Measured {
  std::optional<CylinderFit> cylinder;
  double distance_m = 0;  // camera to the object
  std::size_t points = 0;
  std::string shapes;  // what the shape detection found, for the log
};

Measured fit_labelled(const Truth& truth, AxisPrior prior) {
  Measured out;
  auto scenario = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios/cup_added.yaml");
  EXPECT_TRUE(scenario.ok());
  if (!scenario.ok()) return out;
  auto simulator = sim::Simulator::create(*scenario);
  EXPECT_TRUE(simulator.ok());
  if (!simulator.ok()) return out;
  const sim::SimFrame rendered = simulator->render(truth.phase, truth.frame);
  auto cloud = io::rgbd_to_cloud(rendered.color, rendered.depth, simulator->scenario().intrinsics);
  EXPECT_TRUE(cloud.ok());
  if (!cloud.ok()) return out;
  Cloud world = **cloud;
  const Pose& T = rendered.truth.T_world_camera;
  std::vector<int> indices;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < world.size(); ++i) {
    auto& p = world.points[i];
    if (!is_valid(p)) continue;
    p.getVector3fMap() = (T * p.getVector3fMap().cast<double>()).cast<float>();
    if (rendered.labels.labels[i] / 10 == truth.object_id) {
      indices.push_back(static_cast<int>(i));
      centroid += p.getVector3fMap().cast<double>();
    }
  }
  out.points = indices.size();
  if (indices.empty()) return out;
  out.distance_m = (centroid / static_cast<double>(indices.size()) - T.translation()).norm();
  FitConfig config;
  config.axis_prior = prior;
  auto fit = fit_object(world, indices, config, Eigen::Vector3d::UnitZ(), T.translation());
  EXPECT_TRUE(fit.ok()) << (fit.ok() ? "" : fit.error().message);
  if (!fit.ok()) return out;
  out.cylinder = fit->cylinder;
  for (const auto& shape : fit->shapes) {
    char text[96];
    std::snprintf(text, sizeof text, " %s(%zu points, r %.1f mm, half angle %.1f)", to_string(shape.kind), shape.indices.size(),
                  shape.radius_m * 1000, shape.half_angle_deg);
    out.shapes += text;
  }
  return out;
}

double axis_error_deg(const CylinderFit& c) {
  return std::acos(std::min(1.0, std::abs(c.axis.z()))) * 180.0 / M_PI;
}

void check(const char* name, const Truth& truth, double radius_tolerance_m, double axis_tolerance_deg) {
  const Measured upright = fit_labelled(truth, AxisPrior::kUpright);
  const Measured free_axis = fit_labelled(truth, AxisPrior::kNone);
  std::printf("%s: shapes found:%s\n", name, free_axis.shapes.c_str());
  ASSERT_TRUE(upright.cylinder.has_value()) << name;
  ASSERT_TRUE(free_axis.cylinder.has_value()) << name;
  std::printf("%s at %.2f m, %zu points: upright prior radius %.2f mm (true %.1f, error %+.2f), coverage %.0f deg; "
              "free axis radius %.2f mm (error %+.2f), axis error %.2f deg, rms %.2f mm\n",
              name, upright.distance_m, upright.points, upright.cylinder->radius_m * 1000, truth.radius_m * 1000,
              (upright.cylinder->radius_m - truth.radius_m) * 1000, upright.cylinder->coverage_deg,
              free_axis.cylinder->radius_m * 1000, (free_axis.cylinder->radius_m - truth.radius_m) * 1000,
              axis_error_deg(*free_axis.cylinder), free_axis.cylinder->rms_m * 1000);
  EXPECT_GT(upright.distance_m, 0.8);
  EXPECT_LT(upright.distance_m, 1.2);
  EXPECT_TRUE(upright.cylinder->axis_fixed);
  EXPECT_NEAR(upright.cylinder->radius_m, truth.radius_m, radius_tolerance_m) << name;
  EXPECT_FALSE(free_axis.cylinder->axis_fixed);
  EXPECT_NEAR(free_axis.cylinder->radius_m, truth.radius_m, radius_tolerance_m) << name;
  EXPECT_LT(axis_error_deg(*free_axis.cylinder), axis_tolerance_deg) << name;
}

// The issue asks for 2 mm and 2 degrees; measured: can -0.89 mm, 0.09 deg; cup -0.42 mm, 0.13 deg
// (CGAL explains the cup as a cone of 1.5 degrees, refined as a cylinder). The can was -0.37 mm
// before the refinement left out the points near depth edges (FitConfig::edge_margin_deg, 2 of
// the simulator's pixels): it does not flatten its silhouettes as the Xtion does, and the
// narrower arc fits a smaller circle (without the margin the radius moves by 0.2 mm over frames 0,
// 7, 19 and 33 of the phase: the change is not noise).
TEST(ScenarioFitTest, CanOfKnownRadiusAtAboutOneMetre) { check("can r 33 mm", {0, 0, 2, 0.033}, 0.001, 0.5); }
TEST(ScenarioFitTest, CupOfKnownRadiusAtAboutOneMetre) { check("cup r 40 mm", {1, 0, 4, 0.040}, 0.001, 0.5); }

}  // namespace
}  // namespace scenewatch::ontology
