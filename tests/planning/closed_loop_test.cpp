// The closed loop on the simulator (issue 31): planned views against random ones from the same
// candidates, on the clutter scenario, coverage measured against the simulator's true surfaces.
// The full comparison (10 seeds, every measure, 10 views) is scenewatch-bench --only nbv.
#include <gtest/gtest.h>

#include <cstdio>

#include "closed_loop.h"
#include "scenewatch/ontology/class_library.h"
#include "scenewatch/sim/scenario_yaml.h"

namespace scenewatch::planning::eval {
namespace {

sim::Scenario clutter() {
  auto s = sim::load_scenario(std::string(SCENEWATCH_SOURCE_DIR) + "/sample_clouds/scenarios/clutter.yaml");
  EXPECT_TRUE(s) << s.error().message;
  return *s;
}

// Mean coverage per view over seeds 1..seeds.
std::vector<double> mean_curve(const sim::Scenario& scenario, ClosedLoopSetup setup, bool random, int seeds) {
  setup.random = random;
  std::vector<double> mean(static_cast<std::size_t>(setup.views + 1), 0.0);
  for (int seed = 1; seed <= seeds; ++seed) {
    auto c = run_closed_loop(scenario, setup, static_cast<std::uint64_t>(seed));
    EXPECT_TRUE(c) << c.error().message;
    if (!c) return mean;
    EXPECT_GT(c->surface_samples, 100u);
    for (std::size_t i = 0; i < mean.size(); ++i) mean[i] += c->coverage[i] / seeds;
  }
  return mean;
}

void print(const char* name, const std::vector<double>& curve) {
  std::printf("%-8s", name);
  for (double c : curve) std::printf(" %.3f", c);
  std::printf("\n");
}

TEST(ClosedLoop, PlannedViewsCoverOneObjectFasterThanRandom) {
  const sim::Scenario scenario = clutter();
  ClosedLoopSetup setup;
  setup.target_ids = {1};  // the cereal box, in the middle of the clutter
  setup.views = 3;
  const std::vector<double> planned = mean_curve(scenario, setup, false, 3);
  const std::vector<double> random = mean_curve(scenario, setup, true, 3);
  print("planned", planned);
  print("random", random);
  EXPECT_DOUBLE_EQ(planned[0], random[0]);  // the same first view per seed
  for (std::size_t i = 1; i < planned.size(); ++i) EXPECT_GE(planned[i], planned[i - 1]);
  // Measured (3 seeds): planned 0.978 after 3 views, random 0.854.
  EXPECT_GE(planned[3], 0.95);
  EXPECT_GT(planned[3], random[3] + 0.08);
}

// Issue 31 item 3: aimed at what a robot knows of the can (its points seen so far), the ontology's
// completion fits the can class in nearly every step and leaves random behind. Against the box of
// those points it is within noise here (3 seeds, 3 views: 0.879 against 0.914); over 10 seeds and 10
// views (scenewatch-bench --only nbv) the two are within 0.05 at every view on the can.
TEST(ClosedLoop, TheCompletionOfWhatWasSeenIsATargetToo) {
  const sim::Scenario scenario = clutter();
  auto classes = ontology::load_classes_file(std::string(SCENEWATCH_SOURCE_DIR) + "/config/ontology.yaml");
  ASSERT_TRUE(classes) << classes.error().message;
  ClosedLoopSetup setup;
  setup.target_ids = {3};  // the can
  setup.views = 3;
  setup.classes = &*classes;
  std::vector<double> mean[3];
  int completed = 0;
  for (int k = 0; k < 3; ++k) {
    setup.planned_target = k == 0 ? PlannedTarget::kObservedBox : PlannedTarget::kCompletion;
    setup.random = k == 2;
    mean[k].assign(4, 0.0);
    for (int seed = 1; seed <= 3; ++seed) {
      auto c = run_closed_loop(scenario, setup, static_cast<std::uint64_t>(seed));
      ASSERT_TRUE(c) << c.error().message;
      for (int v = 0; v <= 3; ++v) mean[k][static_cast<std::size_t>(v)] += c->coverage[static_cast<std::size_t>(v)] / 3;
      if (k == 1) {
        completed += c->completed_steps;
        EXPECT_EQ(c->last_class, "can");
      }
    }
  }
  print("observed", mean[0]);
  print("complete", mean[1]);
  print("random", mean[2]);
  EXPECT_GE(completed, 8) << "the can class fitted the can's points in (measured) 8 of the 9 planning steps";
  EXPECT_DOUBLE_EQ(mean[1][0], mean[0][0]);  // the same first view
  for (std::size_t v = 1; v < 4; ++v) EXPECT_GE(mean[1][v], mean[1][v - 1]);
  EXPECT_GT(mean[1][3], 0.86) << "measured 0.879";
  EXPECT_GT(mean[1][3], mean[2][3] + 0.06) << "measured 0.879 against random's 0.791";
}

}  // namespace
}  // namespace scenewatch::planning::eval
