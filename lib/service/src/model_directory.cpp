// What saves leave in the model directory: the snapshot folder a save writes before it renames it
// into place (snap-NNNNNN.tmp) and the link it swaps in for `current` (current.tmp). A save killed
// part-way, or one that failed after its folder was made, leaves them; nothing else removes them.
#include "scenewatch/service/model_directory.h"

#include <exception>

#include "scenewatch/pipeline/working_memory.h"

namespace scenewatch::service {
namespace fs = std::filesystem;

namespace {
bool unfinished(const std::string& name) {
  const std::string suffix = ".tmp";
  if (name == "current" + suffix) return true;
  return name.rfind("snap-", 0) == 0 && name.size() > suffix.size() &&
         name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}
}  // namespace

std::vector<std::string> remove_unfinished_snapshots(const fs::path& model_dir) {
  std::vector<std::string> removed;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(model_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (!unfinished(name)) continue;
    std::error_code remove_ec;
    fs::remove_all(entry.path(), remove_ec);  // a link is removed, not followed
    if (!remove_ec) removed.push_back(name);
  }
  return removed;
}

Result<pipeline::LoadedSnapshot> load_newest_good(pipeline::WorkingMemory& memory, const fs::path& model_dir) {
  try {
    return memory.load_newest_good(model_dir);
  } catch (const std::exception& e) {
    return invalid_argument("'" + model_dir.string() + "': the model's loader failed on it: " + e.what());
  }
}

Status save_model(const pipeline::WorkingMemory& memory, const fs::path& model_dir, std::size_t keep_snapshots) {
  Status saved = memory.save(model_dir, keep_snapshots);
  if (!saved) remove_unfinished_snapshots(model_dir);
  return saved;
}

}  // namespace scenewatch::service
