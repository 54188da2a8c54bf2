#pragma once
/// The set of object classes, and their YAML form (config/ontology.yaml, `scenewatch define-class`).
#include <filesystem>
#include <string>
#include <vector>

#include "scenewatch/core/result.h"
#include "scenewatch/ontology/object_class.h"

namespace scenewatch::ontology {

/// Classes by name, in the order they were added. NOT thread safe (a value type: copy it).
class ClassLibrary {
 public:
  /// Adds `object_class` or replaces the class of the same name; an invalid class is refused.
  Status define(const ObjectClass& object_class);
  /// The class named `name`, or nullptr.
  const ObjectClass* find(const std::string& name) const;
  const std::vector<ObjectClass>& classes() const { return classes_; }
  bool empty() const { return classes_.empty(); }

 private:
  std::vector<ObjectClass> classes_;
};

/// Parses a classes document: a map with one key `classes`, a list of class maps (see
/// config/ontology.yaml for every field). Unknown keys, wrong types, bad ranges and duplicate
/// names are errors naming `source` and the field ("ontology.yaml: classes[2] (cup).radius_m.min:
/// expected a number").
Result<ClassLibrary> parse_classes(const std::string& yaml_text, const std::string& source = "classes");

/// Reads and parses a classes file; the message names the file.
Result<ClassLibrary> load_classes_file(const std::filesystem::path& path);

/// The YAML of one class (a map, as one element of `classes`); parse_classes reads it back equal.
std::string to_yaml(const ObjectClass& object_class);

/// The YAML of a list of classes: `classes: [...]`.
std::string to_yaml(const std::vector<ObjectClass>& classes);

}  // namespace scenewatch::ontology
