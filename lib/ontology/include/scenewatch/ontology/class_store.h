#pragma once
/// ontology.sqlite, the ontology's persistent store in the model directory: the classes defined
/// through the API, the instances seen (class, fitted parameters, time) and the learnt motion
/// constraints. Every write is one SQLite transaction in WAL mode with synchronous=FULL: a process
/// killed mid-write (kill -9) leaves the file as it was before or after that write. The file has a
/// `schema_version` table; opening an older version upgrades it step by step (version N to N+1, each
/// in a transaction); a damaged file, a foreign SQLite database or a newer version is an error that
/// names the file.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "scenewatch/core/result.h"
#include "scenewatch/ontology/object_class.h"

namespace scenewatch::ontology {

/// One object seen and classified.
struct InstanceRecord {
  std::int64_t id = 0;
  std::string class_name;
  std::string parameters_json;  ///< the fitted primitive's parameters, as the caller encoded them
  double time_s = 0;            ///< when it was seen (the caller's clock, e.g. the frame's stamp)
};

/// A learnt constraint on a class's motion: whether `dof` (x, y, z, roll, pitch, yaw) was seen to move.
struct ConstraintRecord {
  std::string class_name;
  std::string dof;
  bool allowed = true;
  double time_s = 0;
};

/// The store. NOT thread safe: one owner at a time (ClassCatalog serialises access). Move-only.
class ClassStore {
 public:
  /// The schema this build writes. Version 1: classes (name, yaml), instances. Version 2: adds
  /// the constraints table and the classes' defined_s column.
  static constexpr int kSchemaVersion = 2;

  /// Opens `path`, creating it (and nothing else: its folder must exist) when missing, and
  /// migrates an older schema to kSchemaVersion.
  static Result<ClassStore> open(const std::filesystem::path& path);

  ClassStore(ClassStore&&) noexcept;
  ClassStore& operator=(ClassStore&&) noexcept;
  ~ClassStore();

  /// Inserts or replaces the class of the same name (validated first).
  Status put_class(const ObjectClass& object_class, double time_s);
  /// The stored classes, by name.
  Result<std::vector<ObjectClass>> classes() const;
  /// Records one instance.
  Status add_instance(const InstanceRecord& instance);
  /// Several instances in one transaction (all or none are stored).
  Status add_instances(const std::vector<InstanceRecord>& instances);
  /// The instances of `class_name` (empty: all), oldest first.
  Result<std::vector<InstanceRecord>> instances(const std::string& class_name = {}) const;
  /// Inserts or replaces the constraint of (class_name, dof).
  Status put_constraint(const ConstraintRecord& constraint);
  Result<std::vector<ConstraintRecord>> constraints() const;

  /// The version the file had when opened (before any migration).
  int opened_version() const;
  const std::filesystem::path& path() const;

 private:
  struct Impl;
  explicit ClassStore(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace scenewatch::ontology
