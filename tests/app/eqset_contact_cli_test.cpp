// `abuopt eqset --freq` with abu.ball_contact: hard (docs/equilibrium_sets.md section 5): the
// overlapping band is excluded (in_set = -1 in the CSV), the contact line is evaluated separately.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "abuopt_cli.hpp"

namespace {

namespace fs = std::filesystem;

TEST(EqsetContactCli, ExcludesOverlapsAndEvaluatesTheContactLine) {
  const fs::path dir = fs::path(ABUOPT_BINARY_DIR) / "eqset_contact_cli_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // configs/eqset.yaml with hard contact
  std::ifstream in(std::string(ABUOPT_SOURCE_DIR) + "/configs/eqset.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const auto at = yaml.find("\nabu:\n");
  ASSERT_NE(at, std::string::npos);
  yaml.insert(at + 6, "  ball_contact: hard\n");
  const fs::path cfg = dir / "eqset_hard.yaml";
  std::ofstream(cfg) << yaml;
  const auto r = abuopt::test::run_abuopt("eqset " + cfg.string() + " --freq 10 --grid 64 --json --out " +
                                          (dir / "out").string(), "", false);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["ball_contact"], "hard");
  EXPECT_EQ(j["excluded_overlapping"], 64 * 5);  // 5 of 64 per row are closer than 0.2616 rad
  EXPECT_DOUBLE_EQ(j["contact_line"]["coverage_ahead"].get<double>(), 1.0);  // far from resonance
  EXPECT_DOUBLE_EQ(j["contact_line"]["coverage_behind"].get<double>(), 1.0);
  EXPECT_NEAR(j["contact_line"]["spacing_rad"].get<double>(), 2 * std::asin(3e-3 / (2 * 1.15e-2)), 1e-12);
  // CSV: -1 exactly on the excluded points, and the contact line file
  std::ifstream csv(dir / "out" / "equilibrium_set.csv");
  std::string line;
  std::getline(csv, line);
  int minus = 0, rows = 0;
  while (std::getline(csv, line)) {
    ++rows;
    std::stringstream ss(line);
    std::string b1, b2, amp, in_set;
    std::getline(ss, b1, ',');
    std::getline(ss, b2, ',');
    std::getline(ss, amp, ',');
    std::getline(ss, in_set, ',');
    if (in_set == "-1") ++minus;
  }
  EXPECT_EQ(rows, 64 * 64);
  EXPECT_EQ(minus, 64 * 5);
  EXPECT_TRUE(fs::exists(dir / "out" / "contact_line.csv"));
}

}  // namespace
