// The model loader: a damaged snapshot folder, as a disk error, a half-copied backup or a hand
// edit leaves it, loaded the ways the daemon loads it: at start-up (service::load_newest_good)
// and by LoadModel (through the RequestHandler). The input is split at "\n--8<--\n" into the
// folder's files (scene.json, background.ot, events.jsonl, then one keyframe's colour PNG, depth
// PNG, pose and intrinsics; missing parts: files left out). Neither way may crash; both must agree;
// a refused model leaves the memory as it was; a model that loads must save again, and that must
// load. A loader that throws (the handler answers INTERNAL, the start-up stops with an error)
// is a defect of its own: each distinct one is printed once to the log.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>

#include "fuzz_files.h"
#include "scenewatch.pb.h"
#include "scenewatch/core/scene_json.h"
#include "scenewatch/pipeline/working_memory.h"
#include "scenewatch/service/model_directory.h"
#include "scenewatch/service/request_handler.h"

namespace {
namespace fs = std::filesystem;
using namespace scenewatch;

const char* const kFiles[] = {"scene.json",
                              "background.ot",
                              "events.jsonl",
                              "keyframes/keyframe-000001.color.png",
                              "keyframes/keyframe-000001.depth.png",
                              "keyframes/keyframe-000001.pose.txt",
                              "keyframes/keyframe-000001.intrinsics.txt"};
constexpr std::size_t kParts = sizeof kFiles / sizeof kFiles[0];

const fs::path& model_dir() {
  static const fs::path dir = fuzz::scratch_dir() / "model";
  return dir;
}

/// Writes the parts into model/snap-000001 of the scratch folder, with `current` pointing at it.
void write_model(const std::uint8_t* data, std::size_t size) {
  std::error_code ec;
  fs::remove_all(model_dir(), ec);
  fs::create_directories(model_dir() / "snap-000001" / "keyframes");
  fs::create_directory_symlink("snap-000001", model_dir() / "current");
  const auto parts = fuzz::split_input(data, size, "\n--8<--\n", kParts);
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(parts[i].data());
    fuzz::write_scratch((fs::path("model") / "snap-000001" / kFiles[i]).string(), bytes, parts[i].size());
  }
}

struct Fixture {
  pipeline::WorkingMemory memory{pipeline::Config{}};
  service::RequestHandler handler{memory, [] {
                                    service::HandlerConfig config;
                                    config.model_dir = model_dir();
                                    return config;
                                  }()};
};

/// LoadModel as a client sends it; the response, which must parse.
proto::Response load_model(Fixture& f) {
  proto::Request request;
  request.set_id(1);
  request.mutable_load_model();
  service::SessionContext context;
  const service::Reply reply = f.handler.handle_now(request.SerializeAsString(), context);
  proto::Response response;
  if (!response.ParseFromString(reply.payload)) std::abort();
  if (reply.ok != (response.status().code() == proto::Status::OK)) std::abort();
  return response;
}

/// Prints a loader's exception once per distinct message (printable characters only: the log stays
/// text).
void report_once(std::string message) {
  static std::set<std::string> seen;
  for (char& c : message) {
    if (c < 0x20 || c > 0x7e) c = '?';
  }
  if (seen.insert(message.substr(0, 200)).second) std::fprintf(stderr, "loader threw: %s\n", message.c_str());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Fixture* fixture = new Fixture();  // lives for the process, as the daemon's does
  pipeline::WorkingMemory& memory = fixture->memory;
  memory.reset();
  write_model(data, size);
  const auto before = memory.snapshot();
  const auto started = service::load_newest_good(memory, model_dir());
  if (!started.ok() && memory.snapshot() != before) std::abort();  // a refused model changes nothing
  if (!started.ok() && started.error().message.find("the model's loader failed on it") != std::string::npos) {
    report_once(started.error().message);
  }
  const proto::Response loaded = load_model(*fixture);
  if (loaded.status().code() == proto::Status::INTERNAL) report_once(loaded.status().message());
  // One snapshot: the start-up and LoadModel both load it, or neither does.
  if ((loaded.status().code() == proto::Status::OK) != started.ok()) std::abort();
  if (!started.ok()) return 0;
  const auto snapshot = memory.snapshot();
  if (!snapshot) std::abort();
  for (const auto& object : snapshot->objects) (void)to_json(object).dump();
  (void)memory.events_since(0, 100);
  // What was loaded saves again, and that loads.
  const fs::path again = fuzz::scratch_dir() / "saved";
  std::error_code ec;
  fs::remove_all(again, ec);
  if (!service::save_model(memory, again, 1).ok()) std::abort();
  if (!memory.load(again).ok()) std::abort();
  return 0;
}
