// The bag readers (issue 32): arbitrary bytes as a ROS 1 .bag (fuzz_ros1_bag) or an MCAP file
// (fuzz_mcap), as `scenewatch replay|ingest|fit BAG` meet them. io::open_bag chooses topics, pairs
// images and looks up poses; io::load_bag_frame decodes a frame. SCENEWATCH_FUZZ_MCAP picks the
// format.
#include <algorithm>
#include <cstdint>
#include <cstdlib>

#include "fuzz_files.h"
#include "scenewatch/io/bag.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace scenewatch;
#ifdef SCENEWATCH_FUZZ_MCAP
  const auto path = fuzz::write_scratch("input.mcap", data, size);
#else
  const auto path = fuzz::write_scratch("input.bag", data, size);
#endif
  auto recording = io::open_bag(path);
  if (!recording.ok()) {
    if (recording.error().message.empty()) std::abort();  // every refusal says why
    return 0;
  }
  (void)io::skipped_summary(*recording);
  for (std::size_t i = 0; i < std::min<std::size_t>(recording->frames.size(), 4); ++i) {
    auto frame = io::load_bag_frame(*recording, i);
    if (!frame.ok()) {
      if (frame.error().message.empty()) std::abort();
      continue;
    }
    // What it accepts is consistent: as many points as width x height.
    const Cloud& c = *frame->cloud;
    if (c.points.size() != static_cast<std::size_t>(c.width) * c.height) std::abort();
  }
  return 0;
}
