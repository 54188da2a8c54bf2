// Object classes in YAML: strict parsing (unknown keys and wrong types are errors naming the
// field) and emitting back.
#include "scenewatch/ontology/class_library.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <set>
#include <sstream>

#include "scenewatch/core/yaml_value.h"

namespace scenewatch::ontology {
namespace {

/// Reads the keys of one YAML map, remembering which were read so that the rest are errors.
class Fields {
 public:
  Fields(const YAML::Node& node, std::string path) : node_(node), path_(std::move(path)) {}

  Status is_map() const {
    if (!node_.IsMap()) return yaml::key_error(path_, "expected a map");
    return {};
  }
  std::string path(const std::string& key) const { return path_ + "." + key; }
  YAML::Node get(const std::string& key) {
    read_.insert(key);
    return node_[key];
  }
  Status number(const std::string& key, double& out) {
    const YAML::Node v = get(key);
    if (!v) return {};
    // Any number yaml-cpp reads, .inf and .nan too (validate() bounds the fields that need it).
    const auto number = yaml::read_number(v, path(key), yaml::Finite::kAny);
    if (!number) return number.error();
    out = *number;
    return {};
  }
  Status text(const std::string& key, std::string& out, bool required = false) {
    const YAML::Node v = get(key);
    if (!v) return required ? Status(yaml::key_error(path(key), "required")) : Status();
    const auto s = yaml::read_string(v, path(key));
    if (!s) return s.error();
    out = *s;
    return {};
  }
  Status range(const std::string& key, Range& out, bool required) {
    const YAML::Node v = get(key);
    if (!v) return required ? Status(yaml::key_error(path(key), "required ([min, max])")) : Status();
    return parse_range(v, path(key), out);
  }
  Status finish() const {
    for (const auto& kv : node_) {
      if (!kv.first.IsScalar()) return invalid_argument(path_ + ": a key is not a plain name");
      const std::string key = kv.first.as<std::string>();
      if (!read_.count(key)) return yaml::key_error(path(key), "unknown key");
    }
    return {};
  }

  static Status parse_range(const YAML::Node& v, const std::string& where, Range& out) {
    if (!v.IsSequence() || v.size() != 2) return yaml::key_error(where, "expected [min, max]");
    for (std::size_t i = 0; i < 2; ++i) {
      const auto bound = yaml::read_number(v[i], where, yaml::Finite::kAny);
      if (!bound) return yaml::key_error(where, "expected two numbers [min, max]");
      (i == 0 ? out.min : out.max) = *bound;
    }
    return {};
  }

 private:
  YAML::Node node_;
  std::string path_;
  std::set<std::string> read_;
};

template <typename Enum, std::size_t N>
Status parse_enum(Fields& f, const std::string& key, const char* const (&names)[N], const Enum (&values)[N], Enum& out) {
  std::string s;
  if (Status st = f.text(key, s); !st) return st;
  if (s.empty()) return {};
  std::string all;
  for (std::size_t i = 0; i < N; ++i) {
    if (s == names[i]) {
      out = values[i];
      return {};
    }
    all += (i ? ", " : "") + std::string(names[i]);
  }
  return invalid_argument(f.path(key) + ": '" + s + "' is not one of " + all);
}

Status parse_class(const YAML::Node& node, const std::string& where, ObjectClass& c) {
  Fields f(node, where);
  if (Status s = f.is_map(); !s) return s;
  if (Status s = f.text("name", c.name, true); !s) return s;
  Fields named(node, where + " (" + c.name + ")");
  named.get("name");
  static const char* const kShapes[] = {"cylinder", "frustum", "sphere", "box"};
  static const ClassShape kShapeValues[] = {ClassShape::kCylinder, ClassShape::kFrustum, ClassShape::kSphere, ClassShape::kBox};
  if (!node["shape"]) return invalid_argument(named.path("shape") + ": required (cylinder, frustum, sphere or box)");
  if (Status s = parse_enum(named, "shape", kShapes, kShapeValues, c.shape); !s) return s;
  const bool round = c.shape != ClassShape::kBox;
  if (Status s = named.range("radius_m", c.radius_m, round); !s) return s;
  if (Status s = named.range("height_m", c.height_m, c.shape != ClassShape::kSphere); !s) return s;
  if (Status s = named.range("taper_deg", c.taper_deg, c.shape == ClassShape::kFrustum); !s) return s;
  if (const YAML::Node v = named.get("size_m")) {
    if (!v.IsSequence()) return invalid_argument(named.path("size_m") + ": expected [[min, max], [min, max]]");
    c.size_m.resize(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (Status s = Fields::parse_range(v[i], named.path("size_m") + "[" + std::to_string(i) + "]", c.size_m[i]); !s) return s;
    }
  }
  static const char* const kAxes[] = {"any", "upright"};
  static const ClassAxis kAxisValues[] = {ClassAxis::kAny, ClassAxis::kUpright};
  if (Status s = parse_enum(named, "axis", kAxes, kAxisValues, c.axis); !s) return s;
  if (Status s = named.number("axis_tolerance_deg", c.axis_tolerance_deg); !s) return s;
  static const char* const kTops[] = {"any", "open", "closed"};
  static const ClassTop kTopValues[] = {ClassTop::kAny, ClassTop::kOpen, ClassTop::kClosed};
  if (Status s = parse_enum(named, "top", kTops, kTopValues, c.top); !s) return s;
  if (Status s = named.number("max_rms_m", c.max_rms_m); !s) return s;
  if (Status s = named.number("min_explained", c.min_explained); !s) return s;
  if (Status s = named.number("min_coverage_deg", c.min_coverage_deg); !s) return s;
  if (Status s = named.text("description", c.description); !s) return s;
  if (const YAML::Node v = named.get("grasps")) {
    if (!v.IsSequence()) return invalid_argument(named.path("grasps") + ": expected a list");
    for (std::size_t i = 0; i < v.size(); ++i) {
      Fields g(v[i], named.path("grasps") + "[" + std::to_string(i) + "]");
      if (Status s = g.is_map(); !s) return s;
      GraspDefinition def;
      if (Status s = g.text("name", def.name, true); !s) return s;
      static const char* const kKinds[] = {"side", "rim", "top"};
      static const GraspKind kKindValues[] = {GraspKind::kSide, GraspKind::kRim, GraspKind::kTop};
      if (!v[i]["kind"]) return invalid_argument(g.path("kind") + ": required (side, rim or top)");
      if (Status s = parse_enum(g, "kind", kKinds, kKindValues, def.kind); !s) return s;
      if (Status s = g.number("height_fraction", def.height_fraction); !s) return s;
      if (Status s = g.finish(); !s) return s;
      c.grasps.push_back(def);
    }
  }
  if (const YAML::Node v = named.get("allowed_dofs")) {
    if (!v.IsSequence()) return invalid_argument(named.path("allowed_dofs") + ": expected a list of x, y, z, roll, pitch, yaw");
    for (std::size_t i = 0; i < v.size(); ++i) {
      auto dof = yaml::read_string(v[i], named.path("allowed_dofs") + "[" + std::to_string(i) + "]");
      if (!dof) return dof.error();
      c.allowed_dofs.push_back(*dof);
    }
  }
  if (Status s = named.finish(); !s) return s;
  if (Status s = validate(c); !s) return invalid_argument(where + ": " + s.error().message);
  return {};
}

void emit_range(YAML::Emitter& out, const char* key, const Range& r) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq << r.min << r.max << YAML::EndSeq;
}

void emit_class(YAML::Emitter& out, const ObjectClass& c) {
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << c.name;
  out << YAML::Key << "shape" << YAML::Value << to_string(c.shape);
  if (c.shape != ClassShape::kBox) emit_range(out, "radius_m", c.radius_m);
  if (c.shape != ClassShape::kSphere) emit_range(out, "height_m", c.height_m);
  if (c.shape == ClassShape::kFrustum) emit_range(out, "taper_deg", c.taper_deg);
  if (c.shape == ClassShape::kBox) {
    out << YAML::Key << "size_m" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const Range& r : c.size_m) out << YAML::Flow << YAML::BeginSeq << r.min << r.max << YAML::EndSeq;
    out << YAML::EndSeq;
  }
  out << YAML::Key << "axis" << YAML::Value << (c.axis == ClassAxis::kUpright ? "upright" : "any");
  out << YAML::Key << "axis_tolerance_deg" << YAML::Value << c.axis_tolerance_deg;
  out << YAML::Key << "top" << YAML::Value << (c.top == ClassTop::kOpen ? "open" : c.top == ClassTop::kClosed ? "closed" : "any");
  out << YAML::Key << "max_rms_m" << YAML::Value << c.max_rms_m;
  out << YAML::Key << "min_explained" << YAML::Value << c.min_explained;
  out << YAML::Key << "min_coverage_deg" << YAML::Value << c.min_coverage_deg;
  out << YAML::Key << "grasps" << YAML::Value << YAML::BeginSeq;
  for (const GraspDefinition& g : c.grasps) {
    out << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << g.name << YAML::Key << "kind" << YAML::Value
        << to_string(g.kind) << YAML::Key << "height_fraction" << YAML::Value << g.height_fraction << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "allowed_dofs" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const auto& d : c.allowed_dofs) out << d;
  out << YAML::EndSeq;
  if (!c.description.empty()) out << YAML::Key << "description" << YAML::Value << c.description;
  out << YAML::EndMap;
}

}  // namespace

Status ClassLibrary::define(const ObjectClass& object_class) {
  if (Status s = validate(object_class); !s) return s;
  for (auto& c : classes_) {
    if (c.name == object_class.name) {
      c = object_class;
      return {};
    }
  }
  classes_.push_back(object_class);
  return {};
}

const ObjectClass* ClassLibrary::find(const std::string& name) const {
  for (const auto& c : classes_)
    if (c.name == name) return &c;
  return nullptr;
}

Result<ClassLibrary> parse_classes(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    return invalid_argument(source + ": not valid YAML: " + e.what());
  }
  Fields top(root, source);
  if (Status s = top.is_map(); !s) return invalid_argument(source + ": expected a map with the key 'classes'");
  const YAML::Node list = top.get("classes");
  if (Status s = top.finish(); !s) return invalid_argument(source + ": " + s.error().message.substr(source.size() + 1));
  if (!list || !list.IsSequence()) return invalid_argument(source + ": classes: expected a list of classes");
  ClassLibrary library;
  for (std::size_t i = 0; i < list.size(); ++i) {
    ObjectClass c;
    if (Status s = parse_class(list[i], source + ": classes[" + std::to_string(i) + "]", c); !s) return s.error();
    if (library.find(c.name)) return invalid_argument(source + ": classes[" + std::to_string(i) + "]: the name '" + c.name + "' is used twice");
    if (Status s = library.define(c); !s) return s.error();
  }
  return library;
}

Result<ClassLibrary> load_classes_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return not_found(path.string() + ": cannot open the classes file");
  std::stringstream text;
  text << in.rdbuf();
  return parse_classes(text.str(), path.string());
}

std::string to_yaml(const ObjectClass& object_class) {
  YAML::Emitter out;
  out.SetDoublePrecision(10);
  emit_class(out, object_class);
  return out.c_str();
}

std::string to_yaml(const std::vector<ObjectClass>& classes) {
  YAML::Emitter out;
  out.SetDoublePrecision(10);
  out << YAML::BeginMap << YAML::Key << "classes" << YAML::Value << YAML::BeginSeq;
  for (const auto& c : classes) emit_class(out, c);
  out << YAML::EndSeq << YAML::EndMap;
  return out.c_str();
}

}  // namespace scenewatch::ontology
