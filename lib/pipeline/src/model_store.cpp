#include "model_store.h"

#include "scenewatch/core/event_json.h"
#include "scenewatch/core/files.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <memory>
#include <system_error>

namespace scenewatch::pipeline {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {
Eigen::Vector3d vec3(const json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

OrientedBox box_from(const json& j) {
  OrientedBox b;
  b.center = vec3(j.at("center"));
  const auto& q = j.at("rotation_xyzw");
  b.rotation = Eigen::Quaterniond(q.at(3).get<double>(), q.at(0).get<double>(), q.at(1).get<double>(), q.at(2).get<double>()).normalized();
  b.extents = vec3(j.at("extents"));
  return b;
}

DofFlags flags_from(const json& j) {
  DofFlags f{};
  for (const auto& name : j) {
    bool known = false;
    for (int k = 0; k < kDofCount; ++k) {
      if (name.get<std::string>() == to_string(static_cast<Dof>(k))) f[static_cast<std::size_t>(k)] = known = true;
    }
    if (!known) throw std::invalid_argument("unknown DoF '" + name.get<std::string>() + "'");
  }
  return f;
}

ForegroundState foreground_from(const json& j) {
  ForegroundState s;
  const auto m = j.at("T_world_object").get<std::vector<double>>();
  if (m.size() != 16) throw std::invalid_argument("T_world_object: 16 numbers expected");
  Eigen::Matrix4d M = Eigen::Map<const Eigen::Matrix4d>(m.data());
  if (auto st = validate_rigid(M); !st) throw std::invalid_argument("T_world_object: " + st.error().message);
  s.T_world_object = pose_from_matrix(M);
  s.free = flags_from(j.at("free"));
  for (const auto& jh : j.at("handlings")) {
    Handling h;
    h.start_s = jh.at("start_s").get<double>();
    h.end_s = jh.at("end_s").get<double>();
    const auto r = jh.at("range").get<std::vector<double>>();
    if (r.size() != h.range.size()) throw std::invalid_argument("handling range: 6 numbers expected");
    std::copy(r.begin(), r.end(), h.range.begin());
    h.moved = flags_from(jh.at("moved"));
    s.handlings.push_back(h);
  }
  s.promoted_s = j.at("promoted_s").get<double>();
  s.model_points = j.value("model_points", std::size_t{0});
  s.visible = false;  // until a frame sees it again
  return s;
}

template <typename T, typename F>
Result<T> parse(const char* what, F&& f) {
  try {
    return f();
  } catch (const std::exception& e) {
    return invalid_argument(std::string("malformed ") + what + ": " + e.what());
  }
}
}  // namespace

Result<Plane> plane_from_json(const json& j) {
  return parse<Plane>("plane", [&] {
    Plane p;
    p.id = j.at("id").get<int>();
    p.normal = vec3(j.at("normal"));
    p.d = j.at("d").get<double>();
    for (const auto& h : j.at("hull")) p.hull.push_back(vec3(h));
    p.area_m2 = j.at("area_m2").get<double>();
    p.inlier_count = j.at("inlier_count").get<std::size_t>();
    p.centroid = vec3(j.at("centroid"));
    return p;
  });
}

Result<TrackedObject> object_from_json(const json& j) {
  return parse<TrackedObject>("object", [&] {
    TrackedObject o;
    o.id = j.at("id").get<std::uint64_t>();
    o.cluster.plane_id = j.at("plane_id").get<int>();
    o.cluster.centroid = vec3(j.at("centroid"));
    o.cluster.box = box_from(j.at("box"));
    o.cluster.point_count = j.at("point_count").get<std::size_t>();
    const auto& c = j.at("mean_rgb");
    o.cluster.mean_rgb = Eigen::Vector3f(c.at(0).get<float>(), c.at(1).get<float>(), c.at(2).get<float>());
    if (j.contains("rgb_covariance")) {  // absent in models saved before it existed
      const auto v = j.at("rgb_covariance").get<std::vector<float>>();
      if (v.size() != 9) throw std::runtime_error("rgb_covariance: 9 numbers expected");
      o.cluster.rgb_covariance = Eigen::Map<const Eigen::Matrix3f>(v.data());
      if (!o.cluster.rgb_covariance.allFinite()) throw std::runtime_error("rgb_covariance: not finite");
    }
    o.first_seen_s = j.at("first_seen_s").get<double>();
    o.last_seen_s = j.at("last_seen_s").get<double>();
    o.supported_by = j.value("supported_by", std::uint64_t{0});  // absent in models saved before it existed
    o.observations = j.at("observations").get<int>();
    if (j.contains("foreground")) o.foreground = foreground_from(j.at("foreground"));
    return o;
  });
}


Status write_file_synced(const fs::path& path, const std::string& text) {
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) return io_error("'" + path.string() + "': cannot open for writing");
    out << text;
    out.flush();
    if (!out) return io_error("'" + path.string() + "': write failed");
  }
  return fsync_path(path, false);
}

Result<fs::path> current_snapshot(const fs::path& model_dir) {
  std::error_code ec;
  const fs::path link = model_dir / "current";
  if (!fs::is_symlink(link, ec)) return not_found("'" + model_dir.string() + "': no saved model (no 'current' link)");
  const fs::path target = model_dir / fs::read_symlink(link, ec);
  if (ec || !fs::is_directory(target, ec)) {
    return invalid_argument("'" + link.string() + "': points at a missing snapshot folder");
  }
  return target;
}

Status commit_snapshot(const fs::path& model_dir, const std::function<Status(const fs::path&)>& write_files,
                       std::size_t keep) {
  std::error_code ec;
  fs::create_directories(model_dir, ec);
  if (ec) return io_error("'" + model_dir.string() + "': cannot create model directory: " + ec.message());
  // Next snapshot number: one past the highest present.
  int next = 1;
  for (const auto& entry : fs::directory_iterator(model_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("snap-", 0) == 0) next = std::max(next, std::atoi(name.c_str() + 5) + 1);
  }
  char name[32];
  std::snprintf(name, sizeof(name), "snap-%06d", next);
  const fs::path staging = model_dir / (std::string(name) + ".tmp");
  const fs::path final_dir = model_dir / name;
  fs::remove_all(staging, ec);
  fs::create_directories(staging, ec);
  if (ec) return io_error("'" + staging.string() + "': cannot create: " + ec.message());
  if (auto st = write_files(staging); !st) {
    fs::remove_all(staging, ec);
    return st;
  }
  for (const auto& entry : fs::directory_iterator(staging, ec)) {
    if (auto st = fsync_path(entry.path(), false); !st) return st;
  }
  if (auto st = fsync_path(staging, true); !st) return st;
  fs::rename(staging, final_dir, ec);
  if (ec) return io_error("'" + final_dir.string() + "': cannot rename snapshot into place: " + ec.message());
  const fs::path link_tmp = model_dir / "current.tmp";
  fs::remove(link_tmp, ec);
  fs::create_directory_symlink(name, link_tmp, ec);
  if (ec) return io_error("'" + link_tmp.string() + "': cannot create link: " + ec.message());
  fs::rename(link_tmp, model_dir / "current", ec);  // atomic replacement of the link
  if (ec) return io_error("'" + (model_dir / "current").string() + "': cannot replace link: " + ec.message());
  if (auto st = fsync_path(model_dir, true); !st) return st;
  // Snapshots beyond the newest `keep` are no longer kept.
  const std::vector<fs::path> snapshots = snapshots_newest_first(model_dir);
  for (std::size_t i = std::max<std::size_t>(1, keep); i < snapshots.size(); ++i) {
    if (snapshots[i].filename() != name) fs::remove_all(snapshots[i], ec);
  }
  return {};
}

std::vector<fs::path> snapshots_newest_first(const fs::path& model_dir) {
  std::error_code ec;
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(model_dir, ec)) {
    const std::string n = entry.path().filename().string();
    if (n.rfind("snap-", 0) == 0 && n.find(".tmp") == std::string::npos) names.push_back(n);
  }
  std::sort(names.begin(), names.end(), std::greater<>());  // names sort by number: snap-%06d
  std::vector<fs::path> out;
  for (const auto& n : names) out.push_back(model_dir / n);
  return out;
}

namespace {

// The keyframes' features in a snapshot folder (localization::save_features).
constexpr const char* kFeaturesFile = "keyframe-features.bin";

// Loads the background map and checks it against what scene.json recorded when it was saved (its
// size in bytes and its leaf count): a damaged file is refused, not loaded in part and then saved
// over the model. Models saved before the record existed are loaded unchecked.
Status load_background(background::OccupancyMap& map, const fs::path& path, const nlohmann::json& scene) {
  const auto record = scene.is_object() ? scene.find("background") : scene.end();
  if (record != scene.end() && !record->is_object()) {
    return invalid_argument("'" + path.string() + "': the model's scene.json records its background as " +
                            std::string(record->type_name()) + ", not an object with bytes and leaf_nodes");
  }
  if (record != scene.end()) {
    std::error_code ec;
    const auto bytes = fs::file_size(path, ec);
    if (ec) return io_error("'" + path.string() + "': " + ec.message());
    const auto expected = record->value("bytes", std::uint64_t{0});
    if (bytes != expected) {
      return invalid_argument("'" + path.string() + "': damaged: " + std::to_string(bytes) + " bytes, the model recorded " +
                              std::to_string(expected) + " when it was saved");
    }
  }
  if (auto st = map.load(path); !st) return st;
  if (record != scene.end()) {
    const auto leaves = record->value("leaf_nodes", std::uint64_t{0});
    if (map.num_leaf_nodes() != leaves) {
      return invalid_argument("'" + path.string() + "': damaged: " + std::to_string(map.num_leaf_nodes()) +
                              " leaf nodes, the model recorded " + std::to_string(leaves));
    }
  }
  return {};
}

// scene.json's objects, foreground objects and counters into `out` (not yet the events nor the features).
Status read_scene_json(const nlohmann::json& scene, const fs::path& dir, SceneRecord& out) {
  try {
    out.last_stamp_s = scene.value("last_stamp_s", 0.0);
    out.frames = scene.at("frames_processed").get<std::uint64_t>();
    out.points = scene.value("points_processed", std::uint64_t{0});
    out.next_object_id = scene.at("next_object_id").get<std::uint64_t>();
    out.next_event_id = scene.value("next_event_id", std::uint64_t{1});
    for (const auto& j : scene.at("objects")) {
      auto o = object_from_json(j);
      if (!o) return o.error();
      for (const auto& p : j.value("samples", nlohmann::json::array()))
        out.samples[o->id].emplace_back(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>());
      out.objects.push_back(*o);
    }
    for (const auto& j : scene.value("foreground", nlohmann::json::array())) {
      auto o = object_from_json(j);
      if (!o) return o.error();
      if (!o->foreground) return invalid_argument("'" + (dir / "scene.json").string() + "': foreground object " + std::to_string(o->id) + " has no foreground state");
      auto model = std::make_shared<Cloud>();
      for (const auto& p : j.at("model")) {
        PointT q;
        q.x = p.at(0).get<float>(), q.y = p.at(1).get<float>(), q.z = p.at(2).get<float>();
        q.r = p.at(3).get<std::uint8_t>(), q.g = p.at(4).get<std::uint8_t>(), q.b = p.at(5).get<std::uint8_t>();
        model->push_back(q);
      }
      if (model->empty()) return invalid_argument("'" + (dir / "scene.json").string() + "': foreground object " + std::to_string(o->id) + " has an empty model");
      out.foreground.emplace_back(*o, std::move(model));
    }
    for (const auto& j : scene.at("planes")) {
      auto p = plane_from_json(j);
      if (!p) return p.error();
      out.planes.push_back(*p);
    }
  } catch (const std::exception& e) {
    return invalid_argument("'" + (dir / "scene.json").string() + "': malformed: " + e.what());
  }
  return {};
}

}  // namespace

Result<BackgroundRecord> save_background(const background::OccupancyMap& map, const fs::path& dir) {
  BackgroundRecord record;
  if (auto st = map.save(dir / "background.ot"); !st) return st.error();
  record.leaf_nodes = map.num_leaf_nodes();
  // What the map file must be on load: OctoMap reads a truncated .ot without complaint.
  std::error_code ec;
  record.bytes = fs::file_size(dir / "background.ot", ec);
  if (ec) return io_error("'" + (dir / "background.ot").string() + "': " + ec.message());
  return record;
}

Status write_scene(const fs::path& dir, const SceneRecord& s) {
  json scene = {{"format", "scenewatch-model"}, {"version", 1}, {"frames_processed", s.frames},
                {"points_processed", s.points}, {"next_object_id", s.next_object_id},
                {"last_stamp_s", s.last_stamp_s},
                {"background", {{"bytes", s.background.bytes}, {"leaf_nodes", s.background.leaf_nodes}}}};
  scene["objects"] = json::array();
  for (const auto& o : s.objects) {
    json j = to_json(o);
    json pts = json::array();
    if (const auto samples = s.samples.find(o.id); samples != s.samples.end())
      for (const auto& p : samples->second) pts.push_back({p.x(), p.y(), p.z()});
    j["samples"] = pts;
    scene["objects"].push_back(j);
  }
  // Foreground objects with their point models (object frame: x y z r g b).
  scene["foreground"] = json::array();
  for (const auto& [o, model] : s.foreground) {
    json j = to_json(o);
    json pts = json::array();
    if (model)
      for (const auto& p : model->points) pts.push_back({p.x, p.y, p.z, p.r, p.g, p.b});
    j["model"] = pts;
    scene["foreground"].push_back(j);
  }
  scene["planes"] = json::array();
  for (const auto& p : s.planes) scene["planes"].push_back(to_json(p));
  scene["next_event_id"] = s.next_event_id;
  std::string log;
  for (const auto& e : s.events) {
    json j = to_json(e);
    j.erase("indices_before");  // indices into frames the model no longer holds
    j.erase("indices_after");
    log += j.dump() + "\n";
  }
  if (auto st = localization::save_features(dir / kFeaturesFile, s.features); !st) return st;
  if (auto st = write_file_synced(dir / "scene.json", scene.dump(2)); !st) return st;
  return write_file_synced(dir / "events.jsonl", log);
}

Result<SceneRecord> read_snapshot(const fs::path& dir, background::OccupancyMap& map) {
  std::ifstream in(dir / "scene.json");
  if (!in) return io_error("'" + (dir / "scene.json").string() + "': cannot open");
  json scene;
  try {
    scene = json::parse(in);
  } catch (const std::exception& e) {
    return invalid_argument("'" + (dir / "scene.json").string() + "': " + e.what());
  }
  try {
    if (auto st = load_background(map, dir / "background.ot", scene); !st) return st.error();
  } catch (const std::exception& e) {  // a record of the wrong type: json's type_error
    return invalid_argument("'" + (dir / "scene.json").string() + "': malformed background record: " + e.what());
  }
  SceneRecord out;
  if (auto st = read_scene_json(scene, dir, out); !st) return st.error();
  std::ifstream log(dir / "events.jsonl");
  std::string line;
  while (std::getline(log, line)) {
    if (line.empty()) continue;
    try {
      auto e = event_from_json(json::parse(line));
      if (!e) return e.error();
      out.events.push_back(*e);
    } catch (const std::exception& ex) {
      return invalid_argument("'" + (dir / "events.jsonl").string() + "': " + ex.what());
    }
  }
  // Keyframe features (absent in models saved before them: extracted again on first use).
  if (std::error_code ec; fs::exists(dir / kFeaturesFile, ec)) {
    auto loaded = localization::load_features(dir / kFeaturesFile);
    if (!loaded) return loaded.error();
    out.features = std::move(*loaded);
  }
  return out;
}

Result<std::pair<fs::path, std::vector<std::string>>> load_newest_good(
    const fs::path& model_dir, const std::function<Status(const fs::path&)>& load) {
  auto current = current_snapshot(model_dir);
  if (!current && current.error().code == ErrorCode::kNotFound) return current.error();
  std::vector<std::string> refused;  // one message per snapshot tried before the one that loads
  std::vector<fs::path> candidates;
  if (current) candidates.push_back(*current);
  for (const auto& snap : snapshots_newest_first(model_dir)) {
    if (!current || snap.filename() != current->filename()) candidates.push_back(snap);
  }
  for (const auto& snap : candidates) {
    if (auto st = load(snap); !st) {
      refused.push_back(st.error().message);
      continue;
    }
    return std::make_pair(snap, std::move(refused));
  }
  if (!current) refused.insert(refused.begin(), current.error().message);
  std::string why;
  for (const auto& r : refused) why += (why.empty() ? "" : "; ") + r;
  return invalid_argument("'" + model_dir.string() + "': no snapshot loads: " + why);
}

}  // namespace scenewatch::pipeline
