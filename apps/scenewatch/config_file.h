#pragma once
// The offline commands' --config: a scenewatchd config file, of which they use the pipeline
// sections (the server section may be there; it is not read).
#include <string>

#include "scenewatch/core/result.h"
#include "scenewatch/pipeline/working_memory.h"

namespace scenewatch::cli {

/// The pipeline configuration in `path`; the defaults when `path` is empty. Errors name the file
/// and the key.
Result<pipeline::Config> read_config_file(const std::string& path);

}  // namespace scenewatch::cli
