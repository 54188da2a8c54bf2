#include "scenewatch/core/files.h"

#include <fstream>
#include <system_error>

namespace scenewatch {
namespace fs = std::filesystem;

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

Status check_readable_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return not_found(quoted(path) + ": no such file");
  if (!fs::is_regular_file(path, ec)) return invalid_argument(quoted(path) + ": not a regular file");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) return io_error(quoted(path) + ": cannot open for reading");
  return {};
}

}  // namespace scenewatch
