#pragma once
/// Locations of test data, compiled in (SCENEWATCH_DATA_DIR points at ../shared/data).
#include <gtest/gtest.h>

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace scenewatch::test {

/// The shared real-data folder.
inline std::filesystem::path data_dir() { return SCENEWATCH_DATA_DIR; }
inline std::filesystem::path source_dir() { return SCENEWATCH_SOURCE_DIR; }
inline std::filesystem::path binary_dir() { return SCENEWATCH_BINARY_DIR; }

/// A fresh, empty temporary directory for one test (mkdtemp under $TMPDIR).
inline std::filesystem::path make_temp_dir(const std::string& tag) {
  std::string pattern = (std::filesystem::temp_directory_path() / ("scenewatch-" + tag + "-XXXXXX")).string();
  if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed for " + pattern);
  return pattern;
}

}  // namespace scenewatch::test

/// Skips the test with a clear message when the shared data folder (or a file in it) is absent,
/// as in a user's fresh clone. In CI it is present and the test runs.
#define SCENEWATCH_REQUIRE_DATA(relative)                                                     \
  do {                                                                                        \
    if (!std::filesystem::exists(::scenewatch::test::data_dir() / (relative))) {              \
      GTEST_SKIP() << "real data not found: " << (::scenewatch::test::data_dir() / (relative)) \
                   << " (clone with ../shared beside the repository to run this test)";       \
    }                                                                                         \
  } while (0)
