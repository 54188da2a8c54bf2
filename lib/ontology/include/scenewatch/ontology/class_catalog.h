#pragma once
/// The daemon's classes: those of the classes file (config/ontology.yaml), overlaid by the classes
/// defined through the API, which the store (ontology.sqlite in the model directory) keeps across
/// restarts; and what was learnt from the objects seen: their instances and, from handled objects,
/// the classes' learnt motions. Thread safe (one mutex for the classes and what was learnt, one for
/// the store; a defined class is written before it becomes visible, instances and learnt motions are
/// visible at once and written by a background writer).
#include <condition_variable>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "scenewatch/core/dof.h"
#include "scenewatch/core/result.h"
#include "scenewatch/ontology/class_library.h"
#include "scenewatch/ontology/class_store.h"

namespace scenewatch::ontology {

/// The store's file name in a model directory.
inline constexpr const char* kClassStoreFile = "ontology.sqlite";

/// What handled instances of a class taught about its motions (the foreground's learnt DoFs,
/// issue 12): a DoF is free when any handled instance was seen moving along it, frozen when
/// handled instances were seen and none moved along it.
struct LearntMotions {
  DofFlags free{};
  /// The DoF names (x y z roll pitch yaw order) that are free, or with `free_ones` false, frozen.
  std::vector<std::string> names(bool free_ones) const;
};

class ClassCatalog {
 public:
  /// Reads `classes_file` (empty: no file classes) and opens `store_path` (empty: nothing is
  /// persisted), whose classes replace the file's of the same name and whose learnt constraints
  /// are the classes' learnt motions.
  static Result<std::unique_ptr<ClassCatalog>> open(const std::filesystem::path& classes_file,
                                                    const std::filesystem::path& store_path);
  /// Writes what is still queued (see flush()) and stops the writer.
  ~ClassCatalog();
  ClassCatalog(const ClassCatalog&) = delete;
  ClassCatalog& operator=(const ClassCatalog&) = delete;

  /// Adds or replaces a class: validated, stored (when there is a store), then visible.
  Status define(const ObjectClass& object_class, double time_s);
  /// A copy of the current classes.
  ClassLibrary library() const;
  /// True when a store backs the catalog.
  bool persistent() const;

  /// Records one object seen and classified. When it was handled (`handled_free`: the free DoFs
  /// the foreground learnt for it) and its class is not unknown, its free DoFs join the class's
  /// learnt motions. Cheap: nothing waits for the disk; the instance and any learnt motion that
  /// changed are queued for the background writer, which stores each batch in one transaction.
  void record(const InstanceRecord& instance, const std::optional<DofFlags>& handled_free = std::nullopt);
  /// The learnt motions by class name (classes with no handled instance are absent).
  std::map<std::string, LearntMotions> learnt() const;
  /// Waits until everything recorded before the call is in the store; the first write error since
  /// the last flush, if any (a failed batch is dropped, not retried). Without a store: OK at once.
  Status flush();

 private:
  ClassCatalog() = default;
  void write_loop();

  mutable std::mutex mutex_;  // library_, learnt_, the queue and the writer's state
  ClassLibrary library_;
  std::map<std::string, LearntMotions> learnt_;
  std::vector<InstanceRecord> queued_instances_;
  std::vector<ConstraintRecord> queued_constraints_;
  std::uint64_t queued_batches_ = 0;   // batches handed to the writer so far (one per record())
  std::uint64_t written_batches_ = 0;  // of those, how many the writer has finished
  bool stopping_ = false;
  std::optional<Error> write_error_;
  std::condition_variable wake_writer_, written_;

  std::mutex store_mutex_;  // the store (not thread safe); taken after mutex_, never before it
  std::optional<ClassStore> store_;
  std::thread writer_;
};

}  // namespace scenewatch::ontology
