#pragma once
// The real 7-Scenes kitchen of the shared data (redkitchen_long: files 0-498, every second frame;
// sequence index i is file 2 i), for the localization tests.
#include <gtest/gtest.h>

#include "scenewatch/io/sequence.h"
#include "test_data.h"

namespace scenewatch::localization::test_kitchen {

inline io::Sequence kitchen() {
  auto seq = io::open_sequence(scenewatch::test::data_dir() / "redkitchen_long");
  EXPECT_TRUE(seq.ok()) << seq.error().message;
  return *seq;
}

inline Frame load(const io::Sequence& seq, std::size_t i) {
  auto f = io::load_sequence_frame(seq, i);
  EXPECT_TRUE(f.ok()) << f.error().message;
  return *f;
}

/// The halves of the relocalization protocol (issue 29): the model from files 0-248, the frames
/// relocalized or streamed from files 250-498.
constexpr std::size_t kModelFrames = 125;
constexpr std::size_t kHeldOutEnd = 250;

}  // namespace scenewatch::localization::test_kitchen
