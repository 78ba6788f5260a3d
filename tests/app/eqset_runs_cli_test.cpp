// `abuopt eqset CONFIG --runs RUNS_CSV` (docs/equilibrium_sets.md section 6) on a small Monte Carlo of
// the 2003 profile: the runs it counts, the depth it reports against abuopt's own |I_r|, the early / late
// split against the settling speeds, the lemma depth >= gauge per run, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "abuopt_cli.hpp"

namespace {

namespace fs = std::filesystem;

using Table = std::vector<std::map<std::string, std::string>>;

Table read_csv(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> head;
  Table out;
  auto split = [](const std::string& l) {
    std::vector<std::string> v;
    std::stringstream ss(l);
    for (std::string f; std::getline(ss, f, ',');) v.push_back(f);
    if (!l.empty() && l.back() == ',') v.emplace_back();
    return v;
  };
  if (std::getline(in, line)) head = split(line);
  while (std::getline(in, line)) {
    const auto f = split(line);
    std::map<std::string, std::string> row;
    for (std::size_t k = 0; k < head.size() && k < f.size(); ++k) row[head[k]] = f[k];
    out.push_back(row);
  }
  return out;
}

std::string src(const std::string& rel) { return std::string(ABUOPT_SOURCE_DIR) + "/" + rel; }

fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::path(ABUOPT_BINARY_DIR) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace

TEST(EqsetRunsCli, TwoBallsOfThe2003Profile) {
  const fs::path dir = fresh_dir("eqset_runs_cli_test");
  const std::string cfg = src("configs/designs/report_2003.yaml");
  auto mc = abuopt::test::run_abuopt("montecarlo " + cfg + " --runs 128 --seed 9001 --threads 1 --out " +
                                     (dir / "mc").string(), "", false);
  ASSERT_EQ(mc.status, 0) << mc.output;
  const std::string runs = (dir / "mc" / "runs.csv").string();
  const auto r = abuopt::test::run_abuopt("eqset " + cfg + " --runs " + runs + " --json --out " + (dir / "fs").string(),
                                          "", false);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  const Table mc_rows = read_csv(runs), rows = read_csv(dir / "fs" / "final_states.csv");
  std::map<std::string, double> ir;  // index -> abuopt's |I_r| of the settled runs
  for (const auto& row : mc_rows)
    if (row.at("status") == "ok" && row.at("settled") == "1") ir[row.at("index")] = std::stod(row.at("ir_magnitude_kgm"));
  ASSERT_GT(ir.size(), 100u);
  EXPECT_EQ(j["settled"].get<std::size_t>(), ir.size());
  EXPECT_EQ(j["settled"].get<std::size_t>() + j["not_settled"].get<std::size_t>() + j["runs_failed"].get<std::size_t>(),
            mc_rows.size());
  EXPECT_EQ(j["early"]["count"].get<std::size_t>() + j["late"]["count"].get<std::size_t>(), ir.size());
  EXPECT_DOUBLE_EQ(j["mu"].get<double>(), 0.02);
  const double rl = j["r_lock_kgm"].get<double>();
  EXPECT_NEAR(rl / 1e-7, 15.90, 0.005);
  const double edge = j["edge_hz"].get<double>();
  EXPECT_NEAR(edge, 28.36, 0.005);
  // The mean depth is abuopt's mean |I_r| over r_lock; per run, depth x r_lock is |I_r| (|U| of the final
  // angles), early runs settled below the edge and late ones above, and depth >= gauge where it holds.
  double sum = 0;
  for (const auto& [k, v] : ir) sum += v;
  EXPECT_NEAR(j["depth_mean"].get<double>(), sum / static_cast<double>(ir.size()) / rl, 1e-9);
  ASSERT_EQ(rows.size(), ir.size());
  std::size_t early = 0, stuck = 0;
  for (const auto& row : rows) {
    const double depth = std::stod(row.at("depth")), g = std::stod(row.at("gauge_settle"));
    EXPECT_NEAR(depth * rl, ir.at(row.at("index")), 1e-6 * 5.6e-4 * 3.7e-3) << "run " << row.at("index");
    const bool is_early = row.at("group") == "early";
    early += is_early;
    EXPECT_EQ(is_early, std::stod(row.at("settle_hz")) < edge) << "run " << row.at("index");
    if (g <= 1) {
      ++stuck;
      EXPECT_GE(depth, g - 1e-12) << "run " << row.at("index");
    }
  }
  EXPECT_EQ(early, j["early"]["count"].get<std::size_t>());
  EXPECT_GT(stuck, ir.size() / 2);
  // The 2003 profile's early runs stop at the end of its first ramp, 25 Hz; the late ones in the band.
  EXPECT_NEAR(j["early"]["settle_hz"]["median"].get<double>(), 25.0, 0.05);
  EXPECT_GT(j["late"]["settle_hz"]["p10"].get<double>(), 28.5);
  // Passage split at 25 Hz: reached at t = 1 s, so early = settled before 1 s.
  const auto p = abuopt::test::run_abuopt("eqset " + cfg + " --runs " + runs + " --split passage --edge 25 --json", "", false);
  ASSERT_EQ(p.status, 0) << p.output;
  const auto jp = nlohmann::json::parse(p.output);
  EXPECT_NEAR(jp["edge_time_s"].get<double>(), 1.0, 1e-9);
  std::size_t before = 0;
  for (const auto& row : mc_rows)
    if (row.at("status") == "ok" && row.at("settled") == "1" && std::stod(row.at("settling_time_s")) < 1.0) ++before;
  EXPECT_EQ(jp["early"]["count"].get<std::size_t>(), before);
  // The text output names the split and both groups.
  const auto t = abuopt::test::run_abuopt("eqset " + cfg + " --runs " + runs, "", false);
  ASSERT_EQ(t.status, 0) << t.output;
  EXPECT_NE(t.output.find("r_lock 15.90e-7 kg m"), std::string::npos) << t.output;
  EXPECT_NE(t.output.find("early"), std::string::npos);
  EXPECT_NE(t.output.find("late"), std::string::npos);

  // Bad input: one error naming the option, its value and the rule (exit status 2).
  const auto six = abuopt::test::run_abuopt("eqset " + src("configs/designs/mean_6balls_19s.yaml") + " --runs " + runs);
  EXPECT_EQ(six.status, 2);
  EXPECT_NE(six.output.find("--runs"), std::string::npos) << six.output;
  EXPECT_NE(six.output.find("2 beta_final columns, the config 6 balls"), std::string::npos) << six.output;
  const auto split = abuopt::test::run_abuopt("eqset " + cfg + " --runs " + runs + " --split early");
  EXPECT_EQ(split.status, 2);
  EXPECT_NE(split.output.find("--split = early: must be speed or passage"), std::string::npos) << split.output;
  const auto mu = abuopt::test::run_abuopt("eqset " + cfg + " --runs " + runs + " --mu 0.03");
  EXPECT_EQ(mu.status, 2);
  EXPECT_NE(mu.output.find("--mu"), std::string::npos) << mu.output;
  const auto grid = abuopt::test::run_abuopt("eqset " + cfg + " --runs " + runs + " --grid 20");
  EXPECT_EQ(grid.status, 2);
  EXPECT_NE(grid.output.find("--grid = 20: has no use with --runs"), std::string::npos) << grid.output;
  const auto missing = abuopt::test::run_abuopt("eqset " + cfg + " --runs " + (dir / "none.csv").string());
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.output.find("cannot be read"), std::string::npos) << missing.output;
}

// Six balls: depth x r_lock is abuopt's |I_r| of the six final angles (the N-ball U), at the runs' mu.
TEST(EqsetRunsCli, SixBallsAtTheRunsMu) {
  const fs::path dir = fresh_dir("eqset_runs_cli_test_six");
  const std::string cfg = src("configs/designs/mean_6balls_19s.yaml");
  auto mc = abuopt::test::run_abuopt("montecarlo " + cfg + " --mu 0.03 --runs 16 --seed 9001 --threads 1 --out " +
                                     (dir / "mc").string(), "", false);
  ASSERT_EQ(mc.status, 0) << mc.output;
  const std::string runs = (dir / "mc" / "runs.csv").string();
  const auto r = abuopt::test::run_abuopt("eqset " + cfg + " --runs " + runs + " --json --out " + (dir / "fs").string(),
                                          "", false);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_DOUBLE_EQ(j["mu"].get<double>(), 0.03);
  EXPECT_NEAR(j["r_lock_kgm"].get<double>() / 1e-7, 23.62, 0.005);  // six balls of the same total mass: same M
  std::map<std::string, double> ir;
  for (const auto& row : read_csv(dir / "mc" / "runs.csv"))
    if (row.at("status") == "ok" && row.at("settled") == "1") ir[row.at("index")] = std::stod(row.at("ir_magnitude_kgm"));
  const Table rows = read_csv(dir / "fs" / "final_states.csv");
  ASSERT_EQ(rows.size(), ir.size());
  ASSERT_GT(rows.size(), 10u);
  for (const auto& row : rows)
    EXPECT_NEAR(std::stod(row.at("depth")) * std::stod(row.at("r_lock_kgm")), ir.at(row.at("index")), 1e-6 * 5.6e-4 * 3.7e-3);
}

// --lock-set: uniform starts in the lock set of configs/eqset.yaml at mu 0.03 on a 40 x 40 grid, 49.9 %
// (FinalStates.LockSetOfUniformStarts), and the reach of a ramp at 314.16 rad/s^2, 0.318.
TEST(EqsetRunsCli, LockSetOfUniformStarts) {
  const std::string cfg = src("configs/eqset.yaml");
  const auto r = abuopt::test::run_abuopt("eqset " + cfg + " --lock-set --grid 40 --mu 0.03 --alpha 314.16 --json", "", false);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["grid"].get<int>(), 40);
  EXPECT_NEAR(j["share"].get<double>(), 0.499, 0.006);
  EXPECT_NEAR(j["reach"].get<double>(), 0.318, 5e-4);
  EXPECT_LT(j["unreached_share"].get<double>(), j["share"].get<double>());
  EXPECT_NEAR(j["floor"].get<double>(), j["share"].get<double>() * j["depth_mean"].get<double>(), 1e-15);
  EXPECT_NEAR(j["r_lock_kgm"].get<double>() / 1e-7, 23.62, 0.005);
  const auto text = abuopt::test::run_abuopt("eqset " + cfg + " --lock-set --grid 40", "", false);
  ASSERT_EQ(text.status, 0) << text.output;
  EXPECT_NE(text.output.find("in the lock set: "), std::string::npos) << text.output;
  const auto bad = abuopt::test::run_abuopt("eqset " + cfg + " --lock-set --alpha -1");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("--alpha = -1: must be an angular acceleration >= 0"), std::string::npos) << bad.output;
  const auto both = abuopt::test::run_abuopt("eqset " + cfg + " --lock-set --freq 29");
  EXPECT_EQ(both.status, 2) << both.output;
  const auto out = abuopt::test::run_abuopt("eqset " + cfg + " --lock-set --out /tmp/never");
  EXPECT_EQ(out.status, 2);
  EXPECT_NE(out.output.find("--out = /tmp/never: has no use with --lock-set"), std::string::npos) << out.output;
}

// The runs locked before the band are uniform starts in the lock set (docs/equilibrium_sets.md section 6):
// a two-ball design whose first ramp stops at 22.6 Hz, at mu 0.03, 256 random starts: its early runs are as
// many as the lock set's share of the torus (50.1 %, `--lock-set`) within 3 binomial sigma (9.4 points)
// and as deep (0.739 r_lock) within 0.08 (3 standard errors of about 130 runs); they settle in the first
// ramp (p90 below 23 Hz), the late ones in the band (p10 above 28 Hz).
TEST(EqsetRunsCli, EarlyRunsAreUniformStartsInTheLockSet) {
  const fs::path dir = fresh_dir("eqset_runs_cli_test_lock");
  const fs::path cfg = dir / "k4.yaml";
  std::ofstream(cfg) << R"(abu:
  friction_mu: 0.03
  ball_contact: hard
profile:
  start_frequency_hz: 0.0
  segments:
    - {end_frequency_hz: 22.6222, duration_s: 1.55852}
    - {end_frequency_hz: 28.9129, duration_s: 3.4931}
    - {end_frequency_hz: 28.9129, duration_s: 3.71217}
    - {end_frequency_hz: 100, duration_s: 5.08554}
motor:
  kind: ideal
simulation:
  method: event_driven
  rtol: 1.0e-6
)";
  auto mc = abuopt::test::run_abuopt("montecarlo " + cfg.string() + " --design random --runs 256 --seed 9001 --threads 1 --out " +
                                     (dir / "mc").string(), "", false);
  ASSERT_EQ(mc.status, 0) << mc.output;
  const auto r = abuopt::test::run_abuopt("eqset " + cfg.string() + " --runs " + (dir / "mc" / "runs.csv").string() + " --json",
                                          "", false);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  const auto lock = nlohmann::json::parse(
      abuopt::test::run_abuopt("eqset " + cfg.string() + " --lock-set --grid 80 --json", "", false).output);
  const double p = lock["share"].get<double>(), n = j["settled"].get<double>();
  EXPECT_NEAR(p, 0.501, 0.01);
  EXPECT_GT(n, 250);
  EXPECT_NEAR(j["early"]["share"].get<double>(), p, 3 * std::sqrt(p * (1 - p) / n));
  EXPECT_NEAR(j["early"]["depth_mean"].get<double>(), lock["depth_mean"].get<double>(), 0.08);
  EXPECT_LT(j["early"]["settle_hz"]["p90"].get<double>(), 23.0);
  EXPECT_GT(j["late"]["settle_hz"]["p10"].get<double>(), 28.0);
}

