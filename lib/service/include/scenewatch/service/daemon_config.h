#pragma once
/// Configuration file of scenewatchd: the `server` section plus the pipeline's sections.
#include <filesystem>

#include "scenewatch/core/result.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/service/server_config.h"

namespace scenewatch::service {

/// The `ontology` section.
struct OntologyConfig {
  /// The object classes file (config/ontology.yaml's format); empty: the daemon's built-in
  /// default (the shipped config/ontology.yaml). Relative to the config file's folder.
  std::filesystem::path classes_file;
};

/// Everything scenewatchd reads from its config file.
struct DaemonConfig {
  ServerConfig server;
  pipeline::Config pipeline;
  OntologyConfig ontology;
};

/// Loads and validates a daemon config file: `server`, `ontology` and the pipeline's sections. Relative
/// paths in `server` are taken relative to the file's folder.
Result<DaemonConfig> load_daemon_config(const std::filesystem::path& path);

}  // namespace scenewatch::service
