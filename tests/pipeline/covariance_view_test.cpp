// The seed's planner behind the memory (issue 31 item 2): the simulator's object_moved seen along
// an arc on one side of the table (cameras towards -x of the cereal box); the observation
// histories recovered from the keyframes put the planned camera on the sphere, on the box's far
// side.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scenewatch/pipeline/covariance_view_request.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::pipeline {
namespace {

TEST(CovarianceView, PlansTheObjectsUnseenSideOnTheSphere) {
  auto loaded = sim::load_scenario(test::source_dir() / "sample_clouds/scenarios/object_moved.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  const sim::Scenario scenario = sim::with_frames(sim::with_resolution(*loaded, 320, 240), 12);
  auto simulator = sim::Simulator::create(scenario);
  ASSERT_TRUE(simulator.ok()) << simulator.error().message;
  Config config;
  config.segmentation.up = Eigen::Vector3d::UnitZ();
  WorkingMemory memory(config);
  double stamp = 0;
  for (int f = 0; f < simulator->frame_count(0); ++f) {  // the first arc only: one side
    auto frame = sim::as_frame(simulator->render(0, f), scenario.intrinsics, stamp += 0.1);
    ASSERT_TRUE(frame.ok());
    ASSERT_TRUE(memory.process(*frame).ok());
  }
  const auto keyframes = memory.keyframes();
  ASSERT_GE(keyframes.size(), 2u);

  // The cereal box (id 2 of the scenario): the tracked object nearest it.
  const Eigen::Vector3d truth = scenario.objects[1].T_world_object.translation();
  const auto snapshot = memory.snapshot();
  const TrackedObject* box = nullptr;
  for (const auto& o : snapshot->objects) {
    if ((o.cluster.box.center.head<2>() - truth.head<2>()).norm() < 0.08) box = &o;
  }
  ASSERT_NE(box, nullptr);
  const Eigen::Vector3d c = box->cluster.box.center;
  Eigen::Vector3d seen_from = Eigen::Vector3d::Zero();
  for (const auto& kf : keyframes) seen_from += (kf->T_world_camera.translation() - c).normalized();
  seen_from.normalize();

  const double r = 0.7;
  for (planning::WeightRule rule : {planning::WeightRule::kAllAxesLambda, planning::WeightRule::kMajorAxisUnit,
                                    planning::WeightRule::kMajorAxisLambda}) {
    auto request = covariance_view_request(memory, box->id, rule, r);
    ASSERT_TRUE(request.ok()) << request.error().message;
    auto answer = planning::covariance_next_view(*request);
    ASSERT_TRUE(answer.ok()) << answer.error().message;
    const Eigen::Vector3d x = answer->view.T_world_camera.translation();
    const double angle_deg = std::acos((x - c).normalized().dot(seen_from)) * 180.0 / M_PI;
    std::printf("%s: %zu keyframes; %s; angle to the seen side %.1f deg\n", planning::covariance_measure_name(rule),
                keyframes.size(), answer->why.c_str(), angle_deg);
    EXPECT_NEAR((x - c).norm(), r, 1e-6);
    EXPECT_GT(answer->observed, 0u) << "the keyframes saw the box's front";
    EXPECT_LT(answer->observed, answer->points) << "nothing saw its back";
    // The camera looks at the weighted centre.
    const Eigen::Vector3d axis = answer->view.T_world_camera.linear().col(2);
    EXPECT_NEAR(axis.dot((answer->view.look_at_world - x).normalized()), 1.0, 1e-9);
    if (rule == planning::WeightRule::kAllAxesLambda) {
      EXPECT_GT(angle_deg, 150.0) << answer->why;  // measured 158.4
    }
  }

  auto unknown = covariance_view_request(memory, 999999, planning::WeightRule::kAllAxesLambda, r);
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.error().code, ErrorCode::kNotFound);
}

}  // namespace
}  // namespace scenewatch::pipeline
