#include "scenewatch/sim/ground_truth.h"

#include "scenewatch/core/files.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

namespace scenewatch::sim {
namespace {

// Written in insertion order (format and version first); read with the same type.
using json = nlohmann::ordered_json;

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr const char* kTruthFormat = "scenewatch-sim-ground-truth";
constexpr const char* kChangesFormat = "scenewatch-sim-changes";
constexpr int kVersion = 1;

// ---- JSON encoding ----------------------------------------------------------------------------

json pose_json(const Pose& T) {
  json rows = json::array();
  const Eigen::Matrix4d m = T.matrix();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

json vec_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

json dof_json(const DofVector& v) {
  json j = json::object();
  for (int k = 0; k < kDofCount; ++k) j[to_string(static_cast<Dof>(k))] = v[static_cast<std::size_t>(k)];
  return j;
}

json dof_list_json(const DofFlags& f) {
  json j = json::array();
  for (int k = 0; k < kDofCount; ++k) {
    if (f[static_cast<std::size_t>(k)]) j.push_back(to_string(static_cast<Dof>(k)));
  }
  return j;
}

json shape_json(const Shape& s) {
  json j;
  j["kind"] = to_string(s.kind);
  switch (s.kind) {
    case ShapeKind::kBox:
      j["size_m"] = vec_json(s.size_m);
      break;
    case ShapeKind::kCylinder:
      j["radius_m"] = s.radius_m;
      j["height_m"] = s.height_m;
      break;
    case ShapeKind::kFrustum:
      j["radius_m"] = s.radius_m;
      j["top_radius_m"] = s.top_radius_m;
      j["height_m"] = s.height_m;
      break;
    case ShapeKind::kSphere:
      j["radius_m"] = s.radius_m;
      break;
    case ShapeKind::kCapsule:
      j["radius_m"] = s.radius_m;
      j["height_m"] = s.height_m;
      break;
  }
  if (s.kind == ShapeKind::kCylinder || s.kind == ShapeKind::kFrustum) {
    j["open_top"] = s.open_top;
    if (s.open_top) j["wall_m"] = s.wall_m;
  }
  return j;
}

json object_json(const ObjectTruth& o) {
  return {{"id", o.id}, {"name", o.name}, {"label", o.label}, {"shape", shape_json(o.shape)},
          {"transparent", o.transparent}};
}

json intervals_json(const std::vector<ContactInterval>& v) {
  json j = json::array();
  for (const auto& c : v) j.push_back({{"object", c.object_id}, {"first_frame", c.first_frame}, {"last_frame", c.last_frame}});
  return j;
}

// ---- JSON decoding (throws; the public readers turn that into an Error) ---------------------------

struct DecodeError {
  std::string message;
};

const json& at(const json& j, const std::string& key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw DecodeError{where + ": missing key '" + key + "'"};
  return j.at(key);
}

template <typename T>
T get(const json& j, const std::string& key, const std::string& where) {
  try {
    return at(j, key, where).get<T>();
  } catch (const json::exception& e) {
    throw DecodeError{where + "." + key + ": " + e.what()};
  }
}

Pose pose_from(const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 4) throw DecodeError{where + ": expected a 4x4 matrix"};
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    const json& row = j[static_cast<std::size_t>(r)];
    if (!row.is_array() || row.size() != 4) throw DecodeError{where + ": expected a 4x4 matrix"};
    for (int c = 0; c < 4; ++c) {
      if (!row[static_cast<std::size_t>(c)].is_number()) throw DecodeError{where + ": matrix entries must be numbers"};
      m(r, c) = row[static_cast<std::size_t>(c)].get<double>();
    }
  }
  Pose T = Pose::Identity();
  T.matrix() = m;
  return T;
}

Eigen::Vector3d vec_from(const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) throw DecodeError{where + ": expected [x, y, z]"};
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

DofVector dof_from(const json& j, const std::string& where) {
  DofVector v{};
  for (int k = 0; k < kDofCount; ++k) v[static_cast<std::size_t>(k)] = get<double>(j, to_string(static_cast<Dof>(k)), where);
  return v;
}

Dof dof_named(const std::string& name, const std::string& where) {
  for (int k = 0; k < kDofCount; ++k) {
    if (name == to_string(static_cast<Dof>(k))) return static_cast<Dof>(k);
  }
  throw DecodeError{where + ": unknown DoF '" + name + "'"};
}

DofFlags dof_flags_from(const json& j, const std::string& where) {
  DofFlags f{};
  if (!j.is_array()) throw DecodeError{where + ": expected a list of DoF names"};
  for (const auto& n : j) f[static_cast<std::size_t>(dof_named(n.get<std::string>(), where))] = true;
  return f;
}

Shape shape_from(const json& j, const std::string& where) {
  Shape s;
  const auto kind = get<std::string>(j, "kind", where);
  bool known = false;
  for (ShapeKind k : {ShapeKind::kBox, ShapeKind::kCylinder, ShapeKind::kFrustum, ShapeKind::kSphere, ShapeKind::kCapsule}) {
    if (kind == to_string(k)) { s.kind = k; known = true; }
  }
  if (!known) throw DecodeError{where + ".kind: unknown shape '" + kind + "'"};
  if (j.contains("size_m")) s.size_m = vec_from(j["size_m"], where + ".size_m");
  if (j.contains("radius_m")) s.radius_m = get<double>(j, "radius_m", where);
  if (j.contains("top_radius_m")) s.top_radius_m = get<double>(j, "top_radius_m", where);
  if (j.contains("height_m")) s.height_m = get<double>(j, "height_m", where);
  if (j.contains("open_top")) s.open_top = get<bool>(j, "open_top", where);
  if (j.contains("wall_m")) s.wall_m = get<double>(j, "wall_m", where);
  return s;
}

ObjectTruth object_from(const json& j, const std::string& where) {
  ObjectTruth o;
  o.id = get<int>(j, "id", where);
  o.name = get<std::string>(j, "name", where);
  o.label = get<std::uint16_t>(j, "label", where);
  o.shape = shape_from(at(j, "shape", where), where + ".shape");
  o.transparent = get<bool>(j, "transparent", where);
  return o;
}

std::vector<ContactInterval> intervals_from(const json& j, const std::string& where) {
  std::vector<ContactInterval> v;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string w = where + "[" + std::to_string(i) + "]";
    v.push_back({get<int>(j[i], "object", w), get<int>(j[i], "first_frame", w), get<int>(j[i], "last_frame", w)});
  }
  return v;
}

/// True for a number, string, bool or null, or a list of them (a vector, a matrix row).
bool is_flat(const json& j) {
  if (!j.is_structured()) return true;
  if (!j.is_array()) return false;
  return std::all_of(j.begin(), j.end(), [](const json& e) { return !e.is_structured(); });
}

/// Pretty-prints with one key per line but vectors and matrices on one line each, so that a file
/// of hundreds of poses stays readable.
void pretty(const json& j, int indent, std::string* out) {
  const bool matrix = j.is_array() && !j.empty() && std::all_of(j.begin(), j.end(), [](const json& e) {
    return e.is_array() && is_flat(e);
  });
  if (is_flat(j) || matrix) {
    *out += j.dump();
    return;
  }
  const std::string pad(static_cast<std::size_t>(indent + 1), ' ');
  const bool object = j.is_object();
  *out += object ? "{" : "[";
  if (j.empty()) {
    *out += object ? "}" : "]";
    return;
  }
  bool first = true;
  for (auto it = j.begin(); it != j.end(); ++it) {
    *out += first ? "\n" : ",\n";
    first = false;
    *out += pad;
    if (object) *out += json(it.key()).dump() + ": ";
    pretty(*it, indent + 1, out);
  }
  *out += "\n" + std::string(static_cast<std::size_t>(indent), ' ') + (object ? "}" : "]");
}

Status write_json_atomically(const std::filesystem::path& path, const json& j) {
  return write_atomically(path, [&](const std::filesystem::path& tmp) -> Status {
    std::ofstream out(tmp);
    if (!out) return io_error(path.string() + ": cannot open for writing");
    std::string text;
    pretty(j, 0, &text);
    out << text << '\n';
    out.flush();
    if (!out) return io_error(path.string() + ": write failed");
    return {};
  });
}

Result<json> read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return not_found(path.string() + ": cannot open");
  try {
    return json::parse(in);
  } catch (const json::exception& e) {
    return invalid_argument(path.string() + ": not valid JSON: " + e.what());
  }
}

/// Intervals of consecutive frames in which `member(frame)` holds `id`.
template <typename Member>
void collect_intervals(const SequenceTruth& t, Member member, std::vector<ContactInterval>* out) {
  std::set<int> ids;
  for (const auto& f : t.frames) for (int id : member(f)) ids.insert(id);
  for (int id : ids) {
    int start = -1;
    for (std::size_t i = 0; i <= t.frames.size(); ++i) {
      const bool in = i < t.frames.size() &&
                      std::find(member(t.frames[i]).begin(), member(t.frames[i]).end(), id) != member(t.frames[i]).end();
      if (in && start < 0) start = static_cast<int>(i);
      if (!in && start >= 0) {
        out->push_back({id, start, static_cast<int>(i) - 1});
        start = -1;
      }
    }
  }
  std::sort(out->begin(), out->end(), [](const ContactInterval& a, const ContactInterval& b) {
    return a.first_frame != b.first_frame ? a.first_frame < b.first_frame : a.object_id < b.object_id;
  });
}

std::optional<Pose> pose_of(const FrameTruth& f, int id) {
  for (const auto& o : f.objects) {
    if (o.id == id) return o.T_world_object;
  }
  return std::nullopt;
}

const ObjectTruth* find_object(const SequenceTruth& t, int id) {
  for (const auto& o : t.objects) {
    if (o.id == id) return &o;
  }
  return nullptr;
}

bool exceeds(const DofVector& v, int k, const DofThresholds& th) {
  const double limit = k < 3 ? th.translation_m : th.rotation_deg;
  return std::abs(v[static_cast<std::size_t>(k)]) > limit;
}

}  // namespace



void analyse_interactions(SequenceTruth* t) {
  t->touched.clear();
  t->held.clear();
  t->manipulations.clear();
  t->frozen_dof_motions.clear();
  collect_intervals(*t, [](const FrameTruth& f) -> const std::vector<int>& { return f.touched; }, &t->touched);
  collect_intervals(*t, [](const FrameTruth& f) -> const std::vector<int>& { return f.held; }, &t->held);

  std::map<int, DofFlags> released;  // per object: DoFs seen to move in earlier manipulations
  std::map<int, int> count;
  for (const ContactInterval& h : t->held) {
    Manipulation m;
    m.object_id = h.object_id;
    m.grasp_frame = h.first_frame;
    const int last = h.last_frame + 1 < static_cast<int>(t->frames.size()) ? h.last_frame + 1 : h.last_frame;
    m.release_frame = h.last_frame + 1 < static_cast<int>(t->frames.size()) ? h.last_frame + 1 : -1;
    const auto start = pose_of(t->frames[static_cast<std::size_t>(h.first_frame)], h.object_id);
    if (!start) continue;
    DofVector lo{}, hi{};
    std::vector<std::pair<int, DofVector>> deltas;
    for (int f = h.first_frame; f <= last; ++f) {
      const auto pose = pose_of(t->frames[static_cast<std::size_t>(f)], h.object_id);
      if (!pose) continue;
      const DofVector d = dof_delta(t->T_world_support, *start, *pose);
      deltas.emplace_back(f, d);
      for (int k = 0; k < kDofCount; ++k) {
        lo[static_cast<std::size_t>(k)] = std::min(lo[static_cast<std::size_t>(k)], d[static_cast<std::size_t>(k)]);
        hi[static_cast<std::size_t>(k)] = std::max(hi[static_cast<std::size_t>(k)], d[static_cast<std::size_t>(k)]);
      }
    }
    DofFlags& seen = released[m.object_id];
    for (int k = 0; k < kDofCount; ++k) {
      const auto ks = static_cast<std::size_t>(k);
      m.dof_range[ks] = hi[ks] - lo[ks];
      m.moved[ks] = exceeds(m.dof_range, k, t->thresholds);
      m.newly_moved[ks] = m.moved[ks] && !seen[ks];
    }
    const bool learning = count[m.object_id]++ == 0;
    if (!learning) {
      FrozenDofMotion fm;
      fm.object_id = m.object_id;
      fm.manipulation = static_cast<int>(t->manipulations.size());
      for (int k = 0; k < kDofCount; ++k) {
        if (m.newly_moved[static_cast<std::size_t>(k)]) fm.dofs.push_back(static_cast<Dof>(k));
      }
      if (!fm.dofs.empty()) {
        fm.first_frame = h.first_frame;
        bool found = false;
        for (const auto& [f, d] : deltas) {
          for (Dof dof : fm.dofs) {
            // Range, not value: the first frame at which the span seen so far exceeds the threshold
            // equals the first frame at which |delta| does, since delta starts at 0.
            if (exceeds(d, static_cast<int>(dof), t->thresholds)) { fm.first_frame = f; found = true; break; }
          }
          if (found) break;
        }
        t->frozen_dof_motions.push_back(fm);
      }
    }
    for (int k = 0; k < kDofCount; ++k) seen[static_cast<std::size_t>(k)] = seen[static_cast<std::size_t>(k)] || m.moved[static_cast<std::size_t>(k)];
    t->manipulations.push_back(m);
  }
}

ChangeTruth compare_sequences(const SequenceTruth& before, const SequenceTruth& after) {
  ChangeTruth c;
  c.from = before.phase;
  c.to = after.phase;
  if (before.frames.empty() || after.frames.empty()) return c;
  const FrameTruth& last = before.frames.back();
  const FrameTruth& first = after.frames.front();
  for (const ObjectPose& o : last.objects) {
    const auto later = pose_of(first, o.id);
    if (!later) {
      c.removed.push_back({*find_object(before, o.id), o.T_world_object});
      continue;
    }
    ObjectDisplacement d;
    d.id = o.id;
    d.T_world_before = o.T_world_object;
    d.T_world_after = *later;
    d.translation_world_m = later->translation() - o.T_world_object.translation();
    d.rotation_deg = Eigen::AngleAxisd(later->linear() * o.T_world_object.linear().transpose()).angle() * kRadToDeg;
    d.dof_delta = dof_delta(after.T_world_support, o.T_world_object, *later);
    if (d.translation_world_m.norm() > after.thresholds.translation_m || d.rotation_deg > after.thresholds.rotation_deg) {
      c.moved.push_back(d);
    }
  }
  for (const ObjectPose& o : first.objects) {
    if (!pose_of(last, o.id)) c.added.push_back({*find_object(after, o.id), o.T_world_object});
  }
  return c;
}

Status write_ground_truth(const std::filesystem::path& path, const SequenceTruth& t) {
  json j;
  j["format"] = kTruthFormat;
  j["version"] = kVersion;
  j["scenario"] = t.scenario;
  j["phase"] = t.phase;
  j["seed"] = t.seed;
  j["intrinsics"] = {{"fx", t.intrinsics.fx}, {"fy", t.intrinsics.fy}, {"cx", t.intrinsics.cx},
                     {"cy", t.intrinsics.cy}, {"width", t.intrinsics.width}, {"height", t.intrinsics.height}};
  j["labels"] = {{"background", kLabelBackground}, {"table", kLabelTable}, {"hand", kLabelHand},
                 {"object_factor", kObjectLabelFactor}};
  j["T_world_support"] = pose_json(t.T_world_support);
  j["dof_thresholds"] = {{"translation_m", t.thresholds.translation_m}, {"rotation_deg", t.thresholds.rotation_deg}};
  j["objects"] = json::array();
  for (const auto& o : t.objects) j["objects"].push_back(object_json(o));
  j["frames"] = json::array();
  for (const auto& f : t.frames) {
    json jf;
    jf["name"] = f.name;
    jf["stamp_s"] = f.stamp_s;
    jf["T_world_camera"] = pose_json(f.T_world_camera);
    jf["T_world_camera_reported"] = pose_json(f.T_world_camera_reported);
    jf["T_world_hand"] = f.T_world_hand ? pose_json(*f.T_world_hand) : json(nullptr);
    jf["objects"] = json::array();
    for (const auto& o : f.objects) jf["objects"].push_back({{"id", o.id}, {"T_world_object", pose_json(o.T_world_object)}});
    jf["held"] = f.held;
    jf["touched"] = f.touched;
    j["frames"].push_back(jf);
  }
  j["touched"] = intervals_json(t.touched);
  j["held"] = intervals_json(t.held);
  j["manipulations"] = json::array();
  for (const auto& m : t.manipulations) {
    j["manipulations"].push_back({{"object", m.object_id},
                                  {"grasp_frame", m.grasp_frame},
                                  {"release_frame", m.release_frame},
                                  {"dof_range", dof_json(m.dof_range)},
                                  {"moved_dofs", dof_list_json(m.moved)},
                                  {"newly_moved_dofs", dof_list_json(m.newly_moved)}});
  }
  j["frozen_dof_motions"] = json::array();
  for (const auto& fm : t.frozen_dof_motions) {
    json dofs = json::array();
    for (Dof d : fm.dofs) dofs.push_back(to_string(d));
    j["frozen_dof_motions"].push_back({{"object", fm.object_id}, {"manipulation", fm.manipulation},
                                       {"dofs", dofs}, {"first_frame", fm.first_frame}});
  }
  return write_json_atomically(path, j);
}

Result<SequenceTruth> read_ground_truth(const std::filesystem::path& path) {
  auto parsed = read_json(path);
  if (!parsed) return parsed.error();
  const json& j = *parsed;
  const std::string file = path.string();
  try {
    if (get<std::string>(j, "format", file) != kTruthFormat) return invalid_argument(file + ": format is not " + kTruthFormat);
    if (get<int>(j, "version", file) != kVersion) return invalid_argument(file + ": unsupported version");
    SequenceTruth t;
    t.scenario = get<std::string>(j, "scenario", file);
    t.phase = get<std::string>(j, "phase", file);
    t.seed = get<std::uint64_t>(j, "seed", file);
    const json& k = at(j, "intrinsics", file);
    t.intrinsics = {get<double>(k, "fx", file + ".intrinsics"), get<double>(k, "fy", file + ".intrinsics"),
                    get<double>(k, "cx", file + ".intrinsics"), get<double>(k, "cy", file + ".intrinsics"),
                    get<int>(k, "width", file + ".intrinsics"), get<int>(k, "height", file + ".intrinsics")};
    t.T_world_support = pose_from(at(j, "T_world_support", file), file + ".T_world_support");
    const json& th = at(j, "dof_thresholds", file);
    t.thresholds = {get<double>(th, "translation_m", file), get<double>(th, "rotation_deg", file)};
    const json& objects = at(j, "objects", file);
    for (std::size_t i = 0; i < objects.size(); ++i) {
      t.objects.push_back(object_from(objects[i], file + ".objects[" + std::to_string(i) + "]"));
    }
    const json& frames = at(j, "frames", file);
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const std::string w = file + ".frames[" + std::to_string(i) + "]";
      const json& jf = frames[i];
      FrameTruth f;
      f.name = get<std::string>(jf, "name", w);
      f.stamp_s = get<double>(jf, "stamp_s", w);
      f.T_world_camera = pose_from(at(jf, "T_world_camera", w), w + ".T_world_camera");
      f.T_world_camera_reported = pose_from(at(jf, "T_world_camera_reported", w), w + ".T_world_camera_reported");
      if (!at(jf, "T_world_hand", w).is_null()) f.T_world_hand = pose_from(jf["T_world_hand"], w + ".T_world_hand");
      const json& objs = at(jf, "objects", w);
      for (std::size_t o = 0; o < objs.size(); ++o) {
        const std::string wo = w + ".objects[" + std::to_string(o) + "]";
        f.objects.push_back({get<int>(objs[o], "id", wo), pose_from(at(objs[o], "T_world_object", wo), wo)});
      }
      f.held = get<std::vector<int>>(jf, "held", w);
      f.touched = get<std::vector<int>>(jf, "touched", w);
      t.frames.push_back(std::move(f));
    }
    t.touched = intervals_from(at(j, "touched", file), file + ".touched");
    t.held = intervals_from(at(j, "held", file), file + ".held");
    const json& ms = at(j, "manipulations", file);
    for (std::size_t i = 0; i < ms.size(); ++i) {
      const std::string w = file + ".manipulations[" + std::to_string(i) + "]";
      Manipulation m;
      m.object_id = get<int>(ms[i], "object", w);
      m.grasp_frame = get<int>(ms[i], "grasp_frame", w);
      m.release_frame = get<int>(ms[i], "release_frame", w);
      m.dof_range = dof_from(at(ms[i], "dof_range", w), w + ".dof_range");
      m.moved = dof_flags_from(at(ms[i], "moved_dofs", w), w + ".moved_dofs");
      m.newly_moved = dof_flags_from(at(ms[i], "newly_moved_dofs", w), w + ".newly_moved_dofs");
      t.manipulations.push_back(m);
    }
    const json& fms = at(j, "frozen_dof_motions", file);
    for (std::size_t i = 0; i < fms.size(); ++i) {
      const std::string w = file + ".frozen_dof_motions[" + std::to_string(i) + "]";
      FrozenDofMotion fm;
      fm.object_id = get<int>(fms[i], "object", w);
      fm.manipulation = get<int>(fms[i], "manipulation", w);
      fm.first_frame = get<int>(fms[i], "first_frame", w);
      for (const auto& n : at(fms[i], "dofs", w)) fm.dofs.push_back(dof_named(n.get<std::string>(), w));
      t.frozen_dof_motions.push_back(fm);
    }
    return t;
  } catch (const DecodeError& e) {
    return invalid_argument(e.message);
  } catch (const json::exception& e) {
    return invalid_argument(file + ": " + e.what());
  }
}

Status write_changes(const std::filesystem::path& path, const std::string& scenario,
                     const std::vector<ChangeTruth>& changes) {
  json j;
  j["format"] = kChangesFormat;
  j["version"] = kVersion;
  j["scenario"] = scenario;
  j["transitions"] = json::array();
  for (const ChangeTruth& c : changes) {
    json jc;
    jc["from"] = c.from;
    jc["to"] = c.to;
    jc["added"] = json::array();
    for (const auto& p : c.added) jc["added"].push_back({{"object", object_json(p.object)}, {"T_world_object", pose_json(p.T_world_object)}});
    jc["removed"] = json::array();
    for (const auto& p : c.removed) jc["removed"].push_back({{"object", object_json(p.object)}, {"T_world_object", pose_json(p.T_world_object)}});
    jc["moved"] = json::array();
    for (const auto& m : c.moved) {
      jc["moved"].push_back({{"id", m.id},
                             {"T_world_before", pose_json(m.T_world_before)},
                             {"T_world_after", pose_json(m.T_world_after)},
                             {"translation_world_m", vec_json(m.translation_world_m)},
                             {"distance_m", m.translation_world_m.norm()},
                             {"rotation_deg", m.rotation_deg},
                             {"dof_delta", dof_json(m.dof_delta)}});
    }
    j["transitions"].push_back(jc);
  }
  return write_json_atomically(path, j);
}

Result<std::vector<ChangeTruth>> read_changes(const std::filesystem::path& path) {
  auto parsed = read_json(path);
  if (!parsed) return parsed.error();
  const json& j = *parsed;
  const std::string file = path.string();
  try {
    if (get<std::string>(j, "format", file) != kChangesFormat) return invalid_argument(file + ": format is not " + kChangesFormat);
    std::vector<ChangeTruth> out;
    const json& ts = at(j, "transitions", file);
    for (std::size_t i = 0; i < ts.size(); ++i) {
      const std::string w = file + ".transitions[" + std::to_string(i) + "]";
      ChangeTruth c;
      c.from = get<std::string>(ts[i], "from", w);
      c.to = get<std::string>(ts[i], "to", w);
      for (const char* key : {"added", "removed"}) {
        const json& list = at(ts[i], key, w);
        for (std::size_t k = 0; k < list.size(); ++k) {
          const std::string wk = w + "." + key + "[" + std::to_string(k) + "]";
          PlacedObject p{object_from(at(list[k], "object", wk), wk + ".object"),
                         pose_from(at(list[k], "T_world_object", wk), wk + ".T_world_object")};
          (std::string(key) == "added" ? c.added : c.removed).push_back(p);
        }
      }
      const json& moved = at(ts[i], "moved", w);
      for (std::size_t k = 0; k < moved.size(); ++k) {
        const std::string wk = w + ".moved[" + std::to_string(k) + "]";
        ObjectDisplacement d;
        d.id = get<int>(moved[k], "id", wk);
        d.T_world_before = pose_from(at(moved[k], "T_world_before", wk), wk + ".T_world_before");
        d.T_world_after = pose_from(at(moved[k], "T_world_after", wk), wk + ".T_world_after");
        d.translation_world_m = vec_from(at(moved[k], "translation_world_m", wk), wk + ".translation_world_m");
        d.rotation_deg = get<double>(moved[k], "rotation_deg", wk);
        d.dof_delta = dof_from(at(moved[k], "dof_delta", wk), wk + ".dof_delta");
        c.moved.push_back(d);
      }
      out.push_back(std::move(c));
    }
    return out;
  } catch (const DecodeError& e) {
    return invalid_argument(e.message);
  } catch (const json::exception& e) {
    return invalid_argument(file + ": " + e.what());
  }
}

}  // namespace scenewatch::sim
