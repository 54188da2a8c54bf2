#pragma once
// The pipeline's part of the daemon's shipped config (config/scenewatchd.yaml), as a user who
// starts scenewatchd without options gets it.
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "scenewatch/pipeline/config_loader.h"
#include "test_data.h"

namespace scenewatch::test {

/// The shipped config's pipeline sections; empty (and the test failed) when it does not load.
inline std::optional<pipeline::Config> shipped_pipeline_config() {
  std::vector<std::string> sections = pipeline::pipeline_sections();
  sections.push_back("server");  // the daemon's own sections
  sections.push_back("ontology");
  auto root = pipeline::load_yaml_file(source_dir() / "config/scenewatchd.yaml", sections);
  if (!root) {
    ADD_FAILURE() << root.error().message;
    return std::nullopt;
  }
  pipeline::Config config;
  if (const Status st = pipeline::read_pipeline_config(*root, config); !st.ok()) {
    ADD_FAILURE() << st.error().message;
    return std::nullopt;
  }
  return config;
}

}  // namespace scenewatch::test
