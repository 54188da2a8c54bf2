// Classes in YAML: the shipped file, strict parsing with errors naming the field, round trip.
#include <gtest/gtest.h>

#include "scenewatch/ontology/class_library.h"
#include "test_data.h"

namespace scenewatch::ontology {
namespace {

const char* kCup = R"(classes:
  - name: cup
    shape: frustum
    radius_m: [0.025, 0.07]
    height_m: [0.04, 0.18]
    taper_deg: [-5, 15]
    top: open
    grasps:
      - {name: side_mid, kind: side, height_fraction: 0.5}
      - {name: rim, kind: rim}
    allowed_dofs: [x, y, z, yaw]
)";

std::string error_of(const std::string& yaml) {
  auto parsed = parse_classes(yaml, "test.yaml");
  return parsed.ok() ? std::string("(no error)") : parsed.error().message;
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST(ClassLibraryTest, ShippedFileLoads) {
  auto library = load_classes_file(test::source_dir() / "config/ontology.yaml");
  ASSERT_TRUE(library.ok()) << library.error().message;
  for (const char* name : {"can", "cup", "bowl", "ball", "box"}) EXPECT_NE(library->find(name), nullptr) << name;
  const ObjectClass* cup = library->find("cup");
  ASSERT_NE(cup, nullptr);
  EXPECT_EQ(cup->shape, ClassShape::kFrustum);
  EXPECT_EQ(cup->top, ClassTop::kOpen);
  // Generic bounds: a cup 30 % wider than the simulator's 40 mm one fits.
  EXPECT_TRUE(cup->radius_m.contains(0.052));
}

TEST(ClassLibraryTest, ParsesAndRoundTrips) {
  auto library = parse_classes(kCup, "test.yaml");
  ASSERT_TRUE(library.ok()) << library.error().message;
  ASSERT_EQ(library->classes().size(), 1u);
  const ObjectClass& cup = library->classes()[0];
  EXPECT_EQ(cup.grasps.size(), 2u);
  EXPECT_EQ(cup.grasps[1].kind, GraspKind::kRim);
  EXPECT_EQ(cup.allowed_dofs, (std::vector<std::string>{"x", "y", "z", "yaw"}));
  EXPECT_DOUBLE_EQ(cup.max_rms_m, 0.004);  // the default
  auto again = parse_classes(to_yaml(library->classes()), "emitted");
  ASSERT_TRUE(again.ok()) << again.error().message << "\n" << to_yaml(library->classes());
  EXPECT_EQ(to_yaml(again->classes()), to_yaml(library->classes()));
}

TEST(ClassLibraryTest, ErrorsNameTheField) {
  EXPECT_NE(error_of(replaced(kCup, "top: open", "lid: open")).find("classes[0] (cup).lid: unknown key"), std::string::npos)
      << error_of(replaced(kCup, "top: open", "lid: open"));
  EXPECT_NE(error_of(replaced(kCup, "[0.025, 0.07]", "[0.07, 0.025]")).find("radius_m min must be <= max"), std::string::npos)
      << error_of(replaced(kCup, "[0.025, 0.07]", "[0.07, 0.025]"));
  EXPECT_NE(error_of(replaced(kCup, "[0.025, 0.07]", "[small, 0.07]")).find("radius_m: expected two numbers"), std::string::npos);
  EXPECT_NE(error_of(replaced(kCup, "shape: frustum", "shape: torus")).find("shape: 'torus' is not one of"), std::string::npos);
  EXPECT_NE(error_of(replaced(kCup, "[x, y, z, yaw]", "[x, spin]")).find("allowed_dofs[1]"), std::string::npos);
  EXPECT_NE(error_of(replaced(kCup, "kind: rim", "kind: handle")).find("grasps[1].kind"), std::string::npos);
  EXPECT_NE(error_of(replaced(kCup, "    taper_deg: [-5, 15]\n", "")).find("taper_deg: required"), std::string::npos);
  EXPECT_NE(error_of(std::string(kCup) + "  - {name: cup, shape: sphere, radius_m: [0.02, 0.1]}\n").find("used twice"), std::string::npos);
  EXPECT_NE(error_of(replaced(kCup, "name: cup", "name: Cup")).find("a-z"), std::string::npos);
  EXPECT_NE(error_of("classes: [").find("not valid YAML"), std::string::npos);
  EXPECT_NE(error_of("classes:\n  - {name: a, shape: sphere, radius_m: [0.02, 0.1], [1, 2]: 3}\n").find("not a plain name"), std::string::npos);
  EXPECT_NE(error_of("classes:\n  - {name: [a], shape: sphere}\n").find("name: expected a string"), std::string::npos);
  EXPECT_NE(error_of("- 1\n").find("expected a map"), std::string::npos);
  EXPECT_NE(error_of("things: []").find("things: unknown key"), std::string::npos) << error_of("things: []");
  auto missing = load_classes_file("/nonexistent/ontology.yaml");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("/nonexistent/ontology.yaml"), std::string::npos);
}

TEST(ClassLibraryTest, DefineReplacesByName) {
  ClassLibrary library;
  ObjectClass ball;
  ball.name = "ball";
  ball.shape = ClassShape::kSphere;
  ball.radius_m = {0.02, 0.1};
  ASSERT_TRUE(library.define(ball).ok());
  ball.radius_m = {0.03, 0.2};
  ASSERT_TRUE(library.define(ball).ok());
  ASSERT_EQ(library.classes().size(), 1u);
  EXPECT_DOUBLE_EQ(library.find("ball")->radius_m.max, 0.2);
  ball.name = "unknown";
  EXPECT_FALSE(library.define(ball).ok());
}

}  // namespace
}  // namespace scenewatch::ontology
