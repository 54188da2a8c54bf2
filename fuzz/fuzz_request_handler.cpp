// The request handler: arbitrary bytes as one Request payload (what the session hands over after
// the framing), answered by a RequestHandler over a real, small WorkingMemory. No token is
// configured, so the calls that change the model run too (the token check comes before them).
// The model is reset before each input, so an input's outcome does not depend on the ones before.
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "fuzz_files.h"
#include "scenewatch.pb.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/service/request_handler.h"

namespace {
namespace fs = std::filesystem;
using namespace scenewatch;

/// The data root IngestFile may read: a fixed path (seed requests name it) holding a small cloud.
const fs::path kDataRoot = "/tmp/scenewatch-fuzz-root";

struct Fixture {
  pipeline::WorkingMemory memory{pipeline::Config{}};
  service::RequestHandler handler;

  static service::HandlerConfig handler_config() {
    std::error_code ec;
    fs::create_directories(kDataRoot, ec);
    std::ofstream(kDataRoot / "cloud.pcd") << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                                              "COUNT 1 1 1\nWIDTH 4\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\n"
                                              "DATA ascii\n0 0 1\n0.1 0 1\n0 0.1 1\n0.1 0.1 1\n";
    service::HandlerConfig config;
    config.data_roots = {kDataRoot};
    config.model_dir = fuzz::scratch_dir() / "model";
    config.max_file_bytes = 1 << 20;
    config.keep_snapshots = 2;
    return config;
  }

  Fixture() : handler(memory, handler_config()) {}
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Fixture* fixture = new Fixture();  // lives for the process, as the daemon's does
  fixture->memory.reset();
  service::SessionContext context;
  std::size_t pushed = 0;
  context.event_sink = [&pushed](std::string) { ++pushed; };
  const service::Reply reply =
      fixture->handler.handle_now(std::string(reinterpret_cast<const char*>(data), size), context);
  fixture->handler.unsubscribe(context);
  // Whatever came in, the answer is a Response the client can parse, with an error or a result.
  proto::Response response;
  if (!response.ParseFromString(reply.payload)) std::abort();
  if (reply.ok != (response.status().code() == proto::Status::OK)) std::abort();
  if (!reply.ok && (response.result_case() != proto::Response::RESULT_NOT_SET || response.status().message().empty())) {
    std::abort();
  }
  return 0;
}
