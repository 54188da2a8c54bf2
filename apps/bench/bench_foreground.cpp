// The foreground's cost per VGA frame (issue 12's target: hand detection + tracking one object
// <= 10 ms on one core): hrt1 pick_toy_1 through WorkingMemory::process as the daemon runs it,
// with the time of the hand detection and of the foreground (registration, promotion, handlings)
// taken from each frame's result. "Tracking one object" are the frames that start with exactly one
// foreground object (after the toy's promotion).
#include <cstdio>
#include <map>

#include "bench.h"
#include "scenewatch/io/sequence.h"
#include "scenewatch/pipeline/working_memory.h"

namespace scenewatch::bench {
namespace {

std::size_t foreground_objects(const pipeline::WorkingMemory& memory) {
  std::size_t n = 0;
  for (const auto& o : memory.snapshot()->objects) n += o.foreground ? 1 : 0;
  return n;
}

void print_row(const char* name, const std::vector<double>& v) {
  std::printf("   %-46s %6zu %10.2f %10.2f\n", name, v.size(), median(v), quantile(v, 0.9));
}

}  // namespace

int run_foreground(const Options& o) {
  std::printf("\n== The foreground per VGA frame: hrt1 pick_toy_1 through WorkingMemory::process (issue 12: hands + one tracked object <= 10 ms)\n");
  auto seq = io::open_sequence(o.data_dir / "hrt1/pick_toy_1");
  if (!seq) {
    std::printf("  (hrt1/pick_toy_1 could not be opened; skipped)\n");
    return 0;
  }
  std::vector<Frame> frames;
  for (std::size_t i = 0; i < seq->frames.size(); ++i) {
    auto f = io::load_sequence_frame(*seq, i);
    if (!f) {
      std::printf("  (frame %zu could not be loaded; skipped)\n", i);
      return 0;
    }
    frames.push_back(std::move(*f));
  }
  std::vector<double> hands, tracking, both;
  std::size_t tracked_frames = 0;
  const int runs = std::min(o.repetitions, 3);  // each run is the whole pipeline over 40 frames
  for (int run = 0; run < runs; ++run) {
    pipeline::WorkingMemory memory{pipeline::Config{}};
    for (const auto& f : frames) {
      const bool one_object = foreground_objects(memory) == 1;
      auto r = memory.process(f);
      if (!r) {
        std::printf("  %s\n", r.error().message.c_str());
        return 1;
      }
      if (r->hands > 0) hands.push_back(r->hands_ms);
      if (!one_object) continue;
      ++tracked_frames;
      tracking.push_back(r->foreground_ms);
      both.push_back(r->hands_ms + r->foreground_ms);
    }
  }
  std::printf("   %-46s %6s %10s %10s\n", "stage", "frames", "median ms", "p90 ms");
  print_row("hand detection (frames with a hand)", hands);
  print_row("foreground, one object tracked", tracking);
  print_row("hands + foreground, one object tracked", both);
  std::printf("   (%d runs; %zu frames with one foreground object)\n", runs, tracked_frames);
  return 0;
}

}  // namespace scenewatch::bench
