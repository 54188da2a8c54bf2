// Classification against ground truth: simulated objects of exactly known shape and size (the
// simulator's labels pick their points, world frame, the table's normal is z), and real views
// (../shared/data: the YCB cans, the PCL mug). Floors a little beyond the figures measured
// (docs/ontology.md, "Object classes").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <cstdlib>
#include <sstream>
#include <string>

#include "scenewatch/io/cloud_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/ontology/class_library.h"
#include "scenewatch/ontology/describe.h"
#include "scenewatch/segmentation/tabletop.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::ontology {
namespace {

ClassLibrary shipped_classes() {
  auto library = load_classes_file(test::source_dir() / "config/ontology.yaml");
  EXPECT_TRUE(library.ok()) << (library.ok() ? "" : library.error().message);
  return library.ok() ? *library : ClassLibrary{};
}

double tilt_deg(const Eigen::Vector3d& axis, const Eigen::Vector3d& up) {
  return std::acos(std::min(1.0, std::abs(axis.normalized().dot(up.normalized())))) * 180.0 / M_PI;
}

void print(const std::string& name, const ObjectDescription& d) {
  std::printf("%s: class %s (score %.2f)", name.c_str(), d.class_name.c_str(), d.score);
  if (d.primitive) {
    const ShapeFit& f = *d.primitive;
    std::printf(", %s r %.2f mm (%.2f..%.2f), h %.1f mm, size %.1f x %.1f mm, rms %.2f mm, coverage %.0f deg, inside %.2f",
                to_string(f.shape), f.radius_m * 1000, f.bottom_radius_m * 1000, f.top_radius_m * 1000, f.height_m * 1000,
                f.size_m.x() * 1000, f.size_m.y() * 1000, f.rms_m * 1000, f.coverage_deg, f.inner_fraction);
  }
  std::printf("\n");
  for (const auto& m : d.candidates)
    if (!m.accepted) std::printf("    not %s (%.2f): %s\n", m.class_name.c_str(), m.score, m.reason.c_str());
}

// ---------------------------------------------------------------------------------------------
// Simulator

/// One simulated object: its points (world frame) from the labels, described with world up.
struct SimObject {
  std::string scenario_yaml;  // the scenario's text
  int phase = 0;
  std::uint16_t object_id = 0;
};

Result<ObjectDescription> describe_sim(const SimObject& object, const ClassLibrary& library, double* distance_m = nullptr) {
  auto scenario = sim::parse_scenario(object.scenario_yaml, "test scenario");
  if (!scenario) return scenario.error();
  auto simulator = sim::Simulator::create(*scenario);
  if (!simulator) return simulator.error();
  const sim::SimFrame rendered = simulator->render(object.phase, 0);
  auto cloud = io::rgbd_to_cloud(rendered.color, rendered.depth, simulator->scenario().intrinsics);
  if (!cloud) return cloud.error();
  const Pose& T = rendered.truth.T_world_camera;
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < (*cloud)->size(); ++i) {
    const auto& p = (*cloud)->points[i];
    if (is_valid(p) && rendered.labels.labels[i] / 10 == object.object_id) points.push_back(T * p.getVector3fMap().cast<double>());
  }
  if (distance_m && !points.empty()) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto& p : points) c += p;
    *distance_m = (c / static_cast<double>(points.size()) - T.translation()).norm();
  }
  return describe(points, Eigen::Vector3d::UnitZ(), library, T.translation());
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string cup_added() { return read_text(test::source_dir() / "sample_clouds/scenarios/cup_added.yaml"); }

/// cup_added with its cup (r 40 mm, the widest cup of the other tests) replaced.
std::string with_cup(const std::string& cup) {
  std::string text = cup_added();
  const std::string old = "{id: 4, name: cup, shape: cylinder, radius_m: 0.04, height_m: 0.1, open_top: true, wall_m: 0.005,";
  const std::size_t at = text.find(old);
  EXPECT_NE(at, std::string::npos) << "cup_added.yaml changed";
  if (at != std::string::npos) text.replace(at, old.size(), cup);
  return text;
}

TEST(ClassifySimTest, CanOfKnownSizeAtAboutOneMetre) {
  const ClassLibrary library = shipped_classes();
  double distance = 0;
  auto d = describe_sim({cup_added(), 0, 2}, library, &distance);
  ASSERT_TRUE(d.ok()) << d.error().message;
  print("sim can r 33 h 122", *d);
  EXPECT_GT(distance, 0.8);
  EXPECT_LT(distance, 1.2);
  EXPECT_EQ(d->class_name, "can");
  ASSERT_TRUE(d->primitive);
  EXPECT_NEAR(d->primitive->radius_m, 0.033, 0.002);
  EXPECT_LT(tilt_deg(d->primitive->axis, Eigen::Vector3d::UnitZ()), 2.0);
  EXPECT_NEAR(d->primitive->height_m, 0.122, 0.01);
  // Grasps on the primitive: side at mid height, 66 mm wide; top grasp from above.
  ASSERT_EQ(d->grasps.size(), 2u);
  EXPECT_EQ(d->grasps[0].name, "side_mid");
  EXPECT_NEAR(d->grasps[0].position.z(), 0.75 + 0.061, 0.01);  // the table top is at 0.75 m
  EXPECT_NEAR(d->grasps[0].width_m, 0.066, 0.004);
  EXPECT_NEAR(d->grasps[0].approach.z(), 0.0, 1e-9);
  EXPECT_NEAR(d->grasps[1].approach.z(), -1.0, 1e-6);
  // The completed can: the whole surface, the unseen back included, on the true cylinder.
  ASSERT_FALSE(d->completed_points.empty());
  const Eigen::Vector2d truth_xy(-0.12, 0.2);
  double worst = 0;
  for (const auto& p : d->completed_points) {
    const double rho = (p.head<2>() - truth_xy).norm();
    if (p.z() > 0.76 && p.z() < 0.75 + 0.112) worst = std::max(worst, std::abs(rho - 0.033));
  }
  EXPECT_LT(worst, 0.003) << "side of the completed can off the true cylinder";
}

TEST(ClassifySimTest, CupIsACup) {
  const ClassLibrary library = shipped_classes();
  auto d = describe_sim({cup_added(), 1, 4}, library);
  ASSERT_TRUE(d.ok()) << d.error().message;
  print("sim cup r 40", *d);
  EXPECT_EQ(d->class_name, "cup");
  ASSERT_TRUE(d->primitive);
  EXPECT_NEAR(d->primitive->radius_m, 0.040, 0.002);
  EXPECT_LT(tilt_deg(d->primitive->axis, Eigen::Vector3d::UnitZ()), 2.0);
}

// The issue: a cup 30 % wider than any seen before is still a cup (class bounds are generic).
TEST(ClassifySimTest, CupThirtyPercentWiderIsStillACup) {
  const ClassLibrary library = shipped_classes();
  auto d = describe_sim({with_cup("{id: 4, name: cup, shape: cylinder, radius_m: 0.052, height_m: 0.1, open_top: true, wall_m: 0.005,"), 1, 4},
                        library);
  ASSERT_TRUE(d.ok()) << d.error().message;
  print("sim cup r 52", *d);
  EXPECT_EQ(d->class_name, "cup");
  ASSERT_TRUE(d->primitive);
  EXPECT_NEAR(d->primitive->radius_m, 0.052, 0.002);
}

TEST(ClassifySimTest, TaperingCupIsACup) {
  const ClassLibrary library = shipped_classes();
  auto d = describe_sim(
      {with_cup("{id: 4, name: cup, shape: frustum, radius_m: 0.03, top_radius_m: 0.042, height_m: 0.11, open_top: true, wall_m: 0.004,"), 1, 4},
      library);
  ASSERT_TRUE(d.ok()) << d.error().message;
  print("sim tapering cup r 30..42", *d);
  EXPECT_EQ(d->class_name, "cup");
  ASSERT_TRUE(d->primitive);
  EXPECT_NEAR(d->primitive->bottom_radius_m, 0.030, 0.004);
  EXPECT_NEAR(d->primitive->top_radius_m, 0.042, 0.004);
  EXPECT_GT(d->primitive->taper_deg, 2.0);
}

TEST(ClassifySimTest, BoxAndBall) {
  const ClassLibrary library = shipped_classes();
  auto box = describe_sim({cup_added(), 0, 1}, library);
  ASSERT_TRUE(box.ok()) << box.error().message;
  print("sim box 180 x 100 x 120", *box);
  EXPECT_EQ(box->class_name, "box");
  if (box->primitive) {
    EXPECT_NEAR(box->primitive->height_m, 0.12, 0.01);
  }
  auto ball = describe_sim({cup_added(), 0, 3}, library);
  ASSERT_TRUE(ball.ok()) << ball.error().message;
  print("sim ball r 45", *ball);
  EXPECT_EQ(ball->class_name, "ball");
  if (ball->primitive) {
    EXPECT_NEAR(ball->primitive->radius_m, 0.045, 0.002);
  }
}

// ---------------------------------------------------------------------------------------------
// Real data

struct RealScene {
  segmentation::Segmentation scene;
  CloudConstPtr cloud;
};

RealScene segment_ycb(const char* frame) {
  RealScene out;
  io::SequenceOptions options;
  options.depth_scale_m = 1e-4;
  auto seq = io::open_sequence(test::data_dir() / "ycb", options);
  EXPECT_TRUE(seq.ok());
  if (!seq.ok()) return out;
  for (std::size_t i = 0; i < seq->frames.size(); ++i) {
    if (seq->frames[i].name != frame) continue;
    auto loaded = io::load_sequence_frame(*seq, i);
    EXPECT_TRUE(loaded.ok());
    if (!loaded.ok()) return out;
    out.cloud = loaded->cloud;
  }
  EXPECT_TRUE(out.cloud) << frame;
  if (!out.cloud) return out;
  // As ycb_fit_test: the writing tablets are small supports.
  segmentation::Config config;
  config.min_plane_area_m2 = 0.02;
  config.max_planes = 6;
  out.scene = segmentation::segment(*out.cloud, config);
  return out;
}

Eigen::Vector3d support_normal(const RealScene& s, const ObjectCluster& o) {
  for (const auto& plane : s.scene.planes)
    if (plane.id == o.plane_id) return plane.normal;
  return Eigen::Vector3d::UnitZ();
}

struct YcbCan {
  const char* frame;
  int u, v;
  double radius_m;
};

// Every object of 1000 points or more in the frame is described; the can under the pixel must be
// a can of the true radius (3 mm) standing upright (5 degrees); none of the others may be a can.
void check_ycb(const YcbCan& can, const ClassLibrary& library) {
  const RealScene s = segment_ycb(can.frame);
  ASSERT_TRUE(s.cloud);
  const int pixel = can.v * static_cast<int>(s.cloud->width) + can.u;
  bool found = false;
  for (std::size_t i = 0; i < s.scene.objects.size(); ++i) {
    const ObjectCluster& o = s.scene.objects[i];
    if (o.indices.size() < 1000) continue;
    const Eigen::Vector3d up = support_normal(s, o);
    auto d = describe(*s.cloud, o.indices, up, library);
    ASSERT_TRUE(d.ok()) << d.error().message;
    const bool is_the_can = std::find(o.indices.begin(), o.indices.end(), pixel) != o.indices.end();
    print(std::string(can.frame) + " object " + std::to_string(i) + " (" + std::to_string(o.indices.size()) + " points" +
              (is_the_can ? ", the can)" : ")"),
          *d);
    if (!is_the_can) {
      EXPECT_NE(d->class_name, "can") << can.frame << " object " << i << " is not a can";
      continue;
    }
    found = true;
    EXPECT_EQ(d->class_name, "can") << can.frame;
    ASSERT_TRUE(d->primitive);
    EXPECT_NEAR(d->primitive->radius_m, can.radius_m, 0.003) << can.frame;
    EXPECT_LT(tilt_deg(d->primitive->axis, up), 5.0) << can.frame;
  }
  EXPECT_TRUE(found) << "no object at the can's pixel in " << can.frame;
}

class ClassifyRealTest : public ::testing::Test {
 protected:
  void SetUp() override { SCENEWATCH_REQUIRE_DATA("ycb/frame-000003.depth.png"); }
};

TEST_F(ClassifyRealTest, YcbSoupCanFrame3) { check_ycb({"frame-000003", 225, 400, 0.0329}, shipped_classes()); }
TEST_F(ClassifyRealTest, YcbTunaCanFrame4) { check_ycb({"frame-000004", 270, 395, 0.0420}, shipped_classes()); }

// Frame 1: the can is a can of its radius (+1.0 mm, ycb_fit_test), and no other object is a can.
TEST_F(ClassifyRealTest, YcbFrame1NothingElseIsACan) {
  const ClassLibrary library = shipped_classes();
  const RealScene s = segment_ycb("frame-000001");
  ASSERT_TRUE(s.cloud);
  const int can_pixel = 330 * static_cast<int>(s.cloud->width) + 430;
  for (std::size_t i = 0; i < s.scene.objects.size(); ++i) {
    const ObjectCluster& o = s.scene.objects[i];
    if (o.indices.size() < 1000) continue;
    auto d = describe(*s.cloud, o.indices, support_normal(s, o), library);
    ASSERT_TRUE(d.ok()) << d.error().message;
    const bool is_the_can = std::find(o.indices.begin(), o.indices.end(), can_pixel) != o.indices.end();
    print("frame-000001 object " + std::to_string(i) + (is_the_can ? " (the can)" : ""), *d);
    if (is_the_can) {
      EXPECT_EQ(d->class_name, "can");
      ASSERT_TRUE(d->primitive);
      EXPECT_NEAR(d->primitive->radius_m, 0.0329, 0.003);
    } else {
      EXPECT_NE(d->class_name, "can") << "object " << i;
    }
  }
}

TEST(ClassifyMugTest, PclStereoMugIsACup) {
  SCENEWATCH_REQUIRE_DATA("pcl/table_scene_mug_stereo_textured.pcd");
  auto file = io::read_cloud(test::data_dir() / "pcl/table_scene_mug_stereo_textured.pcd");
  ASSERT_TRUE(file.ok()) << file.error().message;
  const Cloud& cloud = *file->cloud;
  const segmentation::Segmentation scene = segmentation::segment(cloud, segmentation::Config{});
  const ObjectCluster* mug = nullptr;
  for (const auto& o : scene.objects)
    if (!mug || o.indices.size() > mug->indices.size()) mug = &o;
  ASSERT_NE(mug, nullptr);
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  for (const auto& plane : scene.planes)
    if (plane.id == mug->plane_id) up = plane.normal;
  auto d = describe(cloud, mug->indices, up, shipped_classes());
  ASSERT_TRUE(d.ok()) << d.error().message;
  print("PCL stereo mug", *d);
  EXPECT_EQ(d->class_name, "cup");
  ASSERT_TRUE(d->primitive);
  // A mug of about 41 mm (YCB's; this one is not measured): a sensible mug size.
  EXPECT_GT(d->primitive->radius_m, 0.03);
  EXPECT_LT(d->primitive->radius_m, 0.055);
}

}  // namespace
}  // namespace scenewatch::ontology

namespace scenewatch::ontology {
namespace {

// One labelled mOSD scene (../shared/data/mosd/learn/learnN.pcd): its cloud, its labels and the
// up the survey describes its objects with, the normal of the segmentation's largest plane (the
// table). Fails the calling test and returns nothing when the file cannot be read.
struct MosdScene {
  CloudConstPtr cloud;
  std::vector<std::uint32_t> labels;
  Eigen::Vector3d up{0, -1, 0};
};

std::optional<MosdScene> load_mosd_scene(int n) {
  const auto path = test::data_dir() / "mosd/learn" / ("learn" + std::to_string(n) + ".pcd");
  auto file = io::read_cloud(path);
  auto labels = io::read_pcd_labels(path);
  EXPECT_TRUE(file.ok() && labels.ok()) << path;
  if (!file.ok() || !labels.ok()) return std::nullopt;
  MosdScene scene{file->cloud, std::move(*labels)};
  const segmentation::Segmentation segmented = segmentation::segment(*scene.cloud, segmentation::Config{});
  double area = 0;
  for (const auto& plane : segmented.planes)
    if (plane.area_m2 > area) scene.up = plane.normal, area = plane.area_m2;
  return scene;
}

// mOSD (../shared/data/mosd/learn): every labelled object of 500 points or more, described with
// the table's normal (the segmentation's largest plane) as up. A survey printed for docs/ontology.md:
// the dataset has no per-object category, only the scenes' (learn0-16 boxes, learn17-24 stacked
// boxes, learn25-32 occluded objects, learn33-44 cylindric objects). Classes are not tuned to it.
// Floors at what was measured: no object of the box scenes is a can or a cup, and 9 of the 38
// objects of the cylindric scenes are (4 cans, 5 cups; most others are tins of r 90-100 mm, wider
// than a can, or lying; learn38's two mugs stand upside down, their closed bases up, and are cans
// for this view: ClassifyMosdMugs below, docs/ontology.md "Primitive fitting").
TEST(ClassifyMosdSurvey, LabelledObjects) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn0.pcd");
  const ClassLibrary library = shipped_classes();
  std::map<std::string, std::map<std::string, int>> counts;  // scene category -> class -> objects
  for (int n = 0; n < 45; ++n) {
    const auto scene = load_mosd_scene(n);
    ASSERT_TRUE(scene);
    const Cloud& cloud = *scene->cloud;
    const auto& labels = scene->labels;
    const Eigen::Vector3d& up = scene->up;
    std::map<std::uint32_t, std::vector<int>> objects;
    for (std::size_t i = 0; i < labels.size(); ++i)
      if (labels[i] >= 20 && is_valid(cloud.points[i])) objects[labels[i] / 10].push_back(static_cast<int>(i));
    const std::string category = n <= 16 ? "boxes" : n <= 24 ? "stacked boxes" : n <= 32 ? "occluded" : "cylindric";
    std::printf("learn%d:", n);
    for (const auto& [id, indices] : objects) {
      if (indices.size() < 500) continue;
      auto d = describe(cloud, indices, up, library);
      const std::string name = d.ok() ? d->class_name : "error";
      ++counts[category][name];
      std::printf(" %u=%s", id, name.c_str());
      if (d.ok() && d->primitive && name != kUnknownClass) std::printf("(r %.0f)", d->primitive->radius_m * 1000);
      if (d.ok() && std::getenv("SCENEWATCH_SURVEY_VERBOSE") != nullptr) print("\n  object " + std::to_string(id), *d);
    }
    std::printf("\n");
  }
  for (const auto& [category, classes] : counts) {
    std::printf("%s:", category.c_str());
    for (const auto& [name, count] : classes) std::printf(" %s %d", name.c_str(), count);
    std::printf("\n");
  }
  const auto round = [&](const std::string& category) { return counts[category]["can"] + counts[category]["cup"]; };
  EXPECT_EQ(round("boxes"), 0) << "a box taken for a can or a cup";
  EXPECT_GE(round("cylindric"), 9) << "fewer cans and cups among the cylindric scenes' objects than measured";
}

/// One labelled object of an mOSD scene (label / 10 == id): its valid pixels, and the pairs of
/// vertically neighbouring pixels on it whose ranges differ by more than 2 cm (the segmentation's
/// gap between two surfaces). The near rim of an open vessel seen from above hides its inside
/// beyond a jump like this all along the rim; a closed top shows none.
struct MosdObject {
  std::vector<int> indices;
  int range_jumps = 0;
};

MosdObject mosd_object(const Cloud& cloud, const std::vector<std::uint32_t>& labels, std::uint32_t id) {
  MosdObject out;
  const std::size_t width = cloud.width;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] / 10 != id || !is_valid(cloud.points[i])) continue;
    out.indices.push_back(static_cast<int>(i));
    const std::size_t below = i + width;
    if (below >= labels.size() || labels[below] / 10 != id || !is_valid(cloud.points[below])) continue;
    const float jump = cloud.points[i].getVector3fMap().norm() - cloud.points[below].getVector3fMap().norm();
    if (std::abs(jump) > 0.02f) ++out.range_jumps;
  }
  return out;
}

// The same two white mugs, open side up in learn39 (objects 3 and 4) and upside down in learn38
// (objects 2 and 3: the colour image shows their closed bases with the foot ring). Seen from
// 40-53 degrees above, an open mug of r 40 mm shows its far inside wall 2 r tan(elevation), from
// 65 mm down to its bottom, beyond its near rim: a jump of several centimetres along the rim, whose
// 80 mm span 50-65 columns at 0.65-0.8 m (measured: 45 and 51 pixel pairs; at least 20 asserted,
// well under the rim's width). The upside-down mugs' tops fall smoothly in range from the far edge
// to the near one (657 -> 620 mm and 826 -> 774 mm down their centre columns; 0 and 1 jumps, at
// most 3 asserted, stray silhouette pixels): no inside to see. The open-top test must agree.
TEST(ClassifyMosdMugs, OpenSideUpIsACupUpsideDownIsNot) {
  SCENEWATCH_REQUIRE_DATA("mosd/learn/learn38.pcd");
  const ClassLibrary library = shipped_classes();
  struct Mug {
    int scene;
    std::uint32_t id;
    bool open_side_up;
  };
  for (const Mug& mug : {Mug{39, 3, true}, Mug{39, 4, true}, Mug{38, 2, false}, Mug{38, 3, false}}) {
    const std::string name = "learn" + std::to_string(mug.scene) + " object " + std::to_string(mug.id);
    SCOPED_TRACE(name);
    const auto scene = load_mosd_scene(mug.scene);  // up as in the survey
    ASSERT_TRUE(scene);
    const Cloud& cloud = *scene->cloud;
    const MosdObject object = mosd_object(cloud, scene->labels, mug.id);
    ASSERT_GT(object.indices.size(), 3000u);
    auto d = describe(cloud, object.indices, scene->up, library);
    ASSERT_TRUE(d.ok()) << d.error().message;
    print(name + " (" + std::to_string(object.range_jumps) + " range jumps)", *d);
    ASSERT_TRUE(d->primitive);
    if (mug.open_side_up) {
      EXPECT_GE(object.range_jumps, 20) << "the data: an open rim hides the inside beyond it";
      EXPECT_EQ(d->class_name, "cup");
      EXPECT_GE(d->primitive->inner_fraction, kOpenTopMinInnerFraction);
    } else {
      EXPECT_LE(object.range_jumps, 3) << "the data: a closed top has no rim to hide anything";
      EXPECT_NE(d->class_name, "cup");
      // Closed for every vessel shape fitted (the can's cylinder, the cup's and the bowl's frustum).
      for (const ClassMatch& m : d->candidates) {
        const bool vessel = m.fit.shape == ClassShape::kCylinder || m.fit.shape == ClassShape::kFrustum;
        if (m.score > 0 && vessel) EXPECT_LT(m.fit.inner_fraction, kOpenTopMinInnerFraction) << m.class_name;
      }
    }
  }
}

}  // namespace
}  // namespace scenewatch::ontology
