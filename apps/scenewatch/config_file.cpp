#include "config_file.h"

#include <vector>

#include "scenewatch/pipeline/config_loader.h"

namespace scenewatch::cli {

Result<pipeline::Config> read_config_file(const std::string& path) {
  pipeline::Config config;
  if (path.empty()) return config;
  std::vector<std::string> sections = pipeline::pipeline_sections();
  sections.push_back("server");    // the daemon's own sections, not read here
  sections.push_back("ontology");
  auto root = pipeline::load_yaml_file(path, sections);
  if (!root) return root.error();
  if (Status s = pipeline::read_pipeline_config(*root, config); !s) return Error{s.error().code, path + ": " + s.error().message};
  return config;
}

}  // namespace scenewatch::cli
