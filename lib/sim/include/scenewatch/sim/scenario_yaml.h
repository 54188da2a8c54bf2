#pragma once
/// Scenarios from YAML (sample_clouds/scenarios/*.yaml; the schema is in sample_clouds/README.md).
/// Parsing is strict: an unknown key, a value of the wrong type or out of range is an error whose
/// message names the file and the key's path ("objects[2].radius_m: expected a number").
#include <filesystem>
#include <string>

#include "scenewatch/core/result.h"
#include "scenewatch/sim/scenario.h"

namespace scenewatch::sim {

/// Parses a scenario from YAML text; `source` names it in error messages.
Result<Scenario> parse_scenario(const std::string& yaml_text, const std::string& source = "scenario");

/// Reads and parses a scenario file; a scenario without a name takes the file's stem.
Result<Scenario> load_scenario(const std::filesystem::path& path);

}  // namespace scenewatch::sim
