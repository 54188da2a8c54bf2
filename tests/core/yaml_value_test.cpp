// The typed YAML values (yaml_value.h) the hand-written readers share: each error names the key's
// path and says what was expected, in the words the scenario and class readers always used.
#include <gtest/gtest.h>

#include <cmath>

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

}  // namespace
}  // namespace scenewatch::yaml
