// `abuopt optimize` end to end on the built binary with configs/optimize/quick.yaml (16 runs per
// evaluation, 10 evaluations): exit status, the files it writes, the best profile running with
// `abuopt simulate` and reproducing the best objective with `abuopt montecarlo`, a rerun answered
// entirely from the archive, and one message per class of bad config (exit status 2).
#include <gtest/gtest.h>

#include "abuopt_cli.hpp"

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

using Result = abuopt::test::CliResult;

Result run(const std::string& args, bool with_stderr = true) {
  return abuopt::test::run_abuopt(args, "", with_stderr);
}

const std::string kQuick = std::string(ABUOPT_SOURCE_DIR) + "/configs/optimize/quick.yaml";

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(ABUOPT_BINARY_DIR) / "optimize_cli_test" / name;
  fs::remove_all(d);
  fs::create_directories(d.parent_path());
  return d;
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream f(p);
  return nlohmann::json::parse(f);
}

long count_lines(const fs::path& p) {
  std::ifstream f(p);
  long n = 0;
  for (std::string l; std::getline(f, l);) ++n;
  return n;
}

std::string write_config(const std::string& name, const std::string& text) {
  const fs::path d = fs::path(ABUOPT_BINARY_DIR) / "optimize_cli_test";
  fs::create_directories(d);
  const fs::path path = d / name;
  std::ofstream(path) << text;
  return path.string();
}

}  // namespace

TEST(OptimizeCli, QuickStudyWritesItsOutputsAndResumesFromTheArchive) {
  const fs::path out = fresh_dir("quick");
  const Result first = run("optimize " + kQuick + " --out " + out.string());
  ASSERT_EQ(first.status, 0) << first.output;
  EXPECT_NE(first.output.find("eval    1"), std::string::npos) << first.output;
  EXPECT_NE(first.output.find("report profile, out-of-sample"), std::string::npos) << first.output;
  for (const char* f : {"history.csv", "result.json", "best_profile.yaml", "convergence.csv", "archive.sqlite"})
    EXPECT_TRUE(fs::exists(out / f)) << f;

  const nlohmann::json j = read_json(out / "result.json");
  EXPECT_EQ(j["evaluations"], 10);
  EXPECT_EQ(j["archive_hits"], 0);
  EXPECT_EQ(j["algorithm"], "COBYLA");
  EXPECT_EQ(j["best"]["x"].size(), 5u);
  EXPECT_TRUE(j["best"]["feasible"].get<bool>());
  EXPECT_EQ(j["best"]["profile"]["segments"].size(), 3u);
  EXPECT_EQ(j["best"]["profile"]["segments"][2]["end_frequency_hz"], 100.0);  // fixed
  EXPECT_LE(j["best"]["metrics"]["startup_time_s"].get<double>(), 20.0 * (1 + 1e-6));
  for (const char* k : {"ir_magnitude_mean", "ir_x_mean", "ir_magnitude_max", "ir_x_median", "pct_mi", "pct_lc",
                        "amplitude_max_mm", "failed_runs", "mc_wall_time_s"})
    EXPECT_TRUE(j["best"]["metrics"].contains(k)) << k;
  EXPECT_EQ(j["validation"]["runs"], 32);
  EXPECT_EQ(j["validation"]["best"]["out_of_sample"]["metrics"]["runs"], 32);
  EXPECT_EQ(j["validation"]["report_profile"]["in_sample"]["metrics"]["runs"], 16);
  EXPECT_EQ(count_lines(out / "history.csv"), 11);  // header + 10 evaluations

  // The best profile is a ready-to-run simulate config.
  const Result sim = run("simulate " + (out / "best_profile.yaml").string() + " --beta0 0.5,3.0 --json", false);
  ASSERT_EQ(sim.status, 0) << sim.output;
  EXPECT_EQ(nlohmann::json::parse(sim.output)["status"], "ok");
  // ... and a montecarlo config: on the optimiser's own initial conditions (quick.yaml: lhs, 16
  // runs, seed 7) it reproduces the best objective (mean |I_r| in 1e-7 kg m): every key that
  // decides the value was written, numbers round-trip exactly.
  const Result mc = run("montecarlo " + (out / "best_profile.yaml").string() +
                            " --design lhs --runs 16 --seed 7 --threads 1 --json",
                        false);
  ASSERT_EQ(mc.status, 0) << mc.output;
  const double mean_ir = nlohmann::json::parse(mc.output)["magnitude"]["mean"].get<double>();
  EXPECT_NEAR(mean_ir / 1e-7, j["best"]["objective"].get<double>(), 1e-12 * j["best"]["objective"].get<double>());

  // Rerunning the same command: every evaluation is answered from the archive, same best design.
  const Result second = run("optimize " + kQuick + " --out " + out.string() + " --json", false);
  ASSERT_EQ(second.status, 0) << second.output;
  const nlohmann::json k = nlohmann::json::parse(second.output);
  EXPECT_EQ(k["evaluations"], 10);
  EXPECT_EQ(k["archive_hits"], 10);
  EXPECT_EQ(k["computed_evaluations"], 0);
  EXPECT_EQ(k["best"]["x"], j["best"]["x"]);
  EXPECT_EQ(k["best"]["objective"], j["best"]["objective"]);
}

TEST(OptimizeCli, MaxEvaluationsOverridesTheBudget) {
  const fs::path out = fresh_dir("budget");
  const Result r = run("optimize " + kQuick + " --out " + out.string() + " --max-evaluations 3 --json", false);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(r.output)["evaluations"], 3);
}

TEST(OptimizeCli, BadConfigsGiveOneClearMessageAndStatus2) {
  const std::string design =
      "montecarlo: {design: lhs, runs: 4}\n"
      "design: {segments: [{end_frequency_hz: 30, duration_s: {min: 0.2, max: 1}}]}\n";
  struct Case {
    std::string yaml, extra, message;
  };
  const Case cases[] = {
      {design + "optimizer: {algorithm: magic}\n", "", "optimizer.algorithm = magic: unknown algorithm; valid"},
      {"montecarlo: {runs: 4, design: lhs}\ndesign: {segments: [{end_frequency_hz: {min: 28, max: 15}, duration_s: 1}]}\n", "",
       "design.segments[0].end_frequency_hz.min = 28: must be below design.segments[0].end_frequency_hz.max = 15"},
      {"montecarlo: {runs: 4, design: lhs}\ndesign: {segments: [{end_frequency_hz: {min: 15, max: 28, x0: 40}, duration_s: 1}]}\n",
       "", "design.segments[0].end_frequency_hz.x0 = 40: must be in [15, 28] (the bounds)"},
      {"montecarlo: {runs: 4, design: lhs}\ndesign: {segments: [{end_frequency_hz: 30, duration_s: 1}]}\n", "",
       "no free variable"},
      {design + "objective: {kind: mean, definiton: report_x}\n", "",
       "objective.definiton = report_x: unknown key (misspelt, or not valid here)"},
      {design + "sao: {initial_radius: 0.2}\n", "", "sao = <section>: only used with optimizer.algorithm: SAO"},
      {design, "--max-evaluations 0", "--max-evaluations = 0: must be >= 1"},
  };
  int i = 0;
  for (const auto& c : cases) {
    const std::string path = write_config("bad" + std::to_string(i++) + ".yaml", c.yaml);
    const fs::path out = fresh_dir("bad");
    const Result r = run("optimize " + path + " --out " + out.string() + " " + c.extra);
    EXPECT_EQ(r.status, 2) << c.yaml << r.output;
    EXPECT_NE(r.output.find("abuopt: error: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << "expected: " << c.message << "\ngot: " << r.output;
  }
  const Result missing = run("optimize /nonexistent/config.yaml");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.output.find("cannot be opened"), std::string::npos) << missing.output;
}

// A design problem made for the report's ABU (formulation 1, family k4_hold, as the startup-profile
// study posed it) run on a stiffer one (k = 4e4 N/m: f_n 55.85 Hz, outside the frequency bounds
// [15, 30.5] Hz): the message names the constraints the least-violating design breaks and says that
// no free frequency reaches the natural frequency.
TEST(OptimizeCli, NoFeasibleDesignNamesTheConstraintsAndTheUnreachableResonance) {
  const std::string text = R"(abu:
  stiffness_N_per_m: 4.0e4
  friction_mu: 0.02
profile:
  start_frequency_hz: 0
  segments:
    - {end_frequency_hz: 25.0, duration_s: 1.0}
    - {end_frequency_hz: 29.5, duration_s: 10.0}
    - {end_frequency_hz: 100.0, duration_s: 8.0}
motor: {kind: ideal}
simulation: {method: event_driven, rtol: 1.0e-6}
montecarlo: {design: lhs, runs: 256, seed: 21, threads: 0}
design:
  segments:
    - end_frequency_hz: {min: 15, max: 28.8, x0: 25}
      duration_s: {min: 0.3, max: 3, x0: 1}
    - end_frequency_hz: {min: 28.6, max: 30.5, x0: 29.2}
      duration_s: {min: 0.5, max: 12, x0: 6}
    - hold: true
      duration_s: {min: 0.2, max: 12, x0: 6}
    - end_frequency_hz: 100
      duration_s: {min: 1, max: 10, x0: 6}
objective: {kind: mean, definition: magnitude}
constraints:
  max_startup_time_s: 19
  max_pct_mi: 2
  max_amplitude_mm: 0.484
  max_angular_acceleration_rad_s2: 314.16
validation: {enabled: false}
optimizer: {algorithm: cobyla, max_evaluations: 80, initial_step: 0.15, xtol_rel: 1.0e-3}
)";
  const std::string cfg = write_config("stiff_abu.yaml", text);
  const fs::path out = fresh_dir("stiff_abu");
  const Result r = run("optimize " + cfg + " --out " + out.string() + " --max-evaluations 3");
  EXPECT_EQ(r.status, 3) << r.output;
  EXPECT_NE(r.output.find("the least-violating design breaks"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(g = "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no free frequency can reach this ABU's natural frequency 55.85 Hz"), std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("see the table above"), std::string::npos) << r.output;
}
