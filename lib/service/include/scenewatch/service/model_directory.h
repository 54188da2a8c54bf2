#pragma once
/// The daemon's model directory (server.model_dir): one daemon at a time holds it, with an
/// exclusive flock on a lock file in it (two daemons on one directory flip `current` between
/// their models and prune each other's snapshots), and what a killed or failed save left behind
/// is removed by the holder.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "scenewatch/core/result.h"
#include "scenewatch/pipeline/working_memory.h"

namespace scenewatch::service {

/// The lock file in the model directory; it holds the PID of the daemon that has the lock.
inline constexpr const char* kModelLockFile = "scenewatchd.lock";

/// An exclusive lock on a model directory, held for the object's life. The kernel releases it
/// when the process ends, however it ends (kill -9 included), so no stale lock is ever left.
/// Movable, not copyable; not thread safe.
class ModelDirLock {
 public:
  /// Creates the directory when missing, then locks it (flock(LOCK_EX | LOCK_NB) on
  /// kModelLockFile) and writes this process's PID into the lock file. When another process holds
  /// the lock: kUnavailable, naming the directory and that process's PID.
  static Result<ModelDirLock> acquire(const std::filesystem::path& model_dir);

  ModelDirLock(ModelDirLock&& other) noexcept;
  ModelDirLock& operator=(ModelDirLock&& other) noexcept;
  ModelDirLock(const ModelDirLock&) = delete;
  ModelDirLock& operator=(const ModelDirLock&) = delete;
  ~ModelDirLock();

 private:
  explicit ModelDirLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

/// Removes what unfinished saves left in a model directory (snap-NNNNNN.tmp folders, a
/// current.tmp link); returns their names. Only for the holder of the directory's lock: another
/// daemon's save in progress looks the same.
std::vector<std::string> remove_unfinished_snapshots(const std::filesystem::path& model_dir);

/// WorkingMemory::load_newest_good, for the start-up. The loader reports a damaged snapshot as an
/// error and goes on to an older one; where it throws instead (a scene.json whose "background"
/// record is not an object, found by fuzz_model_loader: nlohmann's value() throws on an array),
/// the start-up ends with that error as for a model that does not load, rather than the daemon
/// terminating. The memory is unchanged then (the loader builds everything aside first).
Result<pipeline::LoadedSnapshot> load_newest_good(pipeline::WorkingMemory& memory,
                                                  const std::filesystem::path& model_dir);

/// WorkingMemory::save, and when it fails, remove_unfinished_snapshots(): a failed save leaves
/// the model directory as it was.
Status save_model(const pipeline::WorkingMemory& memory, const std::filesystem::path& model_dir,
                  std::size_t keep_snapshots);

}  // namespace scenewatch::service
