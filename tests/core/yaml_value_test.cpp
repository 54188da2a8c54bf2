// The typed YAML values (yaml_value.h) the hand-written readers share: each error names the key's
// path and says what was expected, in the words the scenario and class readers always used.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "scenewatch/core/yaml_value.h"

namespace scenewatch::yaml {
namespace {

std::string message_of(const Status& s) { return s ? "" : s.error().message; }
template <typename T>
std::string message_of(const Result<T>& r) {
  return r ? "" : r.error().message;
}

TEST(YamlValue, NumbersAreFiniteScalarsUnlessAnyIsAsked) {
  EXPECT_EQ(*read_number(YAML::Load("0.25"), "a.b"), 0.25);
  EXPECT_EQ(message_of(read_number(YAML::Load("big"), "a.b")), "a.b: expected a number");
  EXPECT_EQ(message_of(read_number(YAML::Load("[1, 2]"), "a.b")), "a.b: expected a number");
  EXPECT_EQ(message_of(read_number(YAML::Load("~"), "a.b")), "a.b: expected a number");
  EXPECT_EQ(message_of(read_number(YAML::Load(".inf"), "a.b")), "a.b: expected a number");
  EXPECT_TRUE(std::isinf(*read_number(YAML::Load(".inf"), "a.b", Finite::kAny)));
  EXPECT_EQ(message_of(read_number(YAML::Load("big"), "a.b", Finite::kAny)), "a.b: expected a number");
}

TEST(YamlValue, IntegersBoolsAndStrings) {
  EXPECT_EQ(*read_integer(YAML::Load("12"), "k"), 12);
  EXPECT_EQ(message_of(read_integer(YAML::Load("1.5"), "k")), "k: expected an integer");
  EXPECT_EQ(message_of(read_integer(YAML::Load("2e9"), "k")), "k: expected an integer");
  EXPECT_EQ(message_of(read_integer(YAML::Load("two"), "k")), "k: expected a number");
  EXPECT_TRUE(*read_bool(YAML::Load("yes"), "k"));
  EXPECT_EQ(message_of(read_bool(YAML::Load("maybe"), "k")), "k: expected true or false");
  EXPECT_EQ(*read_string(YAML::Load("cup"), "k"), "cup");
  EXPECT_EQ(message_of(read_string(YAML::Load("[a]"), "k")), "k: expected a string");
}

TEST(YamlValue, RangeChecksNameTheKey) {
  EXPECT_TRUE(check_positive(0.1, "k").ok());
  EXPECT_EQ(message_of(check_positive(0, "k")), "k: must be positive");
  EXPECT_EQ(message_of(check_positive(std::nan(""), "k")), "k: must be positive");
  EXPECT_TRUE(check_non_negative(0, "k").ok());
  EXPECT_EQ(message_of(check_non_negative(-1, "k")), "k: must not be negative");
  EXPECT_TRUE(check_in(1, 0, 1, "k").ok());
  EXPECT_EQ(message_of(check_in(1.5, 0, 1, "opacity")), "opacity: must be in 0..1");
  EXPECT_EQ(message_of(check_in(9000, 1, 8192, "intrinsics.width")), "intrinsics.width: must be in 1..8192");
  EXPECT_EQ(message_of(key_error("x.y", "unknown key")), "x.y: unknown key");
}

TEST(YamlValue, AnyValueAsYamlCppReadsIt) {
  EXPECT_EQ(*read_value<double>(YAML::Load("0.25"), "a.b"), 0.25);
  EXPECT_TRUE(std::isinf(*read_value<double>(YAML::Load(".inf"), "a.b")));  // as<double> takes it
  EXPECT_EQ(*read_value<unsigned>(YAML::Load("7"), "a.b"), 7u);
  EXPECT_EQ((*read_value<std::vector<double>>(YAML::Load("[0, 0, 1]"), "a.b")).size(), 3u);
  EXPECT_EQ(message_of(read_value<double>(YAML::Load("fast"), "a.b")), "a.b: cannot read value 'fast'");
  EXPECT_EQ(message_of(read_value<int>(YAML::Load("1.5"), "a.b")), "a.b: cannot read value '1.5'");
  EXPECT_EQ(message_of(read_value<bool>(YAML::Load("maybe"), "a.b")), "a.b: cannot read value 'maybe'");
  EXPECT_EQ(message_of(read_value<double>(YAML::Load("[1, 2]"), "a.b")), "a.b: cannot read value '[1, 2]'");
}

TEST(YamlValue, KeysArePlainNames) {
  const YAML::Node map = YAML::Load("{plain: 1, [a, b]: 2}");
  std::vector<std::string> got;
  for (const auto& kv : map) {
    const auto key = read_key(kv.first, "section");
    got.push_back(key ? *key : key.error().message);
  }
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0], "plain");
  EXPECT_EQ(got[1], "section: a key must be a plain name, got '[a, b]'");
}

}  // namespace
}  // namespace scenewatch::yaml
