// `abuopt simulate` end to end on the built binary: JSON keys, and one message per class of bad
// input (exit status 2, key path + value + rule, never a stack trace).
#include <gtest/gtest.h>

#include "abuopt_cli.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace {

using Result = abuopt::test::CliResult;

Result run(const std::string& args) { return abuopt::test::run_abuopt(args); }

std::string write_config(const std::string& name, const std::string& text) {
  const std::string path = std::string(ABUOPT_BINARY_DIR) + "/" + name;
  std::ofstream(path) << text;
  return path;
}

const std::string kConfigs = std::string(ABUOPT_SOURCE_DIR) + "/configs/";

}  // namespace

TEST(SimulateCli, JsonHasTheDocumentedKeys) {
  const Result r = run("simulate " + kConfigs + "report_final_profile.yaml --beta0 0.5,3.0 --json");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  for (const char* k : {"beta_final", "residual_imbalance", "residual_imbalance_x", "settled", "settling_time",
                        "max_amplitude_mm", "status", "rhs_evaluations", "events"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["status"], "ok");
  EXPECT_EQ(j["beta_final"].size(), 2u);
  EXPECT_LE(j["residual_imbalance_x"].get<double>(), j["residual_imbalance"].get<double>());
}

TEST(SimulateCli, ShippedConfigsRunAndTrajectoryIsWritten) {
  const std::string csv = std::string(ABUOPT_BINARY_DIR) + "/traj_test.csv";
  const Result r = run("simulate " + kConfigs + "one_step_100hz.yaml --trajectory " + csv + " --trajectory-interval 0.5");
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream f(csv);
  std::string header;
  std::getline(f, header);
  EXPECT_EQ(header, "t_s,frequency_hz,x_m,y_m,beta1_rad,beta2_rad,mode1,mode2");
  int lines = 0;
  for (std::string l; std::getline(f, l);) ++lines;
  EXPECT_EQ(lines, 77);  // t = 0, 0.5, ..., 38 s
}

TEST(SimulateCli, BadInputGivesOneClearMessageAndStatus2) {
  struct Case {
    std::string yaml, extra, message;
  };
  const Case cases[] = {
      {"abu: {frition_mu: 0.02}\n", "", "abu.frition_mu = 0.02: unknown key (misspelt, or not valid here); did you mean 'friction_mu'?"},
      {"abu: {friction_mu: lots}\n", "", "abu.friction_mu = lots: must be a number"},
      {"abu: {friction_mu: 1.5}\n", "", "abu.friction_mu = 1.5: must be in [0, 0.999]"},
      {"profile: {segments: [{end_frequency_hz: 25, duration_s: -2}]}\n", "",
       "profile.segments[0].duration_s = -2: must be > 0"},
      {"profile: {segments: []}\n", "", "profile.segments = []: must have at least one segment"},
      {"simulation: {method: magic}\n", "", "simulation.method = magic: must be one of: event_driven, switch_model"},
      {"abu: {balls: [{mass_kg: 1e-4, diameter_m: 0.02}]}\n", "",
       "abu.balls[0].diameter_m = 0.02: must be smaller than abu.ball_track_radius_m (0.0115)"},
      {"simulation: {rtol: 1e-6}\n", "--beta0 1,2,3", "--beta0 = 1,2,3: must give 2 angles (one per ball)"},
      {"{}\n", "--beta0 1,x", "--beta0 = 1,x: 'x' is not a number; must be a comma-separated list of finite angles in rad"},
  };
  int k = 0;
  for (const auto& c : cases) {
    const std::string path = write_config("bad_" + std::to_string(k++) + ".yaml", c.yaml);
    const Result r = run("simulate " + path + " " + c.extra);
    EXPECT_EQ(r.status, 2) << c.yaml << r.output;
    EXPECT_EQ(r.output, "abuopt: error: " + c.message + "\n") << c.yaml;
  }
  const Result missing = run("simulate /nonexistent/none.yaml");
  EXPECT_EQ(missing.status, 2);
  EXPECT_EQ(missing.output, "abuopt: error: config file '/nonexistent/none.yaml' cannot be opened (missing or unreadable)\n");
  const Result notyaml = run("simulate " + write_config("bad_syntax.yaml", "abu: [1, 2\n"));
  EXPECT_EQ(notyaml.status, 2);
  EXPECT_NE(notyaml.output.find("is not valid YAML: line"), std::string::npos) << notyaml.output;
}

TEST(SimulateCli, HelpExplainsTheCommand) {
  const Result r = run("simulate --help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.output.find("--beta0"), std::string::npos);
  EXPECT_NE(r.output.find("--trajectory"), std::string::npos);
  EXPECT_NE(r.output.find("--json"), std::string::npos);
}

// The study's ready-to-run designs carry a montecarlo section (for `abuopt montecarlo`); simulate
// checks it and runs the profile; a bad key in it is still an error naming the key.
TEST(SimulateCli, RunsConfigsWithAMontecarloSection) {
  const Result r = run("simulate " + kConfigs + "designs/two_balls_19s.yaml --beta0 0.5,3.0 --json");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(r.output)["status"], "ok");
  const std::string bad = write_config("simulate_bad_mc.yaml", "montecarlo: {runz: 3}\n");
  const Result b = run("simulate " + bad);
  EXPECT_EQ(b.status, 2);
  EXPECT_NE(b.output.find("montecarlo.runz"), std::string::npos) << b.output;
}

// Every shipped design (configs/designs/; issue 10: "abuopt simulate and abuopt montecarlo run it as
// it is") runs unchanged: simulate with the command its header documents, and a Monte Carlo of 4 random
// starts whose runs all end ok (the designs were validated on 1024; a config that no longer parses
// or a profile that no longer simulates fails here).
TEST(SimulateCli, EveryShippedStudyDesignRunsWithSimulateAndMontecarlo) {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(kConfigs + "designs"))
    if (e.path().extension() == ".yaml") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 10u);  // the catalogue, configs/designs/README.md
  for (const std::string& f : files) {
    // The command the config documents in its header ("abuopt simulate THIS.yaml --beta0 ..."), as it is.
    std::ifstream in(f);
    std::string line, args;
    while (std::getline(in, line)) {
      const std::size_t at = line.find("abuopt simulate THIS.yaml");
      if (at != std::string::npos) {
        args = line.substr(at + std::string("abuopt simulate THIS.yaml").size());
        args = args.substr(0, args.find('#'));
        break;
      }
    }
    const Result s = run("simulate " + f + args + " --json");
    ASSERT_EQ(s.status, 0) << f << "\n" << s.output;
    EXPECT_EQ(nlohmann::json::parse(s.output)["status"], "ok") << f;
    const Result m = abuopt::test::run_abuopt("montecarlo " + f + " --runs 4 --threads 1 --json", "", false);
    ASSERT_EQ(m.status, 0) << f << "\n" << m.output;
    const nlohmann::json j = nlohmann::json::parse(m.output);
    EXPECT_EQ(j["runs"], 4) << f;
    EXPECT_EQ(j["ok"], 4) << f;
  }
}
