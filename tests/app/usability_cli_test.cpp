// The command line helps a user who mistypes: "did you mean" for a subcommand, a flag and a config
// key; long commands show progress on stderr only when asked (or on a terminal).
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "abuopt_cli.hpp"

namespace {

using abuopt::test::run_abuopt;

const std::string kConfigs = std::string(ABUOPT_SOURCE_DIR) + "/configs/";

TEST(UsabilityCli, MisspeltSubcommandGetsASuggestion) {
  const auto r = run_abuopt("montecarol " + kConfigs + "montecarlo_final_profile.yaml");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("'montecarol' is not a command; did you mean 'montecarlo'?"), std::string::npos) << r.output;
}

TEST(UsabilityCli, MisspeltFlagGetsASuggestion) {
  const auto r = run_abuopt("montecarlo " + kConfigs + "montecarlo_final_profile.yaml --seeds 3");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("'--seeds' is not an option; did you mean '--seed'?"), std::string::npos) << r.output;
  const auto q = run_abuopt("reproduce --no-plot");
  EXPECT_EQ(q.status, 2);
  EXPECT_NE(q.output.find("did you mean '--no-plots'?"), std::string::npos) << q.output;
}

TEST(UsabilityCli, NothingCloseGivesNoGuess) {
  const auto r = run_abuopt("frobnicate");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output.find("did you mean"), std::string::npos) << r.output;
}

TEST(UsabilityCli, MisspeltConfigKeyGetsASuggestion) {
  const std::string path = std::string(ABUOPT_BINARY_DIR) + "/usability_misspelt.yaml";
  std::ofstream(path) << "abu: {fricton_mu: 0.02}\n";
  const auto r = run_abuopt("simulate " + path + " --beta0 0.5,3.0");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("abu.fricton_mu = 0.02: unknown key (misspelt, or not valid here); did you mean "
                          "'friction_mu'?"),
            std::string::npos)
      << r.output;
}

TEST(UsabilityCli, ProgressOnlyWhenAskedOffATerminal) {
  // stderr is a pipe here: no progress line unless --progress.
  const std::string base = "montecarlo " + kConfigs + "montecarlo_final_profile.yaml --runs 16 --design random --threads 1";
  const auto quiet = run_abuopt(base);
  ASSERT_EQ(quiet.status, 0) << quiet.output;
  EXPECT_EQ(quiet.output.find("Monte Carlo: 16/16 runs"), std::string::npos) << quiet.output;
  const auto shown = run_abuopt(base + " --progress");
  ASSERT_EQ(shown.status, 0) << shown.output;
  EXPECT_NE(shown.output.find("Monte Carlo: 16/16 runs (100.0 %)"), std::string::npos) << shown.output;
  EXPECT_EQ(shown.output.find('\r'), std::string::npos);  // whole lines off a terminal
}

}  // namespace
