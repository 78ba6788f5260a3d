// The field-description mechanism on a toy struct: one describe_fields gives reading (strict,
// checked), writing (shortest round-trip numbers), validation and the identity text.
#include "abuopt/common/config_fields.hpp"

#include <cmath>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

namespace toy {

using abuopt::EnumNames;
using abuopt::FieldArchive;
using abuopt::FieldOptions;
using abuopt::Rule;

enum class Shape { Round, Square };
inline const EnumNames<Shape> kShapeNames = {{Shape::Round, "round"}, {Shape::Square, "square"}};

struct Item {
  double mass_kg = 1.0;
  long count = 2;
  bool operator==(const Item&) const = default;
};

struct Toy {
  double rtol = 1e-6;
  std::size_t runs = 16;
  bool tail = true;
  std::string table = "FEHLBERG";
  Shape shape = Shape::Round;
  std::vector<double> mus = {0.02};
  std::optional<double> limit;
  std::optional<std::vector<double>> range;
  int threads = 0;  // not part of the identity
  double inner_gain = 3.0;
  bool free = false;
  double value = 5.0;  // a number, or x0 of the free section
  double lower = 0, upper = 0;
  std::vector<Item> items = {Item{}};
  bool operator==(const Toy&) const = default;
};

void describe_fields(FieldArchive& a, Item& i) {
  a.field("mass_kg", i.mass_kg, Rule::positive(), FieldOptions::required_key());
  a.field("count", i.count, Rule::in_range(0, 64));
}

void describe_fields(FieldArchive& a, Toy& t) {
  a.field("rtol", t.rtol, Rule::in_range(1e-14, 0.1));
  a.field("runs", t.runs, Rule::at_least(1));
  a.field("tail", t.tail);
  a.field("table", t.table);
  a.field("shape", t.shape, kShapeNames);
  a.field("mus", t.mus, Rule::non_negative());
  a.field("limit", t.limit, Rule::positive());
  a.field("range", t.range);
  a.field("threads", t.threads, Rule::non_negative(), FieldOptions::not_identity());
  a.section("inner", [&] { a.field("gain", t.inner_gain, Rule::positive()); },
            FieldOptions::only_if(t.shape == Shape::Square, "is only used with shape: square"));
  a.number_or_section("value", t.free, t.value, Rule::any(), [&] {
    a.field("min", t.lower, Rule::any(), FieldOptions::required_key().without_identity());
    a.field("max", t.upper, Rule::any(), FieldOptions::required_key().without_identity());
    a.field("x0", t.value, Rule::any(), FieldOptions::not_identity());
  });
  a.items("items", t.items);
}

}  // namespace toy

namespace {

using abuopt::ConfigError;
using abuopt::YamlReader;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no error>";
}

toy::Toy read(const std::string& text) {
  YamlReader r = YamlReader::load_string(text);
  toy::Toy t;
  abuopt::read_fields(r, t);
  return t;
}

TEST(ConfigFields, AbsentKeysKeepDefaults) {
  EXPECT_EQ(read("{}"), toy::Toy{});
}

TEST(ConfigFields, ReadsEveryKind) {
  const toy::Toy t = read(
      "rtol: 1e-8\nruns: 7\ntail: false\ntable: X\nshape: square\nmus: [0.1, 0.2]\nlimit: 3\nrange: [1, 2]\n"
      "threads: 4\ninner: {gain: 9}\nvalue: {min: 1, max: 2, x0: 1.5}\nitems:\n  - {mass_kg: 2}\n  - {mass_kg: 3, count: 5}\n");
  EXPECT_EQ(t.rtol, 1e-8);
  EXPECT_EQ(t.runs, 7u);
  EXPECT_FALSE(t.tail);
  EXPECT_EQ(t.table, "X");
  EXPECT_EQ(t.shape, toy::Shape::Square);
  EXPECT_EQ(t.mus, (std::vector<double>{0.1, 0.2}));
  EXPECT_EQ(t.limit, 3.0);
  EXPECT_EQ(t.range, (std::vector<double>{1, 2}));
  EXPECT_EQ(t.threads, 4);
  EXPECT_EQ(t.inner_gain, 9.0);
  EXPECT_TRUE(t.free);
  EXPECT_EQ(t.lower, 1.0);
  EXPECT_EQ(t.upper, 2.0);
  EXPECT_EQ(t.value, 1.5);
  ASSERT_EQ(t.items.size(), 2u);
  EXPECT_EQ(t.items[1], (toy::Item{3.0, 5}));
  EXPECT_EQ(t.items[0].count, 2);  // default of a new element
}

TEST(ConfigFields, ErrorsNameKeyValueAndRule) {
  EXPECT_EQ(error_of([] { read("rtol: 0.5"); }), "rtol = 0.5: must be in [1e-14, 0.1]");
  EXPECT_EQ(error_of([] { read("rtoll: 0.5"); }), "rtoll = 0.5: unknown key (misspelt, or not valid here); did you mean 'rtol'?");
  EXPECT_EQ(error_of([] { read("runs: 1.5"); }), "runs = 1.5: must be a whole number");
  EXPECT_EQ(error_of([] { read("shape: oval"); }), "shape = oval: must be one of: round, square");
  EXPECT_EQ(error_of([] { read("items: [{count: 1}]"); }), "items[0].mass_kg = <missing>: is required");
  EXPECT_EQ(error_of([] { read("items: [{mass_kg: 1, colour: red}]"); }),
            "items[0].colour = red: unknown key (misspelt, or not valid here)");
  EXPECT_EQ(error_of([] { read("inner: {gain: 2}"); }), "inner = {gain: 2}: is only used with shape: square");
  EXPECT_EQ(error_of([] { read("shape: square\ninner: {gain: -2}"); }), "inner.gain = -2: must be > 0");
  EXPECT_EQ(error_of([] { read("value: {min: 1}"); }), "value.max = <missing>: is required");
  EXPECT_EQ(error_of([] { read("value: {min: 1, max: 2, step: 3}"); }),
            "value.step = 3: unknown key (misspelt, or not valid here)");
  EXPECT_EQ(error_of([] { read("mus: [0.1, -1]"); }), "mus[1] = -1: must be >= 0");
  EXPECT_EQ(error_of([] { read("rtol: nan"); }), "rtol = nan: must be in [1e-14, 0.1]");
}

TEST(ConfigFields, WriteThenReadGivesTheSameStructBitForBit) {
  toy::Toy t;
  t.rtol = 0.1 + 0.2;  // 0.30000000000000004: needs 17 digits
  t.rtol = 1.0 / 3.0 * 0.1;
  t.runs = 123;
  t.tail = false;
  t.table = "ARKODE_X";
  t.shape = toy::Shape::Square;
  t.mus = {1e-300, 0.1 + 0.2, 5e-324};
  t.limit = 2.5;
  t.range = std::vector<double>{};
  t.threads = 3;
  t.inner_gain = std::nextafter(1.0, 2.0);
  t.free = true;
  t.lower = -1;
  t.upper = 1e300;
  t.value = 0.7;
  t.items = {toy::Item{0.5, 1}, toy::Item{1.5, 64}};
  const std::string text = abuopt::write_fields(t);
  EXPECT_EQ(read(text), t) << text;
  EXPECT_NE(text.find("0.30000000000000004"), std::string::npos) << text;
  EXPECT_NE(text.find("rtol: 0.03333333333333333"), std::string::npos) << text;
  // Disabled sections and absent optionals are not written.
  t.shape = toy::Shape::Round;
  t.inner_gain = 3.0;
  t.limit.reset();
  t.items.clear();
  const std::string text2 = abuopt::write_fields(t);
  EXPECT_EQ(text2.find("inner"), std::string::npos) << text2;
  EXPECT_EQ(text2.find("limit"), std::string::npos) << text2;
  EXPECT_EQ(read(text2), t) << text2;
}

TEST(ConfigFields, ShortestNumbersAreShort) {
  EXPECT_EQ(abuopt::format_shortest(0.324), "0.324");
  EXPECT_EQ(abuopt::format_shortest(1e-6), "1e-06");
  EXPECT_EQ(abuopt::format_shortest(10700), "10700");
  EXPECT_EQ(abuopt::format_shortest(std::numeric_limits<double>::infinity()), "inf");
}

TEST(ConfigFields, ValidateUsesTheSameRulesAsReading) {
  toy::Toy t;
  EXPECT_NO_THROW(abuopt::validate_fields(t, "toy"));
  t.rtol = 0.5;
  EXPECT_EQ(error_of([&] { abuopt::validate_fields(t, "toy"); }), "toy.rtol = 0.5: must be in [1e-14, 0.1]");
  t = toy::Toy{};
  t.items[0].mass_kg = 0;
  EXPECT_EQ(error_of([&] { abuopt::validate_fields(t, "toy"); }), "toy.items[0].mass_kg = 0: must be > 0");
  t = toy::Toy{};
  t.mus = {0.1, -0.5};
  EXPECT_EQ(error_of([&] { abuopt::validate_fields(t, ""); }), "mus[1] = -0.5: must be >= 0");
}

TEST(ConfigFields, IdentityHasEveryIdentityFieldAndOnlyThose) {
  const toy::Toy base;
  const std::string id = abuopt::identity_fields(base, "toy");
  EXPECT_NE(id.find("toy.rtol: 1e-06\n"), std::string::npos) << id;
  EXPECT_NE(id.find("toy.items[0].mass_kg: 1\n"), std::string::npos) << id;
  EXPECT_NE(id.find("toy.limit: none\n"), std::string::npos) << id;
  EXPECT_EQ(id.find("threads"), std::string::npos) << id;
  // Every identity field changes the text; threads and x0 of a free value do not.
  std::vector<std::function<void(toy::Toy&)>> changes = {
      [](toy::Toy& t) { t.rtol = 2e-6; },        [](toy::Toy& t) { t.runs = 17; },
      [](toy::Toy& t) { t.tail = false; },       [](toy::Toy& t) { t.table = "Y"; },
      [](toy::Toy& t) { t.shape = toy::Shape::Square; },
      [](toy::Toy& t) { t.mus = {0.03}; },       [](toy::Toy& t) { t.limit = 1.0; },
      [](toy::Toy& t) { t.range = std::vector<double>{}; },
      [](toy::Toy& t) { t.value = 6; },          [](toy::Toy& t) { t.free = true; },
      [](toy::Toy& t) { t.items[0].count = 3; }, [](toy::Toy& t) { t.items.push_back({}); },
  };
  for (std::size_t i = 0; i < changes.size(); ++i) {
    toy::Toy t;
    changes[i](t);
    EXPECT_NE(abuopt::identity_fields(t, "toy"), id) << "change " << i;
  }
  toy::Toy t;
  t.threads = 8;
  EXPECT_EQ(abuopt::identity_fields(t, "toy"), id);
  t.free = true;
  const std::string free_id = abuopt::identity_fields(t, "toy");
  t.value = 99;
  t.lower = -5;
  EXPECT_EQ(abuopt::identity_fields(t, "toy"), free_id);
}

}  // namespace
