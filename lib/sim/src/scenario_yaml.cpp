#include "scenewatch/sim/scenario_yaml.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <set>
#include <sstream>

#include "scenewatch/core/yaml_value.h"

namespace scenewatch::sim {
namespace {

struct ParseError {
  std::string message;
};

/// The value, or the error thrown as a ParseError (the reader below unwinds on the first error).
template <typename T>
T or_throw(Result<T> r) {
  if (!r) throw ParseError{r.error().message};
  return std::move(*r);
}
void or_throw(const Status& s) {
  if (!s) throw ParseError{s.error().message};
}

/// A YAML map with its path, read strictly: every key must be one of the allowed ones.
class Map {
 public:
  Map(const YAML::Node& node, std::string path) : node_(node), path_(std::move(path)) {
    if (!node_.IsMap()) fail(path_, "expected a map of keys");
  }

  /// Fails on keys that are not in `allowed`.
  void allow(std::initializer_list<const char*> allowed) const {
    std::set<std::string> ok(allowed.begin(), allowed.end());
    for (const auto& kv : node_) {
      const std::string key = kv.first.as<std::string>();
      if (!ok.count(key)) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        fail(key_path(key), "unknown key (allowed here: " + list + ")");
      }
    }
  }

  bool has(const std::string& key) const { return static_cast<bool>(node_[key]); }
  YAML::Node raw(const std::string& key) const { return node_[key]; }
  std::string key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  Map map(const std::string& key) const {
    if (!has(key)) fail(key_path(key), "missing");
    return Map(node_[key], key_path(key));
  }

  double number(const std::string& key, double fallback) const { return has(key) ? number(key) : fallback; }
  double number(const std::string& key) const {
    const YAML::Node n = required(key);
    return to_number(n, key_path(key));
  }
  double positive(const std::string& key, double fallback) const {
    const double v = number(key, fallback);
    or_throw(yaml::check_positive(v, key_path(key)));
    return v;
  }
  double non_negative(const std::string& key, double fallback) const {
    const double v = number(key, fallback);
    or_throw(yaml::check_non_negative(v, key_path(key)));
    return v;
  }
  int integer(const std::string& key, int fallback) const { return has(key) ? integer(key) : fallback; }
  int integer(const std::string& key) const { return or_throw(yaml::read_integer(required(key), key_path(key))); }
  bool boolean(const std::string& key, bool fallback) const {
    if (!has(key)) return fallback;
    return or_throw(yaml::read_bool(node_[key], key_path(key)));
  }
  std::string string(const std::string& key, const std::string& fallback) const {
    if (!has(key)) return fallback;
    return or_throw(yaml::read_string(node_[key], key_path(key)));
  }
  /// A list of exactly `n` numbers (or, when min_n < n, between min_n and n).
  std::vector<double> numbers(const std::string& key, std::size_t n, std::size_t min_n = 0) const {
    const YAML::Node node = required(key);
    if (min_n == 0) min_n = n;
    if (!node.IsSequence() || node.size() < min_n || node.size() > n) {
      fail(key_path(key), min_n == n ? "expected a list of " + std::to_string(n) + " numbers"
                                     : "expected a list of " + std::to_string(min_n) + " to " + std::to_string(n) + " numbers");
    }
    std::vector<double> v;
    for (std::size_t i = 0; i < node.size(); ++i) v.push_back(to_number(node[i], key_path(key) + "[" + std::to_string(i) + "]"));
    return v;
  }
  Eigen::Vector3d vec3(const std::string& key) const {
    const auto v = numbers(key, 3);
    return {v[0], v[1], v[2]};
  }
  Eigen::Vector3d vec3(const std::string& key, const Eigen::Vector3d& fallback) const {
    return has(key) ? vec3(key) : fallback;
  }
  Eigen::Vector2d vec2(const std::string& key, const Eigen::Vector2d& fallback) const {
    if (!has(key)) return fallback;
    const auto v = numbers(key, 2);
    return {v[0], v[1]};
  }
  /// A list node, each element with its path.
  std::vector<std::pair<YAML::Node, std::string>> list(const std::string& key) const {
    std::vector<std::pair<YAML::Node, std::string>> out;
    if (!has(key)) return out;
    const YAML::Node n = node_[key];
    if (!n.IsSequence()) fail(key_path(key), "expected a list");
    for (std::size_t i = 0; i < n.size(); ++i) out.emplace_back(n[i], key_path(key) + "[" + std::to_string(i) + "]");
    return out;
  }

  [[noreturn]] static void fail(const std::string& where, const std::string& what) {
    throw ParseError{yaml::key_error(where, what).message};
  }

  static double to_number(const YAML::Node& n, const std::string& where) { return or_throw(yaml::read_number(n, where)); }

 private:
  YAML::Node required(const std::string& key) const {
    if (!has(key)) fail(key_path(key), "missing");
    return node_[key];
  }

  YAML::Node node_;
  std::string path_;
};

Eigen::Vector3d color(const Map& m, const std::string& key, const Eigen::Vector3d& fallback) {
  if (!m.has(key)) return fallback;
  const auto v = m.numbers(key, 3);
  for (double c : v) {
    if (c < 0 || c > 255) Map::fail(m.key_path(key), "colour components must be in 0..255");
  }
  return {v[0], v[1], v[2]};
}

TextureKind texture_kind(const std::string& name, const std::string& where) {
  for (TextureKind k : {TextureKind::kNone, TextureKind::kChecker, TextureKind::kStripes, TextureKind::kNoise, TextureKind::kWood}) {
    if (name == to_string(k)) return k;
  }
  Map::fail(where, "unknown texture '" + name + "' (none, checker, stripes, noise, wood)");
}

/// Reads the appearance keys (color, texture, and for objects transparent/opacity) of a map.
void read_appearance(const Map& m, Material* mat, bool allow_glass) {
  mat->color = color(m, "color", mat->color);
  if (m.has("texture")) {
    const YAML::Node t = m.raw("texture");
    if (t.IsScalar()) {
      mat->texture = texture_kind(t.as<std::string>(), m.key_path("texture"));
    } else {
      Map tm(t, m.key_path("texture"));
      tm.allow({"type", "color", "scale_m"});
      mat->texture = texture_kind(tm.string("type", "none"), tm.key_path("type"));
      mat->color2 = color(tm, "color", mat->color2);
      mat->scale_m = tm.positive("scale_m", mat->scale_m);
    }
  }
  if (allow_glass) {
    mat->transparent = m.boolean("transparent", mat->transparent);
    mat->opacity = m.number("opacity", mat->opacity);
    or_throw(yaml::check_in(mat->opacity, 0, 1, m.key_path("opacity")));
  }
}

Material material_map(const YAML::Node& n, const std::string& path, Material fallback) {
  Map m(n, path);
  m.allow({"color", "texture"});
  read_appearance(m, &fallback, false);
  return fallback;
}

/// Pose from position ([x, y]: standing on the support at support_z; [x, y, z]: base at z) and
/// roll/pitch/yaw in degrees.
Pose placement(const Map& m, double support_z) {
  const auto p = m.numbers("position", 3, 2);
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(p[0], p[1], p.size() == 3 ? p[2] : support_z);
  T.linear() = rotation_from_rpy_deg(m.number("roll_deg", 0.0), m.number("pitch_deg", 0.0), m.number("yaw_deg", 0.0));
  return T;
}

SceneObject parse_object(const YAML::Node& n, const std::string& path, double support_z) {
  Map m(n, path);
  SceneObject o;
  o.id = m.integer("id");
  o.name = m.string("name", "object" + std::to_string(o.id));
  const std::string shape = m.string("shape", "");
  const std::initializer_list<const char*> common = {"id", "name", "shape", "color", "texture", "transparent", "opacity",
                                                     "position", "roll_deg", "pitch_deg", "yaw_deg"};
  std::vector<const char*> allowed(common);
  Shape& s = o.shape;
  if (shape == "box") {
    s.kind = ShapeKind::kBox;
    allowed.push_back("size_m");
  } else if (shape == "cylinder") {
    s.kind = ShapeKind::kCylinder;
    for (const char* k : {"radius_m", "height_m", "open_top", "wall_m"}) allowed.push_back(k);
  } else if (shape == "cone" || shape == "frustum") {
    s.kind = ShapeKind::kFrustum;
    for (const char* k : {"radius_m", "height_m", "open_top", "wall_m"}) allowed.push_back(k);
    if (shape == "frustum") allowed.push_back("top_radius_m");
  } else if (shape == "sphere") {
    s.kind = ShapeKind::kSphere;
    allowed.push_back("radius_m");
  } else {
    Map::fail(m.key_path("shape"), shape.empty() ? "missing (box, cylinder, cone, frustum, sphere)"
                                                  : "unknown shape '" + shape + "' (box, cylinder, cone, frustum, sphere)");
  }
  {
    std::set<std::string> ok(allowed.begin(), allowed.end());
    for (const auto& kv : n) {
      const std::string key = kv.first.as<std::string>();
      if (!ok.count(key)) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        Map::fail(m.key_path(key), "not a key of a " + shape + " (allowed: " + list + ")");
      }
    }
  }
  switch (s.kind) {
    case ShapeKind::kBox: {
      const auto v = m.numbers("size_m", 3);
      s.size_m = Eigen::Vector3d(v[0], v[1], v[2]);
      break;
    }
    case ShapeKind::kCylinder:
    case ShapeKind::kFrustum:
      s.radius_m = m.number("radius_m");
      s.height_m = m.number("height_m");
      s.top_radius_m = shape == "cone" ? 0.0 : (shape == "frustum" ? m.number("top_radius_m") : s.radius_m);
      s.open_top = m.boolean("open_top", false);
      s.wall_m = m.number("wall_m", s.wall_m);
      break;
    case ShapeKind::kSphere:
      s.radius_m = m.number("radius_m");
      break;
    case ShapeKind::kCapsule:
      break;
  }
  read_appearance(m, &o.material, true);
  o.T_world_object = placement(m, support_z);
  return o;
}

CameraPath parse_camera(const YAML::Node& n, const std::string& path) {
  Map m(n, path);
  CameraPath c;
  const std::string type = m.string("type", "static");
  if (type == "static") {
    m.allow({"type", "position", "target"});
    c.kind = CameraPathKind::kStatic;
    c.position_world = m.vec3("position");
    c.target_world = m.vec3("target", c.target_world);
  } else if (type == "circle") {
    m.allow({"type", "target", "radius_m", "height_m", "start_deg", "arc_deg", "wobble_m", "wobble_cycles"});
    c.kind = CameraPathKind::kCircle;
    c.target_world = m.vec3("target", c.target_world);
    c.radius_m = m.positive("radius_m", c.radius_m);
    c.height_m = m.number("height_m", c.height_m);
    c.start_deg = m.number("start_deg", c.start_deg);
    c.arc_deg = m.number("arc_deg", c.arc_deg);
    c.wobble_m = m.number("wobble_m", c.wobble_m);
    c.wobble_cycles = m.number("wobble_cycles", c.wobble_cycles);
  } else if (type == "handheld") {
    m.allow({"type", "position", "target", "shake_m", "shake_deg"});
    c.kind = CameraPathKind::kHandheld;
    c.position_world = m.vec3("position");
    c.target_world = m.vec3("target", c.target_world);
    c.shake_m = m.non_negative("shake_m", c.shake_m);
    c.shake_deg = m.non_negative("shake_deg", c.shake_deg);
  } else if (type == "keyframes") {
    m.allow({"type", "keys"});
    c.kind = CameraPathKind::kKeyframes;
    for (const auto& [kn, kp] : m.list("keys")) {
      Map k(kn, kp);
      k.allow({"frame", "position", "target"});
      c.keys.push_back({k.number("frame"), k.vec3("position"), k.vec3("target")});
      if (c.keys.size() > 1 && c.keys.back().frame < c.keys[c.keys.size() - 2].frame) {
        Map::fail(k.key_path("frame"), "keys must be in time order");
      }
    }
    if (c.keys.empty()) Map::fail(m.key_path("keys"), "a keyframed camera needs at least one key");
  } else {
    Map::fail(m.key_path("type"), "unknown camera type '" + type + "' (static, circle, handheld, keyframes)");
  }
  return c;
}

HandSpec parse_hand(const YAML::Node& n, const std::string& path) {
  Map m(n, path);
  m.allow({"skin", "scale", "keys"});
  HandSpec h;
  if (m.has("skin")) h.skin = material_map(m.raw("skin"), m.key_path("skin"), h.skin);
  h.scale = m.positive("scale", h.scale);
  for (const auto& [kn, kp] : m.list("keys")) {
    Map k(kn, kp);
    k.allow({"frame", "position", "roll_deg", "pitch_deg", "yaw_deg", "grasp", "release"});
    HandKey key;
    key.frame = k.number("frame");
    key.position_world = k.vec3("position");
    key.roll_deg = k.number("roll_deg", 0.0);
    key.pitch_deg = k.number("pitch_deg", 0.0);
    key.yaw_deg = k.number("yaw_deg", 0.0);
    key.grasp_id = k.integer("grasp", 0);
    key.release_id = k.integer("release", 0);
    if (!h.keys.empty() && key.frame < h.keys.back().frame) Map::fail(k.key_path("frame"), "keys must be in time order");
    h.keys.push_back(key);
  }
  return h;
}

SceneChanges parse_changes(const YAML::Node& n, const std::string& path, double support_z) {
  Map m(n, path);
  m.allow({"remove", "add", "move"});
  SceneChanges c;
  for (const auto& [rn, rp] : m.list("remove")) c.remove.push_back(static_cast<int>(Map::to_number(rn, rp)));
  for (const auto& [an, ap] : m.list("add")) c.add.push_back(parse_object(an, ap, support_z));
  for (const auto& [mn, mp] : m.list("move")) {
    Map mv(mn, mp);
    mv.allow({"id", "position", "roll_deg", "pitch_deg", "yaw_deg"});
    c.move.push_back({mv.integer("id"), placement(mv, support_z)});
  }
  return c;
}

/// A phase from an entry of `phases`, or from the top level of a single-phase scenario (whose
/// `name` is the scenario's, so the phase keeps the name "main").
PhaseSpec parse_phase(const Map& m, double support_z, bool changes_allowed, bool top_level) {
  PhaseSpec p;
  if (!top_level) p.name = m.string("name", p.name);
  p.frames = m.integer("frames", 1);
  if (p.frames < 1) Map::fail(m.key_path("frames"), "must be at least 1");
  if (!m.has("camera")) Map::fail(m.key_path("camera"), "missing");
  p.camera = parse_camera(m.raw("camera"), m.key_path("camera"));
  if (m.has("hand")) p.hand = parse_hand(m.raw("hand"), m.key_path("hand"));
  if (changes_allowed && m.has("changes")) p.changes = parse_changes(m.raw("changes"), m.key_path("changes"), support_z);
  return p;
}

SensorConfig parse_sensor(const YAML::Node& n, const std::string& path) {
  Map m(n, path);
  m.allow({"noise", "depth_sigma_base_m", "depth_sigma_quad", "depth_sigma_offset_m", "baseline_m", "disparity_step_px",
           "min_depth_m", "max_depth_m", "grazing_start_deg", "grazing_end_deg", "transparent_depth", "color_sigma",
           "pose_sigma_m", "pose_sigma_deg"});
  SensorConfig s;
  s.noise = m.boolean("noise", s.noise);
  s.depth_sigma_base_m = m.non_negative("depth_sigma_base_m", s.depth_sigma_base_m);
  s.depth_sigma_quad = m.non_negative("depth_sigma_quad", s.depth_sigma_quad);
  s.depth_sigma_offset_m = m.number("depth_sigma_offset_m", s.depth_sigma_offset_m);
  s.baseline_m = m.non_negative("baseline_m", s.baseline_m);
  s.disparity_step_px = m.non_negative("disparity_step_px", s.disparity_step_px);
  s.min_depth_m = m.non_negative("min_depth_m", s.min_depth_m);
  s.max_depth_m = m.positive("max_depth_m", s.max_depth_m);
  if (s.max_depth_m <= s.min_depth_m) Map::fail(m.key_path("max_depth_m"), "must exceed min_depth_m");
  if (s.max_depth_m > 65.0) Map::fail(m.key_path("max_depth_m"), "must be at most 65 m (16-bit millimetres)");
  s.grazing_start_deg = m.number("grazing_start_deg", s.grazing_start_deg);
  s.grazing_end_deg = m.number("grazing_end_deg", s.grazing_end_deg);
  if (!(s.grazing_start_deg >= 0 && s.grazing_start_deg < s.grazing_end_deg && s.grazing_end_deg <= 90)) {
    Map::fail(m.key_path("grazing_end_deg"), "need 0 <= grazing_start_deg < grazing_end_deg <= 90");
  }
  const std::string td = m.string("transparent_depth", "hole");
  if (td == "hole") s.transparent_depth = TransparentDepth::kHole;
  else if (td == "behind") s.transparent_depth = TransparentDepth::kBehind;
  else Map::fail(m.key_path("transparent_depth"), "expected hole or behind");
  s.color_sigma = m.non_negative("color_sigma", s.color_sigma);
  s.pose_sigma_m = m.non_negative("pose_sigma_m", s.pose_sigma_m);
  s.pose_sigma_deg = m.non_negative("pose_sigma_deg", s.pose_sigma_deg);
  return s;
}

Scenario parse(const YAML::Node& root) {
  Map m(root, "");
  m.allow({"name", "description", "seed", "intrinsics", "frame_rate_hz", "room", "lighting", "table", "objects", "sensor",
           "ground_truth", "phases", "frames", "camera", "hand"});
  Scenario sc;
  sc.name = m.string("name", "");
  sc.description = m.string("description", "");
  if (m.has("seed")) {
    const double seed = m.number("seed");
    if (seed < 0 || seed != std::floor(seed) || seed > 9.0e15) Map::fail("seed", "expected a non-negative integer");
    sc.seed = static_cast<std::uint64_t>(seed);
  }
  if (m.has("intrinsics")) {
    Map k = m.map("intrinsics");
    k.allow({"width", "height", "fx", "fy", "cx", "cy"});
    Intrinsics& K = sc.intrinsics;
    K.width = k.integer("width", K.width);
    K.height = k.integer("height", K.height);
    or_throw(yaml::check_in(K.width, 1, 8192, "intrinsics.width"));
    or_throw(yaml::check_in(K.height, 1, 8192, "intrinsics.height"));
    K.fx = k.positive("fx", 525.0 * K.width / 640.0);
    K.fy = k.positive("fy", K.fx);
    K.cx = k.number("cx", 0.5 * (K.width - 1));
    K.cy = k.number("cy", 0.5 * (K.height - 1));
  }
  sc.frame_rate_hz = m.positive("frame_rate_hz", sc.frame_rate_hz);
  if (m.has("room")) {
    Map r = m.map("room");
    r.allow({"size_m", "center", "floor", "walls", "ceiling"});
    const Eigen::Vector3d size = r.vec3("size_m", sc.room.max_world - sc.room.min_world);
    if (size.minCoeff() <= 0) Map::fail("room.size_m", "sides must be positive");
    const Eigen::Vector2d c = r.vec2("center", Eigen::Vector2d::Zero());
    sc.room.min_world = Eigen::Vector3d(c.x() - 0.5 * size.x(), c.y() - 0.5 * size.y(), 0.0);
    sc.room.max_world = Eigen::Vector3d(c.x() + 0.5 * size.x(), c.y() + 0.5 * size.y(), size.z());
    if (r.has("floor")) sc.room.floor = material_map(r.raw("floor"), "room.floor", sc.room.floor);
    if (r.has("walls")) sc.room.walls = material_map(r.raw("walls"), "room.walls", sc.room.walls);
    if (r.has("ceiling")) sc.room.ceiling = material_map(r.raw("ceiling"), "room.ceiling", sc.room.ceiling);
  }
  if (m.has("lighting")) {
    Map l = m.map("lighting");
    l.allow({"direction", "ambient", "diffuse"});
    const Eigen::Vector3d d = l.vec3("direction", sc.lighting.towards_light_world);
    if (d.norm() <= 0) Map::fail("lighting.direction", "must not be zero");
    sc.lighting.towards_light_world = d.normalized();
    sc.lighting.ambient = l.non_negative("ambient", sc.lighting.ambient);
    sc.lighting.diffuse = l.non_negative("diffuse", sc.lighting.diffuse);
  }
  if (m.has("table")) {
    Map t = m.map("table");
    t.allow({"present", "center", "yaw_deg", "size_m", "height_m", "thickness_m", "leg_radius_m", "leg_inset_m", "top", "legs"});
    TableSpec& tb = sc.table;
    tb.present = t.boolean("present", tb.present);
    tb.center_world = t.vec2("center", tb.center_world);
    tb.yaw_deg = t.number("yaw_deg", tb.yaw_deg);
    tb.size_m = t.vec2("size_m", tb.size_m);
    tb.height_m = t.positive("height_m", tb.height_m);
    tb.thickness_m = t.positive("thickness_m", tb.thickness_m);
    tb.leg_radius_m = t.positive("leg_radius_m", tb.leg_radius_m);
    tb.leg_inset_m = t.non_negative("leg_inset_m", tb.leg_inset_m);
    if (t.has("top")) tb.top = material_map(t.raw("top"), "table.top", tb.top);
    if (t.has("legs")) tb.legs = material_map(t.raw("legs"), "table.legs", tb.legs);
  }
  const double support_z = sc.table.present ? sc.table.height_m : 0.0;
  for (const auto& [on, op] : m.list("objects")) sc.objects.push_back(parse_object(on, op, support_z));
  if (m.has("sensor")) sc.sensor = parse_sensor(m.raw("sensor"), "sensor");
  if (m.has("ground_truth")) {
    Map g = m.map("ground_truth");
    g.allow({"dof_translation_m", "dof_rotation_deg", "touch_tolerance_m"});
    sc.dof_thresholds.translation_m = g.positive("dof_translation_m", sc.dof_thresholds.translation_m);
    sc.dof_thresholds.rotation_deg = g.positive("dof_rotation_deg", sc.dof_thresholds.rotation_deg);
    sc.touch_tolerance_m = g.non_negative("touch_tolerance_m", sc.touch_tolerance_m);
  }
  const bool single = m.has("frames") || m.has("camera") || m.has("hand");
  if (m.has("phases")) {
    if (single) Map::fail("phases", "give either phases or frames/camera/hand at the top level, not both");
    std::set<std::string> names;
    for (const auto& [pn, pp] : m.list("phases")) {
      Map p(pn, pp);
      const bool first = sc.phases.empty();
      if (first) p.allow({"name", "frames", "camera", "hand"});
      else p.allow({"name", "frames", "camera", "hand", "changes"});
      PhaseSpec ph = parse_phase(p, support_z, !first, false);
      if (ph.name.empty() || ph.name.find('/') != std::string::npos || ph.name == "." || ph.name == "..") {
        Map::fail(p.key_path("name"), "must be a plain folder name");
      }
      if (!names.insert(ph.name).second) Map::fail(p.key_path("name"), "duplicate phase name '" + ph.name + "'");
      sc.phases.push_back(std::move(ph));
    }
    if (sc.phases.empty()) Map::fail("phases", "needs at least one phase");
  } else {
    sc.phases.push_back(parse_phase(m, support_z, false, true));
  }
  return sc;
}

}  // namespace

Result<Scenario> parse_scenario(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    return invalid_argument(source + ": not valid YAML: " + e.what());
  }
  try {
    Scenario sc = parse(root);
    if (auto st = validate(sc); !st) return invalid_argument(source + ": " + st.error().message);
    return sc;
  } catch (const ParseError& e) {
    return invalid_argument(source + ": " + e.message);
  } catch (const YAML::Exception& e) {
    return invalid_argument(source + ": " + e.what());
  }
}

Result<Scenario> load_scenario(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return not_found(path.string() + ": cannot open the scenario file");
  std::stringstream ss;
  ss << in.rdbuf();
  auto sc = parse_scenario(ss.str(), path.string());
  if (sc && sc->name.empty()) sc->name = path.stem().string();
  return sc;
}

}  // namespace scenewatch::sim
