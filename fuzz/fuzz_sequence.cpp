// A PNG sequence folder as `scenewatch ingest` and `replay` read it: the input is split at
// "\n--8<--\n" into camera-intrinsics.txt, frame-000000.pose.txt, frame-000000.color.png and
// frame-000000.depth.png (missing parts: files left out). The PNG readers also get each image part
// on its own.
#include <cstdint>
#include <cstdlib>
#include <filesystem>

#include "fuzz_files.h"
#include "scenewatch/io/image_io.h"
#include "scenewatch/io/sequence.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace scenewatch;
  namespace fs = std::filesystem;
  static const char* const kNames[] = {"camera-intrinsics.txt", "frame-000000.pose.txt", "frame-000000.color.png",
                                       "frame-000000.depth.png"};
  const auto parts = fuzz::split_input(data, size, "\n--8<--\n", 4);
  const fs::path dir = fuzz::scratch_dir() / "sequence";
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(parts[i].data());
    fuzz::write_scratch(fs::path("sequence") / kNames[i], bytes, parts[i].size());
  }
  for (std::size_t i = 2; i < parts.size(); ++i) {
    const fs::path image = dir / kNames[i];
    (void)io::read_png_size(image);
    if (auto color = io::read_color_png(image); color.ok()) {
      if (color->rgb.size() != static_cast<std::size_t>(color->width) * color->height * 3) std::abort();
    }
    (void)io::read_depth_png(image);
    (void)io::read_label_png(image);
  }
  if (auto sequence = io::open_sequence(dir); sequence.ok()) {
    for (std::size_t i = 0; i < sequence->frames.size(); ++i) {
      if (auto frame = io::load_sequence_frame(*sequence, i); frame.ok()) {
        const auto& cloud = *frame->cloud;
        if (cloud.points.size() != static_cast<std::size_t>(cloud.width) * cloud.height) std::abort();
      }
    }
  }
  return 0;
}
