#include "scenewatch/core/yaml_value.h"

#include <cmath>
#include <sstream>

namespace scenewatch::yaml {

Error key_error(const std::string& key_path, const std::string& what) { return invalid_argument(key_path + ": " + what); }

Result<double> read_number(const YAML::Node& node, const std::string& key_path, Finite finite) {
  double v = 0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, v) || (finite == Finite::kRequired && !std::isfinite(v))) {
    return key_error(key_path, "expected a number");
  }
  return v;
}

Result<int> read_integer(const YAML::Node& node, const std::string& key_path) {
  const auto v = read_number(node, key_path);
  if (!v) return v.error();
  if (*v != std::floor(*v) || std::abs(*v) > 1e9) return key_error(key_path, "expected an integer");
  return static_cast<int>(*v);
}

Result<bool> read_bool(const YAML::Node& node, const std::string& key_path) {
  bool v = false;
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, v)) return key_error(key_path, "expected true or false");
  return v;
}

Result<std::string> read_string(const YAML::Node& node, const std::string& key_path) {
  if (!node.IsScalar()) return key_error(key_path, "expected a string");
  return node.as<std::string>();
}

Result<std::string> read_key(const YAML::Node& key, const std::string& where) {
  if (key.IsScalar()) return key.Scalar();
  // Converting such a key to a string threw out of the config reader and ended the daemon (found
  // by fuzz_config); write it back as flow YAML for the message instead.
  YAML::Emitter flow;
  flow << YAML::Flow << key;
  return key_error(where, "a key must be a plain name, got '" + std::string(flow.c_str()) + "'");
}

Status check_positive(double v, const std::string& key_path) {
  if (!(v > 0)) return key_error(key_path, "must be positive");
  return {};
}

Status check_non_negative(double v, const std::string& key_path) {
  if (!(v >= 0)) return key_error(key_path, "must not be negative");
  return {};
}

Status check_in(double v, double lo, double hi, const std::string& key_path) {
  if (!(v < lo || v > hi)) return {};
  std::ostringstream range;  // as %g writes them: "0..1", "1..8192"
  range << lo << ".." << hi;
  return key_error(key_path, "must be in " + range.str());
}

}  // namespace scenewatch::yaml
