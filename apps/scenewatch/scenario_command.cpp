// `scenewatch replay SCRIPT.yaml [--check]`: a scripted foreground-extraction test. The script names
// what to replay (a simulator scenario rendered on the fly, or a recorded sequence folder) and what
// must happen; the frames go to a running daemon over TCP, as a client sends them, and what the
// daemon answered is compared with the script. The format is documented in docs/testing.md ("Scenario scripts").
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "commands.h"
#include "frame_spec.h"
#include "install_layout.h"
#include "scenewatch/service/client.h"
#include "scenewatch/sim/scenario_yaml.h"
#include "scenewatch/sim/simulator.h"

namespace scenewatch::cli {
namespace fs = std::filesystem;

namespace {

struct PromotedExpectation {
  Eigen::Vector3d near = Eigen::Vector3d::Zero();
  double within_m = 0.15;
  std::optional<int> by_frame;
  std::vector<std::string> free_dofs, frozen_dofs;
  std::optional<Eigen::Vector3d> ends_near;  ///< where it must be at the end (tracked there)
  double ends_within_m = 0.15;
};

struct Script {
  std::string name;
  std::string simulator;  // scenario name or path
  std::string sequence;   // folder
  int width = 320, height = 240;
  std::optional<int> frames;
  std::vector<PromotedExpectation> promoted;
  std::optional<std::size_t> promoted_count;
  std::map<std::string, std::pair<std::size_t, std::size_t>> events;  // kind -> [min, max]
};

Result<Script> read_script(const fs::path& path) {
  Script s;
  try {
    const YAML::Node root = YAML::LoadFile(path.string());
    s.name = root["name"] ? root["name"].as<std::string>() : path.stem().string();
    const YAML::Node replay = root["replay"];
    if (!replay) return invalid_argument("'" + path.string() + "': 'replay' is missing (simulator: NAME or sequence: DIR)");
    if (replay["simulator"]) s.simulator = replay["simulator"].as<std::string>();
    if (replay["sequence"]) {
      fs::path seq = replay["sequence"].as<std::string>();
      s.sequence = (seq.is_relative() ? path.parent_path() / seq : seq).lexically_normal().string();
    }
    if (s.simulator.empty() == s.sequence.empty()) {
      return invalid_argument("'" + path.string() + "': replay: give exactly one of 'simulator' and 'sequence'");
    }
    if (replay["width"]) s.width = replay["width"].as<int>();
    if (replay["height"]) s.height = replay["height"].as<int>();
    if (replay["frames"]) s.frames = replay["frames"].as<int>();
    const YAML::Node expect = root["expect"];
    if (!expect) return invalid_argument("'" + path.string() + "': 'expect' is missing");
    if (expect["promoted_count"]) s.promoted_count = expect["promoted_count"].as<std::size_t>();
    for (const auto& p : expect["promoted"]) {
      PromotedExpectation e;
      const auto v = p["near"].as<std::vector<double>>();
      if (v.size() != 3) return invalid_argument("'" + path.string() + "': expect.promoted.near: [x, y, z] expected");
      e.near = {v[0], v[1], v[2]};
      if (p["within_m"]) e.within_m = p["within_m"].as<double>();
      if (p["by_frame"]) e.by_frame = p["by_frame"].as<int>();
      if (p["free_dofs"]) e.free_dofs = p["free_dofs"].as<std::vector<std::string>>();
      if (p["frozen_dofs"]) e.frozen_dofs = p["frozen_dofs"].as<std::vector<std::string>>();
      if (p["ends_near"]) {
        const auto w = p["ends_near"].as<std::vector<double>>();
        if (w.size() != 3) return invalid_argument("'" + path.string() + "': expect.promoted.ends_near: [x, y, z] expected");
        e.ends_near = Eigen::Vector3d(w[0], w[1], w[2]);
      }
      if (p["ends_within_m"]) e.ends_within_m = p["ends_within_m"].as<double>();
      s.promoted.push_back(e);
    }
    for (const auto& kv : expect["events"]) {
      const std::string kind = kv.first.as<std::string>();
      proto::Event::Kind k;
      if (!proto::Event::Kind_Parse(kind, &k)) return invalid_argument("'" + path.string() + "': expect.events: unknown kind '" + kind + "'");
      if (kv.second.IsSequence()) {
        const auto r = kv.second.as<std::vector<std::size_t>>();
        if (r.size() != 2 || r[0] > r[1]) return invalid_argument("'" + path.string() + "': expect.events." + kind + ": [min, max] expected");
        s.events[kind] = {r[0], r[1]};
      } else {
        const auto n = kv.second.as<std::size_t>();
        s.events[kind] = {n, n};
      }
    }
  } catch (const YAML::Exception& e) {
    return invalid_argument("'" + path.string() + "': " + e.what());
  }
  return s;
}

// Calls `each(frame, index)` for every frame the script replays.
Status for_each_script_frame(const Script& s, const std::function<Status(const Frame&, int)>& each) {
  if (!s.sequence.empty()) {
    int index = 0;
    return for_each_frame(s.sequence, std::nullopt, [&](Frame f) -> Status {
      if (s.frames && index >= *s.frames) return {};
      return each(f, index++);
    });
  }
  fs::path path = s.simulator;
  if (path.extension() != ".yaml") path = apps::scenarios_dir() / (s.simulator + ".yaml");
  auto scenario = sim::load_scenario(path);
  if (!scenario) return scenario.error();
  auto sized = sim::with_resolution(*scenario, s.width, s.height);
  if (s.frames) sized = sim::with_frames(sized, *s.frames);
  auto simulator = sim::Simulator::create(sized);
  if (!simulator) return simulator.error();
  const double dt = 1.0 / simulator->scenario().frame_rate_hz;
  int index = 0;
  for (std::size_t phase = 0; phase < simulator->phase_count(); ++phase) {
    for (int k = 0; k < simulator->frame_count(phase); ++k, ++index) {
      auto frame = sim::as_frame(simulator->render(phase, k), simulator->scenario().intrinsics, index * dt);
      if (!frame) return frame.error();
      if (auto st = each(*frame, index); !st) return st;
    }
  }
  return {};
}

bool contains(const google::protobuf::RepeatedPtrField<std::string>& list, const std::string& name) {
  for (const auto& n : list)
    if (n == name) return true;
  return false;
}

}  // namespace

int run_scenario(const RemoteOptions& remote, const std::string& script_path, bool check) {
  auto script = read_script(script_path);
  if (!script) return fail(script.error().message);
  auto client = connect_remote(remote);
  if (!client) return fail(client.error().message);
  {
    proto::Request reset;
    reset.mutable_reset();
    auto r = client->call(std::move(reset), remote.timeout_s);
    if (!r) return fail(r.error().message);
    if (r->status().code() != proto::Status::OK) return fail("reset refused: " + r->status().message());
  }
  std::printf("scenario %s: replaying %s through %s:%d\n", script->name.c_str(),
              (script->sequence.empty() ? "simulator " + script->simulator : script->sequence).c_str(), remote.host.c_str(), remote.port);
  std::vector<std::pair<int, proto::Event>> events;
  int frames = 0;
  auto st = for_each_script_frame(*script, [&](const Frame& frame, int index) -> Status {
    proto::Request request;
    *request.mutable_ingest_frame() = service::make_ingest_frame(frame);
    auto r = client->call(std::move(request), remote.timeout_s);
    if (!r) return r.error();
    if (r->status().code() != proto::Status::OK) return invalid_argument("frame " + std::to_string(index) + ": " + r->status().message());
    for (const auto& e : r->ingest().events()) {
      events.emplace_back(index, e);
      std::printf("  frame %4d  %-18s object %-4llu at (%.3f, %.3f, %.3f)  %s\n", index, proto::Event::Kind_Name(e.kind()).c_str(),
                  static_cast<unsigned long long>(e.object_id()), e.centroid_world().x(), e.centroid_world().y(),
                  e.centroid_world().z(), e.detail().c_str());
    }
    ++frames;
    return {};
  });
  if (!st) return fail(st.error().message);
  proto::Request get;
  get.mutable_get_objects();
  auto objects = client->call(std::move(get), remote.timeout_s);
  if (!objects) return fail(objects.error().message);
  std::vector<proto::Object> foreground;
  for (const auto& o : objects->objects().objects())
    if (o.foreground()) foreground.push_back(o);
  std::printf("%d frames, %zu events; %zu foreground object(s)\n", frames, events.size(), foreground.size());
  for (const auto& o : foreground) {
    std::string free, frozen;
    for (const auto& d : o.free_dofs()) free += " " + d;
    for (const auto& d : o.frozen_dofs()) frozen += " " + d;
    std::printf("  object %llu at (%.3f, %.3f, %.3f)%s: free%s; frozen%s; handled %dx\n", static_cast<unsigned long long>(o.id()),
                o.centroid().x(), o.centroid().y(), o.centroid().z(), o.visible() ? "" : " (not seen in the last frame)",
                free.c_str(), frozen.c_str(), o.handlings_size());
  }

  // What the script expects against what happened.
  std::vector<std::string> failures;
  std::map<std::string, std::size_t> count;
  for (const auto& [k, e] : events) ++count[proto::Event::Kind_Name(e.kind())];
  for (const auto& [kind, range] : script->events) {
    const std::size_t n = count[kind];
    if (n < range.first || n > range.second) {
      std::ostringstream os;
      os << kind << ": expected " << (range.first == range.second ? std::to_string(range.first)
                                                                  : std::to_string(range.first) + " to " + std::to_string(range.second))
         << ", got " << n;
      failures.push_back(os.str());
    }
  }
  if (script->promoted_count && foreground.size() != *script->promoted_count) {
    failures.push_back("foreground objects: expected " + std::to_string(*script->promoted_count) + ", got " +
                       std::to_string(foreground.size()));
  }
  for (std::size_t i = 0; i < script->promoted.size(); ++i) {
    const auto& want = script->promoted[i];
    const std::string what = "promoted[" + std::to_string(i) + "] near (" + std::to_string(want.near.x()) + ", " +
                             std::to_string(want.near.y()) + ", " + std::to_string(want.near.z()) + ")";
    const proto::Event* hit = nullptr;
    int at = -1;
    for (const auto& [k, e] : events) {
      if (e.kind() != proto::Event::OBJECT_PROMOTED) continue;
      const Eigen::Vector3d c(e.centroid_world().x(), e.centroid_world().y(), e.centroid_world().z());
      if ((c - want.near).norm() <= want.within_m) {
        hit = &e, at = k;
        break;
      }
    }
    if (!hit) {
      failures.push_back(what + ": no OBJECT_PROMOTED within " + std::to_string(want.within_m) + " m");
      continue;
    }
    if (want.by_frame && at > *want.by_frame) {
      failures.push_back(what + ": promoted at frame " + std::to_string(at) + ", expected by frame " + std::to_string(*want.by_frame));
    }
    const proto::Object* object = nullptr;
    for (const auto& o : foreground)
      if (o.id() == hit->object_id()) object = &o;
    if (!object) {
      failures.push_back(what + ": object " + std::to_string(hit->object_id()) + " is no longer a foreground object");
      continue;
    }
    for (const auto& d : want.free_dofs)
      if (!contains(object->free_dofs(), d)) failures.push_back(what + ": DoF " + d + " expected free, is frozen");
    for (const auto& d : want.frozen_dofs)
      if (!contains(object->frozen_dofs(), d)) failures.push_back(what + ": DoF " + d + " expected frozen, is free");
    if (want.ends_near) {
      const Eigen::Vector3d c(object->centroid().x(), object->centroid().y(), object->centroid().z());
      if ((c - *want.ends_near).norm() > want.ends_within_m) {
        std::ostringstream os;
        os.precision(3);
        os << what << ": ends at (" << c.x() << ", " << c.y() << ", " << c.z() << "), " << (c - *want.ends_near).norm()
           << " m from where it should (within " << want.ends_within_m << " m)";
        failures.push_back(os.str());
      }
    }
  }
  if (failures.empty()) {
    std::printf("scenario %s: every expectation met\n", script->name.c_str());
    return kExitOk;
  }
  std::printf("scenario %s: %zu expectation(s) not met:\n", script->name.c_str(), failures.size());
  for (const auto& f : failures) std::printf("  - %s\n", f.c_str());
  return check ? kExitError : kExitOk;
}

}  // namespace scenewatch::cli
