#pragma once
/// YAML configuration with strict validation: unknown keys and out-of-range values are errors
/// whose message names the key ("segmentation.voxel_size_m: must be > 0, got -1").
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "scenewatch/core/result.h"
#include "scenewatch/core/yaml_value.h"
#include "scenewatch/pipeline/config.h"

namespace scenewatch::pipeline {

/// Reads the keys of one YAML mapping, remembering which were used so that finish() can reject
/// the rest. Not thread safe; use on one section at a time.
class YamlSection {
 public:
  /// `name` is the section's dotted path for messages ("server", "background").
  YamlSection(const YAML::Node& node, std::string name);

  /// Reads `key` into `out` when present; leaves `out` alone when absent.
  template <typename T>
  Status read(const std::string& key, T& out) {
    if (!node_.IsDefined() || node_.IsNull()) return {};
    seen_.insert(key);
    const YAML::Node value = node_[key];
    if (!value.IsDefined() || value.IsNull()) return {};
    auto read = yaml::read_value<T>(value, path(key));
    if (!read) return read.error();
    out = std::move(*read);
    return {};
  }

  /// Dotted path of a key in this section, for messages.
  std::string path(const std::string& key) const { return name_ + "." + key; }
  /// The section must be a mapping (or absent).
  Status check_is_map() const;
  /// Error naming the first key of the section that was never read.
  Status finish() const;

 private:
  YAML::Node node_;
  std::string name_;
  std::set<std::string> seen_;
};

/// Reads the pipeline's sections (background, segmentation, tracking, events) of a YAML root
/// into config, then validates it.
Status read_pipeline_config(const YAML::Node& root, Config& config);

/// The top-level sections read_pipeline_config owns.
const std::vector<std::string>& pipeline_sections();

/// Parses a YAML file; a syntax error names the file, line and column. Any top-level key not in
/// `known_sections` is an error naming it.
Result<YAML::Node> load_yaml_file(const std::filesystem::path& path,
                                  const std::vector<std::string>& known_sections);

}  // namespace scenewatch::pipeline
