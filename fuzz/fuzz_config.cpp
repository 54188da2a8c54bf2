// The daemon's YAML config reader (load_daemon_config: the server section and the pipeline's
// sections, with their range checks): arbitrary bytes as the file given to --config.
#include <cstdint>
#include <cstdlib>

#include "fuzz_files.h"
#include "scenewatch/service/daemon_config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace scenewatch;
  const auto path = fuzz::write_scratch("scenewatchd.yaml", data, size);
  auto config = service::load_daemon_config(path);
  if (config.ok()) {
    // What it accepts passes the checks the daemon makes before it starts.
    if (!service::validate(config->server).ok() || !pipeline::validate(config->pipeline).ok()) std::abort();
  } else if (config.error().message.empty()) {
    std::abort();
  }
  return 0;
}
