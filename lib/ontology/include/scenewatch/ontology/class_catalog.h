#pragma once
/// The daemon's classes: those of the classes file (config/ontology.yaml), overlaid by the classes
/// defined through the API, which the store (ontology.sqlite in the model directory) keeps across
/// restarts. Thread safe (one mutex; the store is written before the classes in memory change).
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "scenewatch/core/result.h"
#include "scenewatch/ontology/class_library.h"
#include "scenewatch/ontology/class_store.h"

namespace scenewatch::ontology {

/// The store's file name in a model directory.
inline constexpr const char* kClassStoreFile = "ontology.sqlite";

class ClassCatalog {
 public:
  /// Reads `classes_file` (empty: no file classes) and opens `store_path` (empty: nothing is
  /// persisted), whose classes replace the file's of the same name.
  static Result<std::unique_ptr<ClassCatalog>> open(const std::filesystem::path& classes_file,
                                                    const std::filesystem::path& store_path);

  /// Adds or replaces a class: validated, stored (when there is a store), then visible.
  Status define(const ObjectClass& object_class, double time_s);
  /// A copy of the current classes.
  ClassLibrary library() const;
  /// True when a store backs the catalog.
  bool persistent() const;

 private:
  ClassCatalog() = default;
  mutable std::mutex mutex_;
  ClassLibrary library_;
  std::optional<ClassStore> store_;
};

}  // namespace scenewatch::ontology
