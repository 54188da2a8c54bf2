// Request latency of GetObjects over loopback against a running scenewatchd (filled in once the
// service client is available; prints a note otherwise).
#include "bench.h"

namespace scenewatch::bench {

int run_latency(const Options&) {
  std::printf("\n== GetObjects latency: the service module is not built; skipped\n");
  return 0;
}

}  // namespace scenewatch::bench
