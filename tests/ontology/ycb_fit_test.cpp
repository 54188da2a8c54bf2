// Real partial views of cans of known radius (../shared/data/ycb, Asus Xtion, depth in 0.1 mm):
// the scene is segmented as `scenewatch fit` does (camera frame), the object under a pixel on the
// can (read off the colour image) is fitted, and its refined cylinder is compared with the model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <cstdio>

#include "scenewatch/io/sequence.h"
#include "scenewatch/ontology/fit.h"
#include "scenewatch/segmentation/tabletop.h"
#include "test_data.h"

namespace scenewatch::ontology {
namespace {

struct CanView {
  const char* frame;
  int u, v;              // a pixel on the can's side
  double true_radius_m;  // ../shared/data/README.md, from the YCB models
  double radius_tolerance_m;
  /// The writing tablet of frames 3 and 4 is smaller than the default support (0.1 m2).
  double min_plane_area_m2 = 0.1;
  int max_planes = 3;
};

struct Outcome {
  std::optional<CylinderFit> cylinder;
  double tilt_deg = 0;  // of the axis from the supporting plane's normal
  std::size_t points = 0;
  std::optional<ObjectFit> fit;
};

Outcome fit_can(const CanView& can, AxisPrior prior, NormalSearch normals = NormalSearch::kGrid) {
  Outcome out;
  io::SequenceOptions options;
  options.depth_scale_m = 1e-4;
  auto seq = io::open_sequence(test::data_dir() / "ycb", options);
  EXPECT_TRUE(seq.ok());
  if (!seq.ok()) return out;
  std::size_t index = seq->frames.size();
  for (std::size_t i = 0; i < seq->frames.size(); ++i)
    if (seq->frames[i].name == can.frame) index = i;
  EXPECT_LT(index, seq->frames.size()) << can.frame;
  if (index >= seq->frames.size()) return out;
  auto frame = io::load_sequence_frame(*seq, index);
  EXPECT_TRUE(frame.ok());
  if (!frame.ok()) return out;
  const Cloud& cloud = *frame->cloud;
  segmentation::Config segmentation_config;
  segmentation_config.min_plane_area_m2 = can.min_plane_area_m2;
  segmentation_config.max_planes = can.max_planes;
  const segmentation::Segmentation scene = segmentation::segment(cloud, segmentation_config);
  const int pixel = can.v * static_cast<int>(cloud.width) + can.u;
  const ObjectCluster* object = nullptr;
  for (const auto& o : scene.objects)
    if (std::find(o.indices.begin(), o.indices.end(), pixel) != o.indices.end()) object = &o;
  EXPECT_NE(object, nullptr) << "no object at pixel " << can.u << "," << can.v << " of " << can.frame;
  if (object == nullptr) return out;
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  for (const auto& plane : scene.planes)
    if (plane.id == object->plane_id) up = plane.normal;
  FitConfig config;
  config.axis_prior = prior;
  config.normal_search = normals;
  auto fit = fit_object(cloud, object->indices, config, up);
  EXPECT_TRUE(fit.ok()) << (fit.ok() ? "" : fit.error().message);
  if (!fit.ok()) return out;
  out.points = object->indices.size();
  out.cylinder = fit->cylinder;
  out.fit = *fit;
  if (out.cylinder) out.tilt_deg = std::acos(std::min(1.0, std::abs(out.cylinder->axis.dot(up)))) * 180.0 / M_PI;
  return out;
}

class YcbFitTest : public ::testing::Test {
 protected:
  void SetUp() override { SCENEWATCH_REQUIRE_DATA("ycb/frame-000003.depth.png"); }
};

// Tolerances a little above the errors measured (docs/ontology.md, "Primitive fitting"): frame 3 -1.4 mm,
// frame 1 +1.0 mm, frame 4 -0.4 mm. Frame 1's can was 7.7 mm too wide while the points within a
// few pixels of its silhouette and of the mustard bottle pulled the fit: the Xtion flattens the
// depth there (FitConfig::edge_margin_deg); leaving them out costs frame 3 2.1 mm (+0.7 before)
// and the simulator's can 0.5 mm (scenario_fit_test), whose seen arcs are wider.
const CanView kSoupFrame3{"frame-000003", 225, 400, 0.0329, 0.0015, 0.03};
const CanView kSoupFrame1{"frame-000001", 430, 330, 0.0329, 0.0015};
// The tablet of frame 4 is mostly covered (by the pitcher, the mustard and the can): found as a
// support from 0.02 m2 with up to 6 planes. The can is short and wide: shape detection calls it
// a sphere, the cylinder comes from the upright circle fit (-0.4 mm).
const CanView kTunaFrame4{"frame-000004", 270, 395, 0.0420, 0.001, 0.02, 6};

void check(const CanView& can) {
  const Outcome upright = fit_can(can, AxisPrior::kUpright);
  ASSERT_TRUE(upright.cylinder.has_value()) << can.frame << ": no cylinder";
  const Outcome free_axis = fit_can(can, AxisPrior::kNone);
  std::printf("%s: %zu points; upright prior (from %s): radius %.1f mm (true %.1f, error %+.1f), height %.1f mm, rms %.2f mm, "
              "coverage %.0f deg",
              can.frame, upright.points, upright.cylinder->from_detection ? "detection" : "circle fit",
              upright.cylinder->radius_m * 1000, can.true_radius_m * 1000,
              (upright.cylinder->radius_m - can.true_radius_m) * 1000, upright.cylinder->height_m * 1000,
              upright.cylinder->rms_m * 1000, upright.cylinder->coverage_deg);
  if (free_axis.cylinder) {
    std::printf("; free axis: radius %.1f mm (error %+.1f), tilt %.1f deg\n", free_axis.cylinder->radius_m * 1000,
                (free_axis.cylinder->radius_m - can.true_radius_m) * 1000, free_axis.tilt_deg);
  } else {
    std::printf("; free axis: no cylinder\n");
  }
  EXPECT_NEAR(upright.cylinder->radius_m, can.true_radius_m, can.radius_tolerance_m) << can.frame;
  EXPECT_TRUE(upright.cylinder->axis_fixed) << can.frame << ": the can stands upright on its support";
  // One side seen: more than a quarter, less than a half turn.
  EXPECT_GT(upright.cylinder->coverage_deg, 90.0) << can.frame;
  EXPECT_LT(upright.cylinder->coverage_deg, 200.0) << can.frame;
}

TEST_F(YcbFitTest, SoupCanFrame3) { check(kSoupFrame3); }
TEST_F(YcbFitTest, SoupCanFrame1) { check(kSoupFrame1); }
TEST_F(YcbFitTest, TunaCanFrame4) { check(kTunaFrame4); }

// The grid's k nearest neighbours against PCL's kd-tree (the oracle, exact k-NN) on the real cans:
// the same points get a normal, the normals agree (angles between them, degrees), and so do the
// refined cylinders.
TEST_F(YcbFitTest, GridNormalsAgreeWithTheKdTreeOracle) {
  for (const CanView* can : {&kSoupFrame3, &kSoupFrame1, &kTunaFrame4}) {
    SCOPED_TRACE(can->frame);
    const Outcome grid = fit_can(*can, AxisPrior::kUpright, NormalSearch::kGrid);
    const Outcome kd = fit_can(*can, AxisPrior::kUpright, NormalSearch::kKdTree);
    ASSERT_TRUE(grid.fit && kd.fit && grid.cylinder && kd.cylinder);
    ASSERT_EQ(grid.fit->sample_points.size(), kd.fit->sample_points.size());
    std::vector<double> angles;
    for (std::size_t i = 0; i < grid.fit->sample_points.size(); ++i) {
      ASSERT_EQ(grid.fit->sample_points[i], kd.fit->sample_points[i]);
      angles.push_back(std::acos(std::min(1.0, grid.fit->sample_normals[i].dot(kd.fit->sample_normals[i]))) * 180.0 / M_PI);
    }
    std::sort(angles.begin(), angles.end());
    const double median = angles[angles.size() / 2], p99 = angles[angles.size() * 99 / 100];
    std::printf("%s: %zu normals, angle to the kd-tree's: median %.3f deg, 99th percentile %.3f deg, max %.1f deg; "
                "radius %.2f mm (kd-tree %.2f mm)\n",
                can->frame, angles.size(), median, p99, angles.back(), grid.cylinder->radius_m * 1000, kd.cylinder->radius_m * 1000);
    // Measured: median 0.000 on all three (the same neighbours), 99th percentile up to 1.6 degrees
    // (frame 1: ties at the k-th neighbour, PCL's float covariance), radii within 0.01 mm.
    EXPECT_LT(median, 0.01);
    EXPECT_LT(p99, 2.0);
    EXPECT_NEAR(grid.cylinder->radius_m, kd.cylinder->radius_m, 0.0001);
  }
}

}  // namespace
}  // namespace scenewatch::ontology
