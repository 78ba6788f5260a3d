#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/common/config_sections.hpp"

#include <gtest/gtest.h>

using abuopt::ConfigError;
using abuopt::Rule;
using abuopt::YamlReader;

namespace {
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no error>";
}
}  // namespace

TEST(YamlReader, ReadsTypedValuesWithDefaults) {
  auto r = YamlReader::load_string("a: 1.5\nb: 3\nc: true\nd: hello\ne: [1, 2]\n");
  EXPECT_DOUBLE_EQ(r.get_double("a"), 1.5);
  EXPECT_EQ(r.get_int("b"), 3);
  EXPECT_TRUE(r.get_bool_or("c", false));
  EXPECT_EQ(r.get_string("d"), "hello");
  EXPECT_EQ(r.get_double_list("e"), (std::vector<double>{1, 2}));
  EXPECT_DOUBLE_EQ(r.get_double_or("missing", 7.0), 7.0);
  EXPECT_NO_THROW(r.finish());
}

TEST(YamlReader, UnknownKeyNamesItsPath) {
  auto r = YamlReader::load_string("sim:\n  rtol: 1e-6\n  rtoll: 2\n");
  auto s = r.child("sim");
  s.get_double("rtol");
  EXPECT_EQ(error_of([&] { s.finish(); }), "sim.rtoll = 2: unknown key (misspelt, or not valid here); did you mean 'rtol'?");
}

TEST(YamlReader, RuleViolationNamesKeyValueAndRule) {
  auto r = YamlReader::load_string("profile:\n  segments:\n    - {duration_s: -2}\n");
  auto p = r.child("profile");
  auto segs = p.children("segments");
  ASSERT_EQ(segs.size(), 1u);
  EXPECT_EQ(error_of([&] { segs[0].get_double("duration_s", Rule::positive()); }),
            "profile.segments[0].duration_s = -2: must be > 0");
}

TEST(YamlReader, WrongTypeAndMissingAndChoice) {
  auto r = YamlReader::load_string("x: abc\nm: foo\n");
  EXPECT_EQ(error_of([&] { r.get_double("x"); }), "x = abc: must be a number");
  EXPECT_EQ(error_of([&] { r.get_double("y"); }), "y = <missing>: is required");
  EXPECT_EQ(error_of([&] { r.get_choice_or("m", "a", {"a", "b"}); }), "m = foo: must be one of: a, b");
  EXPECT_EQ(error_of([] { YamlReader::load_file("/nonexistent/x.yaml"); }),
            "config file '/nonexistent/x.yaml' cannot be opened (missing or unreadable)");
}

TEST(YamlReader, NonScalarKeyIsAnUnknownKeyNotAnInternalError) {
  auto r = YamlReader::load_string("? [a, b]\n: 1\n");
  EXPECT_EQ(error_of([&] { r.finish(); }), "[a, b] = 1: unknown key (misspelt, or not valid here)");
}

// A reader of some sections of a config (simulate, eqset) accepts the others a normal config carries
// and still refuses a misspelt section, with the known sections as hints.
TEST(ConfigSections, OtherCommandsSectionsAreAcceptedUnread) {
  auto r = YamlReader::load_string("abu: {friction_mu: 0.02}\nmontecarlo: {design: grid, grid: 32}\nsweep: {}\n");
  r.child("abu").get_double("friction_mu");
  EXPECT_NO_THROW(abuopt::finish_config(r));
  EXPECT_NE(error_of([&] { r.finish(); }).find("montecarlo = {design: grid, grid: 32}: unknown key"), std::string::npos);
}

TEST(ConfigSections, MisspeltSectionIsRefusedWithAHint) {
  auto r = YamlReader::load_string("abu: {}\nmontecalro: {design: grid}\n");
  r.child("abu");
  EXPECT_EQ(error_of([&] { abuopt::finish_config(r); }),
            "montecalro = {design: grid}: unknown key (misspelt, or not valid here); did you mean 'montecarlo'?");
}

TEST(YamlReader, AnUnknownSectionIsShownBriefly) {
  auto r = YamlReader::load_string("mc: {design: grid, grid: 32, runs: 1024, seed: 1, threads: 0, friction: {fixed: 0.02}}\n");
  EXPECT_EQ(error_of([&] { r.finish(); }),
            "mc = {design: grid, grid: 32, runs: 1024, seed: 1, threads: 0, ...}: unknown key (misspelt, or not valid here)");
  auto q = YamlReader::load_string("l: [1, [2, 3], {a: 1}]\n");
  EXPECT_EQ(error_of([&] { q.finish(); }), "l = [1, [...], {...}]: unknown key (misspelt, or not valid here)");
}
