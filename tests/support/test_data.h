#pragma once
/// Locations of test data, compiled in (SCENEWATCH_DATA_DIR points at ../shared/data).
#include <gtest/gtest.h>

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <system_error>
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

/// A fresh temporary directory removed when the object goes out of scope, even when an assertion
/// ends the test early.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) : path_(make_temp_dir(tag)) {}
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::filesystem::path& p) const { return path_ / p; }
  operator const std::filesystem::path&() const { return path_; }  // NOLINT: used as a path

 private:
  std::filesystem::path path_;
};

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
