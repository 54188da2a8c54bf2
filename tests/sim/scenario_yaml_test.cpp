// Scenario files: every shipped scenario parses; bad ones fail with the key's name.
#include <gtest/gtest.h>

#include <filesystem>

#include "scenewatch/sim/scenario_yaml.h"
#include "test_data.h"

namespace scenewatch::sim {
namespace {

namespace fs = std::filesystem;

const char* kMinimal = R"(
name: minimal
objects:
  - {id: 1, shape: cylinder, radius_m: 0.04, height_m: 0.1, position: [0, 0]}
frames: 2
camera: {type: static, position: [-0.8, 0, 1.4], target: [0, 0, 0.75]}
)";

std::string error_of(const std::string& yaml) {
  auto sc = parse_scenario(yaml, "test.yaml");
  EXPECT_FALSE(sc.ok()) << "expected an error for:\n" << yaml;
  return sc ? std::string() : sc.error().message;
}

TEST(ScenarioYaml, ShippedScenariosParse) {
  const fs::path dir = test::source_dir() / "sample_clouds" / "scenarios";
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".yaml") continue;
    auto sc = load_scenario(e.path());
    ASSERT_TRUE(sc.ok()) << sc.error().message;
    EXPECT_EQ(sc->name, e.path().stem().string());
    EXPECT_FALSE(sc->description.empty()) << e.path();
    names.insert(sc->name);
  }
  for (const char* required : {"glasses_removed", "cup_added", "object_moved", "hand_picks_cup_upright",
                               "hand_tilts_cup", "clutter"}) {
    EXPECT_TRUE(names.count(required)) << required;
  }
  auto demo = load_scenario(test::source_dir() / "sample_clouds" / "tabletop.yaml");
  ASSERT_TRUE(demo.ok()) << demo.error().message;
}

TEST(ScenarioYaml, ReadsPlacementAndDefaults) {
  auto sc = parse_scenario(kMinimal);
  ASSERT_TRUE(sc.ok()) << sc.error().message;
  ASSERT_EQ(sc->objects.size(), 1u);
  // Two coordinates: the object stands on the table top.
  EXPECT_NEAR(sc->objects[0].T_world_object.translation().z(), sc->table.height_m, 1e-12);
  EXPECT_EQ(sc->objects[0].label(), 10);
  ASSERT_EQ(sc->phases.size(), 1u);
  EXPECT_EQ(sc->phases[0].name, "main");
  EXPECT_EQ(sc->phases[0].frames, 2);
  EXPECT_EQ(sc->intrinsics.width, 640);
  EXPECT_EQ(sc->intrinsics.height, 480);
}

TEST(ScenarioYaml, ErrorsNameTheKey) {
  const std::string base = kMinimal;
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = base;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  EXPECT_NE(error_of(base + "colour: [1, 2, 3]\n").find("colour: unknown key"), std::string::npos);
  EXPECT_NE(error_of(with("radius_m: 0.04", "radius_m: big")).find("objects[0].radius_m: expected a number"),
            std::string::npos);
  EXPECT_NE(error_of(with("radius_m: 0.04", "size_m: [1, 1, 1]")).find("objects[0].size_m: not a key of a cylinder"),
            std::string::npos);
  EXPECT_NE(error_of(with("shape: cylinder", "shape: torus")).find("objects[0].shape: unknown shape 'torus'"),
            std::string::npos);
  EXPECT_NE(error_of(with("type: static", "type: drone")).find("camera.type: unknown camera type"), std::string::npos);
  EXPECT_NE(error_of(with("id: 1", "id: 0")).find("objects[0].id"), std::string::npos);
  EXPECT_NE(error_of(with("position: [0, 0]", "position: [0]")).find("objects[0].position"), std::string::npos);
  EXPECT_NE(error_of(with("frames: 2", "frames: two")).find("frames: expected a number"), std::string::npos);
  EXPECT_NE(error_of(base + "sensor: {transparent_depth: maybe}\n").find("sensor.transparent_depth"), std::string::npos);
  EXPECT_NE(error_of(base + "hand: {keys: [{frame: 0, position: [0, 0, 1], grasp: 7}]}\n").find("grasp: no object with id 7"),
            std::string::npos);
  EXPECT_NE(error_of("objects: [").find("not valid YAML"), std::string::npos);
  EXPECT_NE(error_of(base + "phases: []\n").find("phases"), std::string::npos);
  // The file name is in the message.
  EXPECT_EQ(error_of(base + "bogus: 1\n").rfind("test.yaml: ", 0), 0u);
}

TEST(ScenarioYaml, ChangesOnlyAfterTheFirstPhase) {
  const std::string two_phases = R"(
objects:
  - {id: 1, shape: sphere, radius_m: 0.04, position: [0, 0]}
phases:
  - {name: before, frames: 1, camera: {type: static, position: [-0.8, 0, 1.4]}}
  - name: after
    frames: 1
    camera: {type: static, position: [-0.8, 0, 1.4]}
    changes: {remove: [1], add: [{id: 2, shape: box, size_m: [0.1, 0.1, 0.1], position: [0.1, 0.1]}]}
)";
  auto sc = parse_scenario(two_phases);
  ASSERT_TRUE(sc.ok()) << sc.error().message;
  EXPECT_EQ(sc->phases[1].changes.remove, std::vector<int>{1});
  ASSERT_EQ(sc->phases[1].changes.add.size(), 1u);

  std::string bad = two_phases;
  bad.replace(bad.find("remove: [1]"), 11, "remove: [5]");
  EXPECT_NE(error_of(bad).find("changes.remove: no object with id 5"), std::string::npos);
}

}  // namespace
}  // namespace scenewatch::sim
