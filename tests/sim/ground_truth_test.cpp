// Ground truth: DoF decomposition, manipulations and frozen-DoF motions of the shipped hand
// scenarios, changes of the two-phase scenarios, and the JSON round trip.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "scenewatch/sim/ground_truth.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::sim {
namespace {

Simulator shipped(const std::string& name) {
  auto sc = load_scenario(test::source_dir() / "sample_clouds" / "scenarios" / (name + ".yaml"));
  if (!sc) throw std::runtime_error(sc.error().message);
  auto sim = Simulator::create(std::move(*sc));
  if (!sim) throw std::runtime_error(sim.error().message);
  return std::move(*sim);
}

std::vector<std::string> names(const DofFlags& f) {
  std::vector<std::string> v;
  for (int k = 0; k < kDofCount; ++k) {
    if (f[static_cast<std::size_t>(k)]) v.push_back(to_string(static_cast<Dof>(k)));
  }
  return v;
}

TEST(GroundTruth, DofDeltaInTheSupportFrame) {
  Pose support = Pose::Identity();
  support.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  support.translation() = Eigen::Vector3d(1, 2, 0.75);
  Pose start = support * Eigen::Translation3d(0.1, 0.0, 0.0);
  // Lift by 5 cm and turn by 30 degrees about the support normal: z and yaw only.
  Pose lifted = support * Eigen::Translation3d(0.1, 0.0, 0.05) * Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ());
  DofVector d = dof_delta(support, start, lifted);
  EXPECT_NEAR(d[0], 0.0, 1e-12);
  EXPECT_NEAR(d[1], 0.0, 1e-12);
  EXPECT_NEAR(d[2], 0.05, 1e-12);
  EXPECT_NEAR(d[3], 0.0, 1e-9);
  EXPECT_NEAR(d[4], 0.0, 1e-9);
  EXPECT_NEAR(d[5], 30.0, 1e-9);
  // A tilt about the support's x axis is a roll.
  Pose tilted = support * Eigen::Translation3d(0.1, 0.0, 0.0) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX());
  d = dof_delta(support, start, tilted);
  EXPECT_NEAR(d[3], 0.2 * 180 / M_PI, 1e-9);
  EXPECT_NEAR(d[4], 0.0, 1e-9);
  EXPECT_NEAR(d[5], 0.0, 1e-9);
}

TEST(GroundTruth, UprightCarryMovesXYZAndYawOnly) {
  const Simulator sim = shipped("hand_picks_cup_upright");
  const SequenceTruth t = sim.sequence_truth(0);
  ASSERT_EQ(t.manipulations.size(), 1u);
  const Manipulation& m = t.manipulations[0];
  EXPECT_EQ(m.object_id, 3);
  EXPECT_EQ(m.grasp_frame, 35);
  EXPECT_EQ(m.release_frame, 100);
  EXPECT_EQ(names(m.moved), (std::vector<std::string>{"x", "y", "z", "yaw"}));
  EXPECT_NEAR(m.dof_range[5], 40.0, 1e-6);
  EXPECT_NEAR(m.dof_range[2], 0.12, 1e-6);
  EXPECT_LT(m.dof_range[3], 1e-6);
  EXPECT_LT(m.dof_range[4], 1e-6);
  EXPECT_TRUE(t.frozen_dof_motions.empty());
  // The hand touches the cup before it grasps it and until after it lets go.
  ASSERT_EQ(t.held.size(), 1u);
  ASSERT_EQ(t.touched.size(), 1u);
  EXPECT_EQ(t.touched[0].object_id, 3);
  EXPECT_LE(t.touched[0].first_frame, t.held[0].first_frame);
  EXPECT_GE(t.touched[0].last_frame, t.held[0].last_frame);
  EXPECT_GT(t.touched[0].first_frame, 0);
  // The other objects never move; the cup ends upright on the table top.
  const FrameTruth& last = t.frames.back();
  for (const ObjectPose& o : last.objects) {
    const Pose& first = t.frames.front().objects[static_cast<std::size_t>(&o - last.objects.data())].T_world_object;
    if (o.id != 3) {
      EXPECT_TRUE(o.T_world_object.isApprox(first)) << o.id;
    } else {
      EXPECT_NEAR(o.T_world_object.translation().z(), 0.75, 1e-9);
      EXPECT_NEAR(o.T_world_object.linear()(2, 2), 1.0, 1e-12);
    }
  }
}

TEST(GroundTruth, TiltAfterUprightCarryIsAFrozenDofMotion) {
  const Simulator sim = shipped("hand_tilts_cup");
  const SequenceTruth t = sim.sequence_truth(0);
  ASSERT_EQ(t.manipulations.size(), 2u);
  EXPECT_EQ(names(t.manipulations[0].moved), (std::vector<std::string>{"x", "y", "z", "yaw"}));
  const Manipulation& tilt = t.manipulations[1];
  EXPECT_TRUE(tilt.moved[3] || tilt.moved[4]);
  EXPECT_GT(std::max(tilt.dof_range[3], tilt.dof_range[4]), 30.0);
  ASSERT_EQ(t.frozen_dof_motions.size(), 1u);
  const FrozenDofMotion& fm = t.frozen_dof_motions[0];
  EXPECT_EQ(fm.object_id, 3);
  EXPECT_EQ(fm.manipulation, 1);
  for (Dof d : fm.dofs) EXPECT_TRUE(d == Dof::kRoll || d == Dof::kPitch) << to_string(d);
  EXPECT_GT(fm.first_frame, 130);
  EXPECT_LT(fm.first_frame, 150);
}

TEST(GroundTruth, ChangesOfTheTwoPhaseScenarios) {
  {
    const auto c = shipped("glasses_removed").changes();
    ASSERT_EQ(c.size(), 1u);
    EXPECT_EQ(c[0].from, "before");
    EXPECT_EQ(c[0].to, "after");
    ASSERT_EQ(c[0].removed.size(), 2u);
    EXPECT_EQ(c[0].removed[0].object.id, 1);
    EXPECT_EQ(c[0].removed[1].object.id, 2);
    EXPECT_TRUE(c[0].removed[0].object.transparent);
    EXPECT_TRUE(c[0].added.empty());
    EXPECT_TRUE(c[0].moved.empty());
  }
  {
    const auto c = shipped("cup_added").changes();
    ASSERT_EQ(c.size(), 1u);
    ASSERT_EQ(c[0].added.size(), 1u);
    EXPECT_EQ(c[0].added[0].object.id, 4);
    EXPECT_TRUE(c[0].removed.empty());
    EXPECT_TRUE(c[0].moved.empty());
  }
  {
    const auto c = shipped("object_moved").changes();
    ASSERT_EQ(c.size(), 1u);
    ASSERT_EQ(c[0].moved.size(), 1u);
    EXPECT_EQ(c[0].moved[0].id, 2);
    EXPECT_NEAR(c[0].moved[0].translation_world_m.norm(), std::hypot(0.1, 0.1), 1e-9);
    EXPECT_NEAR(c[0].moved[0].rotation_deg, 30.0, 1e-9);
    EXPECT_NEAR(c[0].moved[0].dof_delta[5], 30.0, 1e-9);
    EXPECT_TRUE(c[0].added.empty());
    EXPECT_TRUE(c[0].removed.empty());
  }
}

TEST(GroundTruth, JsonRoundTrip) {
  Simulator sim = shipped("hand_tilts_cup");
  const SequenceTruth t = sim.sequence_truth(0);
  const auto dir = test::make_temp_dir("sim-gt");
  ASSERT_TRUE(write_ground_truth(dir / "ground_truth.json", t).ok());
  auto back = read_ground_truth(dir / "ground_truth.json");
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->scenario, t.scenario);
  EXPECT_EQ(back->phase, t.phase);
  EXPECT_EQ(back->seed, t.seed);
  ASSERT_EQ(back->frames.size(), t.frames.size());
  for (std::size_t f = 0; f < t.frames.size(); ++f) {
    EXPECT_TRUE(back->frames[f].T_world_camera.matrix() == t.frames[f].T_world_camera.matrix());
    ASSERT_EQ(back->frames[f].objects.size(), t.frames[f].objects.size());
    for (std::size_t o = 0; o < t.frames[f].objects.size(); ++o) {
      EXPECT_EQ(back->frames[f].objects[o].id, t.frames[f].objects[o].id);
      EXPECT_TRUE(back->frames[f].objects[o].T_world_object.matrix() == t.frames[f].objects[o].T_world_object.matrix());
    }
    EXPECT_EQ(back->frames[f].held, t.frames[f].held);
    EXPECT_EQ(back->frames[f].touched, t.frames[f].touched);
    EXPECT_EQ(back->frames[f].T_world_hand.has_value(), t.frames[f].T_world_hand.has_value());
  }
  ASSERT_EQ(back->manipulations.size(), t.manipulations.size());
  EXPECT_EQ(back->manipulations[1].moved, t.manipulations[1].moved);
  EXPECT_EQ(back->manipulations[1].dof_range, t.manipulations[1].dof_range);
  ASSERT_EQ(back->frozen_dof_motions.size(), 1u);
  EXPECT_EQ(back->frozen_dof_motions[0].dofs, t.frozen_dof_motions[0].dofs);
  EXPECT_EQ(back->frozen_dof_motions[0].first_frame, t.frozen_dof_motions[0].first_frame);
  ASSERT_EQ(back->objects.size(), t.objects.size());
  EXPECT_EQ(back->objects[2].shape.open_top, t.objects[2].shape.open_top);
  EXPECT_EQ(back->objects[2].shape.radius_m, t.objects[2].shape.radius_m);

  // Changes round trip.
  const auto changes = shipped("object_moved").changes();
  ASSERT_TRUE(write_changes(dir / "changes.json", "object_moved", changes).ok());
  auto changes_back = read_changes(dir / "changes.json");
  ASSERT_TRUE(changes_back.ok()) << changes_back.error().message;
  ASSERT_EQ(changes_back->size(), 1u);
  ASSERT_EQ((*changes_back)[0].moved.size(), 1u);
  EXPECT_TRUE((*changes_back)[0].moved[0].T_world_after.matrix() == changes[0].moved[0].T_world_after.matrix());

  // A broken file is an error naming the key.
  std::ofstream(dir / "bad.json") << R"({"format": "scenewatch-sim-ground-truth", "version": 1})";
  auto bad = read_ground_truth(dir / "bad.json");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("scenario"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace scenewatch::sim
