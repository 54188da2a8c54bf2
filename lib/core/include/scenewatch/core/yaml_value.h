#pragma once
/// Typed values of a YAML file read into structs, with the checks every hand-written reader makes
/// (the simulator's scenarios, the ontology's classes, the pipeline's config): each error is
/// "<key path>: <what>", the key's dotted path first ("objects[0].radius_m: expected a number").
/// yaml-cpp is linked by the modules that read YAML; include this only from them.
#include <yaml-cpp/yaml.h>

#include <string>

#include "scenewatch/core/result.h"

namespace scenewatch::yaml {

/// The error of a key: "<key_path>: <what>".
Error key_error(const std::string& key_path, const std::string& what);

/// Whether a number may be infinite or NaN.
enum class Finite { kRequired, kAny };

/// A scalar number ("expected a number" otherwise; also when not finite, unless kAny).
Result<double> read_number(const YAML::Node& node, const std::string& key_path, Finite finite = Finite::kRequired);
/// A whole number of at most 1e9 in magnitude, written as a number ("expected an integer").
Result<int> read_integer(const YAML::Node& node, const std::string& key_path);
/// true or false, yes or no, ... ("expected true or false").
Result<bool> read_bool(const YAML::Node& node, const std::string& key_path);
/// A scalar as text ("expected a string").
Result<std::string> read_string(const YAML::Node& node, const std::string& key_path);

/// Any type yaml-cpp converts to (numbers, booleans, strings, lists of them), accepted exactly as
/// YAML::Node::as<T> accepts it; "cannot read value '<the value as YAML>'" otherwise. The
/// pipeline's config reader reads every key this way (its users have always seen these words).
template <typename T>
Result<T> read_value(const YAML::Node& node, const std::string& key_path) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    return key_error(key_path, "cannot read value '" + YAML::Dump(node) + "'");
  }
}

/// A mapping key as text. YAML allows any node as a key (`? [a, b]: 1`), which is an error at
/// `where`: "<where>: a key must be a plain name, got '[a, b]'".
Result<std::string> read_key(const YAML::Node& key, const std::string& where);

/// v > 0 ("must be positive").
Status check_positive(double v, const std::string& key_path);
/// v >= 0 ("must not be negative").
Status check_non_negative(double v, const std::string& key_path);
/// lo <= v <= hi ("must be in lo..hi", the bounds as std::ostream writes them: "0..1").
Status check_in(double v, double lo, double hi, const std::string& key_path);

}  // namespace scenewatch::yaml
