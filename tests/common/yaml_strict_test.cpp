// The reader refuses what it would otherwise silently half-read (issue 12): a key given twice in
// one mapping (the first won), a second YAML document (ignored), a directory as the config file.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/yaml_reader.hpp"

namespace abuopt {
namespace {

std::string error_of(const std::string& text) {
  try {
    YamlReader::load_string(text, "t");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(YamlStrict, ADuplicateKeyIsAnErrorNamingIt) {
  const std::string m = error_of("abu:\n  friction_mu: 0.02\n  friction_mu: 0.5\n");
  EXPECT_NE(m.find("abu.friction_mu"), std::string::npos) << m;
  EXPECT_NE(m.find("appears twice"), std::string::npos) << m;
  EXPECT_NE(m.find("line 3"), std::string::npos) << m;
}

TEST(YamlStrict, ADuplicateSectionIsAnError) {
  const std::string m = error_of("abu:\n  friction_mu: 0.02\nabu:\n  friction_mu: 0.5\n");
  EXPECT_NE(m.find("abu = "), std::string::npos) << m;
  EXPECT_NE(m.find("appears twice"), std::string::npos) << m;
}

TEST(YamlStrict, DuplicatesInsideListsAreFoundToo) {
  const std::string m = error_of("profile:\n  segments:\n    - {end_frequency_hz: 5, end_frequency_hz: 6}\n");
  EXPECT_NE(m.find("profile.segments[0].end_frequency_hz"), std::string::npos) << m;
}

TEST(YamlStrict, ASecondDocumentIsAnError) {
  const std::string m = error_of("abu:\n  friction_mu: 0.02\n---\nabu:\n  friction_mu: 0.5\n");
  EXPECT_NE(m.find("more than one YAML document"), std::string::npos) << m;
  EXPECT_EQ(error_of("abu:\n  friction_mu: 0.02\n"), "");
}

// Found by fuzz_config: on this malformed config (a study config with a few bytes changed, a tag
// inside a key) yaml-cpp's LoadAll never stopped collecting empty documents and took gigabytes
// within a second. Reading it must end at once, with a ConfigError or a (rejected later) node.
TEST(YamlStrict, AnInputThatMadeLoadAllCollectDocumentsForeverEnds) {
  std::ifstream in(std::string(ABUOPT_SOURCE_DIR) + "/tests/common/data/loadall_endless_documents.yaml",
                   std::ios::binary);
  ASSERT_TRUE(in) << "test input missing";
  std::ostringstream text;
  text << in.rdbuf();
  ASSERT_GT(text.str().size(), 500u);
  const std::string m = error_of(text.str());
  EXPECT_NE(m.find("more than one YAML document"), std::string::npos) << m;
}

TEST(YamlStrict, TheFileIsNamedAndADirectoryIsBadInput) {
  const std::string file = std::string(ABUOPT_BINARY_DIR) + "/yaml_strict_test.yaml";
  {
    std::ofstream f(file);
    f << "a: 1\nb: 2\na: 3\n";
  }
  try {
    YamlReader::load_file(file);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(file), std::string::npos) << m;
    EXPECT_NE(m.find("a = 3"), std::string::npos) << m;
  }
  std::filesystem::remove(file);
  try {
    YamlReader::load_file(ABUOPT_BINARY_DIR);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
}

TEST(YamlStrict, StringListsAndTheDeepMerge) {
  YamlReader r = YamlReader::load_string("one: a\nmany: [b, c]\nbad: [x, [y]]\n");
  EXPECT_EQ(r.get_string_list_or("one"), std::vector<std::string>{"a"});
  EXPECT_EQ(r.get_string_list_or("many"), (std::vector<std::string>{"b", "c"}));
  EXPECT_EQ(r.get_string_list_or("absent", {"z"}), std::vector<std::string>{"z"});
  EXPECT_THROW(r.get_string_list_or("bad"), ConfigError);
  const YAML::Node base = YAML::Load("a: {x: 1, y: 2}\nb: [1, 2]\n");
  const YAML::Node merged = merge_yaml(base, YAML::Load("a: {y: 3}\nb: [9]\n"));
  EXPECT_EQ(merged["a"]["x"].as<int>(), 1);  // maps merge key by key
  EXPECT_EQ(merged["a"]["y"].as<int>(), 3);
  EXPECT_EQ(merged["b"].size(), 1u);  // sequences replace
  EXPECT_EQ(base["a"]["y"].as<int>(), 2);  // the base is not modified
}

// Issue 29: the document's shape is checked on the parser's events, before a node exists.
TEST(YamlStrict, AnAliasInsideTheNodeItNamesIsALoop) {
  for (const char* text : {"abu:\n  friction_mu: &a [*a]\n", "a: &m {b: [1, {c: *m}]}\n"}) {
    const std::string m = error_of(text);
    EXPECT_NE(m.find("refers to the node it is part of"), std::string::npos) << text << " -> " << m;
  }
  // an alias to a finished node is fine (it is not a loop)
  EXPECT_EQ(error_of("a: &x [1, 2]\nb: *x\n"), "");
}

TEST(YamlStrict, NestedAliasesAreBoundedWhereverTheyAre) {
  std::string laughs = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i <= 9; ++i) {
    laughs += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [";
    for (int k = 0; k < 10; ++k) laughs += std::string(k ? ", " : "") + "*a" + std::to_string(i - 1);
    laughs += "]\n";
  }
  const auto t0 = std::chrono::steady_clock::now();
  const std::string m = error_of(laughs);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  EXPECT_NE(m.find("more than 1e+06 values"), std::string::npos) << m;
  EXPECT_NE(m.find("line "), std::string::npos) << m;
  // depth through aliases: 70 one-element lists, each the alias of the last
  std::string deep = "a0: &a0 [x]\n";
  for (int i = 1; i <= 70; ++i) deep += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [*a" + std::to_string(i - 1) + "]\n";
  EXPECT_NE(error_of(deep).find("levels deep"), std::string::npos);
  EXPECT_NE(error_of("a: " + std::string(100, '[') + std::string(100, ']') + "\n").find("levels deep"), std::string::npos);
}

TEST(YamlStrict, TagsAndNullValuesAreRefused) {
  EXPECT_NE(error_of("abu: {friction_mu: !!float 0.02}\n").find("has the YAML tag 'tag:yaml.org,2002:float'"),
            std::string::npos);
  EXPECT_NE(error_of("abu: !custom {friction_mu: 0.02}\n").find("abu = {...}: has the YAML tag '!custom'"),
            std::string::npos);
  YamlReader r = YamlReader::load_string("abu:\n  friction_mu: ~\n  balls:\n    - ~\n", "t");
  YamlReader abu = r.child("abu");
  try {
    abu.get_double_or("friction_mu", 0.02);
    FAIL() << "a null value took the default";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("abu.friction_mu = ~: has no value"), std::string::npos) << e.what();
  }
  EXPECT_THROW(abu.children("balls"), ConfigError);
  EXPECT_TRUE(abu.has("friction_mu"));  // given, as null: reading it is the error
}

TEST(YamlStrict, LoneCarriageReturnsAreLineBreaks) {
  YamlReader r = YamlReader::load_string("abu:\r  friction_mu: 0.25\r  ball_count: 3\r", "t");
  YamlReader abu = r.child("abu");
  EXPECT_EQ(abu.get_double("friction_mu"), 0.25);
  EXPECT_EQ(abu.get_int("ball_count"), 3);
}

}  // namespace
}  // namespace abuopt
