// The seed's experiment (D5.1 Figs. 3.12 and 3.13) reproduced with the set-up fixed in
// TwoCameraExperiment: the planned camera against random positions on the sphere.
#include <gtest/gtest.h>

#include <cstdio>

#include "scenewatch/planning/point_filter.h"

namespace scenewatch::planning {
namespace {

constexpr int kRuns = 10;

// The trace per step averaged over kRuns runs on one scene.
std::vector<double> mean_trace(const TwoCameraExperiment& setup, const ViewStrategy& strategy) {
  std::vector<double> mean(static_cast<std::size_t>(setup.steps), 0.0);
  for (int run = 0; run < kRuns; ++run) {
    const ExperimentCurve c = run_two_camera_experiment(setup, strategy, /*scene_seed=*/11, /*run_seed=*/100 + run);
    for (std::size_t s = 0; s < mean.size(); ++s) mean[s] += c.trace[s] / kRuns;
  }
  return mean;
}

TEST(Reproduction, PlannedBeatsRandomOnTheTraceOverTheFirst15Steps) {
  TwoCameraExperiment setup;
  setup.steps = 15;
  const std::vector<double> planned = mean_trace(setup, {false, WeightRule::kAllAxesLambda});
  const std::vector<double> random = mean_trace(setup, {true, WeightRule::kAllAxesLambda});
  for (int s = 0; s < setup.steps; ++s) {
    std::printf("step %2d  planned %.4g  random %.4g  ratio %.3f\n", s + 1, planned[s], random[s], planned[s] / random[s]);
    EXPECT_LT(planned[s], random[s]) << "step " << s + 1;
  }
}

TEST(Reproduction, EveryWeightRuleBeatsRandomOverTheFirst15Steps) {
  // The seed (Fig. 3.13) finds rule (3.23) the best of the three. Ours does not: with this set-up
  // (3.21) and (3.22) come out about 15 % lower in mean trace than (3.23) (printed below, and by
  // scenewatch-bench --only nbv). What holds for all three is that they beat random views.
  TwoCameraExperiment setup;
  setup.steps = 15;
  double random_sum = 0.0;
  for (double t : mean_trace(setup, {true, WeightRule::kAllAxesLambda})) random_sum += t;
  for (WeightRule rule : {WeightRule::kMajorAxisUnit, WeightRule::kMajorAxisLambda, WeightRule::kAllAxesLambda}) {
    double sum = 0.0;
    for (double t : mean_trace(setup, {false, rule})) sum += t;
    std::printf("%-13s mean trace over steps 1-15: %.4g (random %.4g)\n", to_string(rule), sum / setup.steps,
                random_sum / setup.steps);
    EXPECT_LT(sum, 0.8 * random_sum) << to_string(rule);
  }
}

TEST(Reproduction, TheFiltersUncertaintyFallsAtEveryStep) {
  // The EKF itself: every update adds information, so the trace never grows, and 50 steps of two
  // views at 1 px noise leave a small fraction of the first step's trace.
  TwoCameraExperiment setup;
  setup.steps = 50;
  const ExperimentCurve c = run_two_camera_experiment(setup, {true, WeightRule::kAllAxesLambda}, 11, 5);
  EXPECT_LT(c.trace.back(), 0.03 * c.trace.front());  // measured 0.018
  for (std::size_t s = 1; s < c.trace.size(); ++s) EXPECT_LE(c.trace[s], c.trace[s - 1] * (1 + 1e-9));
}

}  // namespace
}  // namespace scenewatch::planning
