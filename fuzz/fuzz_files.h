#pragma once
// Scratch files for the fuzz targets whose readers take a path: one private folder per process
// (in /dev/shm when there is one, so each run costs no disk write), removed at exit.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace scenewatch::fuzz {

/// The process's scratch folder, made on first use: in $SCENEWATCH_FUZZ_SCRATCH when set
/// (scripts/fuzz sets it and removes it after each target: libFuzzer ends with _Exit when its
/// time is up, so the atexit clean-up does not always run), else in /dev/shm or /tmp.
inline const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    const char* parent = std::getenv("SCENEWATCH_FUZZ_SCRATCH");
    std::string pattern = (parent != nullptr && *parent != '\0'   ? std::string(parent)
                           : std::filesystem::is_directory("/dev/shm") ? std::string("/dev/shm")
                                                                    : std::string("/tmp")) +
                          "/scenewatch-fuzz-XXXXXX";
    if (::mkdtemp(pattern.data()) == nullptr) std::abort();
    static const std::filesystem::path made(pattern);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(made, ec);
    });
    return made;
  }();
  return dir;
}

/// Writes `size` bytes to `name` in the scratch folder (replacing it) and returns its path.
inline std::filesystem::path write_scratch(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = scratch_dir() / name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

/// Splits the input at each occurrence of `separator` (at most `max_parts` parts; the last part
/// keeps the rest). Lets one input describe several files.
inline std::vector<std::string> split_input(const std::uint8_t* data, std::size_t size, const std::string& separator,
                                            std::size_t max_parts) {
  std::vector<std::string> parts;
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::size_t from = 0;
  while (parts.size() + 1 < max_parts) {
    const std::size_t at = text.find(separator, from);
    if (at == std::string::npos) break;
    parts.push_back(text.substr(from, at - from));
    from = at + separator.size();
  }
  parts.push_back(text.substr(from));
  return parts;
}

}  // namespace scenewatch::fuzz
