// The command line helps a user who mistypes: "did you mean" for a subcommand, a flag and a config
// key; long commands show progress on stderr only when asked (or on a terminal).
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
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

// A config that serves several commands is accepted by each (eqset ignores the montecarlo section);
// a misspelt section is still refused, its value shown briefly, not as the whole section.
TEST(UsabilityCli, EqsetReadsAMonteCarloConfig) {
  const std::string out = std::string(ABUOPT_BINARY_DIR) + "/usability_eqset";
  const auto r = run_abuopt("eqset " + kConfigs + "montecarlo_final_profile.yaml --freq 29 --grid 16 --out " + out);
  EXPECT_EQ(r.status, 0) << r.output;
  const std::string path = std::string(ABUOPT_BINARY_DIR) + "/usability_section.yaml";
  std::ifstream in(kConfigs + "montecarlo_final_profile.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("montecarlo:"), 11, "montecalro:");
  std::ofstream(path) << text;
  const auto bad = run_abuopt("eqset " + path + " --freq 29 --grid 16 --out " + out);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.output.find("montecalro = {design: grid, grid: 32, runs: 1024, seed: 1, threads: 0, ...}: unknown key "
                            "(misspelt, or not valid here); did you mean 'montecarlo'?"),
            std::string::npos)
      << bad.output;
}

// The terms are printed in full once, in `abuopt --help`; a command's help and output point there.
TEST(UsabilityCli, TermsOnceInHelpNotAfterEveryCommand) {
  auto count = [](const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
  };
  const auto top = run_abuopt("--help");
  EXPECT_EQ(count(top.output, "Terms:"), 1u) << top.output;
  EXPECT_NE(top.output.find("95 % half-width"), std::string::npos) << top.output;  // the one "+-" convention
  for (const char* sub : {"archive --help", "archive list --help", "compare --help", "montecarlo --help"}) {
    const auto h = run_abuopt(sub);
    EXPECT_EQ(count(h.output, "Terms:"), 0u) << sub << "\n" << h.output;
  }
  const auto mc = run_abuopt("montecarlo " + kConfigs + "montecarlo_final_profile.yaml --runs 8 --design random --threads 1");
  ASSERT_EQ(mc.status, 0) << mc.output;
  EXPECT_EQ(count(mc.output, "Terms:"), 0u) << mc.output;
  EXPECT_NE(mc.output.find("Terms (I_r, I_r,x, %MI, %LC, +-, units): abuopt --help"), std::string::npos) << mc.output;
}

// simulate prints imbalances in 1e-7 kg m, as the terms say every printout does.
TEST(UsabilityCli, SimulatePrintsTheTermsUnit) {
  const auto r = run_abuopt("simulate " + kConfigs + "montecarlo_final_profile.yaml --beta0 0.5,2.0");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("e-7 kg m, I_r,x = "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("I = 20.72e-7 kg m"), std::string::npos) << r.output;
}

}  // namespace
