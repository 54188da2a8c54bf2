// The hand detector against the simulator's exact labels and against two real recordings (hrt1)
// labelled by eye.
#include "scenewatch/foreground/hand_detector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "scenewatch/io/image_io.h"
#include "scenewatch/io/rgbd.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"
#include "test_data.h"

namespace scenewatch::foreground {
namespace {

/// When SCENEWATCH_HAND_DUMP names a folder, the tests write each frame with its labels painted
/// over it there (hand red, arm yellow, person blue): for looking, not for checking.
void dump(const Cloud& cloud, const HandDetection& d, const std::string& name) {
  const char* dir = std::getenv("SCENEWATCH_HAND_DUMP");
  if (dir == nullptr || d.labels.empty()) return;
  ColorImage image;
  image.width = d.width;
  image.height = d.height;
  image.rgb.resize(3 * cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::uint8_t rgb[3] = {cloud.points[i].r, cloud.points[i].g, cloud.points[i].b};
    const std::uint8_t paint[4][3] = {{0, 0, 0}, {255, 0, 0}, {255, 255, 0}, {0, 80, 255}};
    const int label = static_cast<int>(d.labels[i]);
    for (int c = 0; c < 3; ++c) {
      image.rgb[3 * i + c] = label == 0 ? rgb[c] : static_cast<std::uint8_t>((rgb[c] + 2 * paint[label][c]) / 3);
    }
  }
  (void)io::write_color_png(std::filesystem::path(dir) / (name + ".png"), image);
}

std::string describe(const HandDetection& d) {
  std::string s;
  char text[160];
  for (const Hand& h : d.hands) {
    std::snprintf(text, sizeof text, " [hand %.2f %s %d,%d %dx%d, %zu px, tip %zu px, %.3f m2, elong %.1f, %.2f m]", h.score,
                  h.enters_from_border ? "border" : "free", h.region.x, h.region.y, h.region.width, h.region.height,
                  h.indices.size(), h.tip_indices.size(), h.area_m2, h.elongation, h.length_m);
    s += text;
  }
  std::snprintf(text, sizeof text, " person %zu px, %.2f ms", d.person_indices.size(), d.ms);
  return s + text;
}

TEST(HandDetector, Hrt1Dump) {
  SCENEWATCH_REQUIRE_DATA("hrt1/pick_toy_1");
  for (const char* name : {"pick_toy_1", "pick_toy_2"}) {
    auto seq = io::open_sequence(test::data_dir() / "hrt1" / name);
    ASSERT_TRUE(seq.ok());
    for (std::size_t f = 0; f < seq->frames.size(); ++f) {
      auto frame = io::load_sequence_frame(*seq, f);
      ASSERT_TRUE(frame.ok());
      const HandDetection d = detect_hands(*frame->cloud, HandConfig{});
      std::printf("%s %02zu:%s\n", name, f, describe(d).c_str());
      dump(*frame->cloud, d, std::string(name) + "_" + std::to_string(f));
    }
  }
}

}  // namespace
}  // namespace scenewatch::foreground
