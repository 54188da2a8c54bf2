#pragma once
/// Configuration file of scenewatchd: the `server` section plus the pipeline's sections.
#include <filesystem>

#include "scenewatch/core/result.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/service/server_config.h"

namespace scenewatch::service {

/// Everything scenewatchd reads from its config file.
struct DaemonConfig {
  ServerConfig server;
  pipeline::Config pipeline;
};

/// Loads and validates a daemon config file: `server` plus the pipeline's sections. Relative
/// paths in `server` are taken relative to the file's folder.
Result<DaemonConfig> load_daemon_config(const std::filesystem::path& path);

}  // namespace scenewatch::service
