// `abuopt reproduce` end to end on the built binary, with few runs per case: exit status, the
// Markdown report and tables CSV, every published row of the tables run named in the output, the
// per-case run CSVs, a run without gnuplot, and a bad table id.
#include <gtest/gtest.h>

#include "abuopt_cli.hpp"

#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace {

using Result = abuopt::test::CliResult;

Result run(const std::string& args, const std::string& env = "") { return abuopt::test::run_abuopt(args, env); }

std::string read_all(const std::string& path) {
  std::ifstream f(path);
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

std::size_t count_lines(const std::string& path) {
  std::ifstream f(path);
  std::string line;
  std::size_t n = 0;
  while (std::getline(f, line)) ++n;
  return n;
}

const std::string kConfigs = std::string(ABUOPT_SOURCE_DIR) + "/configs/report";
const std::string kOut = std::string(ABUOPT_BINARY_DIR) + "/reproduce_test_out";

TEST(ReproduceCli, Tables44AndFinalWith16Runs) {
  std::filesystem::remove_all(kOut);
  const Result r = run("reproduce --runs 16 --only 4.4,final --threads 2 --configs " + kConfigs + " --out " + kOut);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("--runs 16: every case uses 4 x 4 grid = 16 runs"), std::string::npos) << r.output;
  // Every published row of the two tables, with the report's values beside ours.
  for (const char* label : {"three-step, 19 s", "one-step, 2 s", "one-step, 4 s", "one-step, 6 s", "one-step, 8 s",
                            "one-step, 10 s", "one-step, 19 s", "final profile, 19 s"})
    EXPECT_NE(r.output.find(label), std::string::npos) << label;
  for (const char* ref : {"/ 8.53", "/ 25.11", "/ 20.73", "/ 12.78", "/ 21.49", "/ 20.20", "/ 17.13", "/ 8.96",
                          "/ 61.33", "/ 37.11", "/ 1.56"})
    EXPECT_NE(r.output.find(ref), std::string::npos) << ref;
  EXPECT_NE(r.output.find("(a) [table 4.4]"), std::string::npos) << r.output;
  // One progress line per case with its wall time.
  EXPECT_NE(r.output.find("[1/8] 4.4 three-step, 19 s: 16 runs in"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("[8/8] final final profile, 19 s: 16 runs in"), std::string::npos) << r.output;

  ASSERT_TRUE(std::filesystem::exists(kOut + "/report.md"));
  ASSERT_TRUE(std::filesystem::exists(kOut + "/tables.csv"));
  EXPECT_EQ(count_lines(kOut + "/tables.csv"), 1u + 8u);
  EXPECT_EQ(count_lines(kOut + "/runs/4.4/three_step.csv"), 1u + 16u);
  EXPECT_EQ(count_lines(kOut + "/runs/final/final.csv"), 1u + 16u);
  // Both tables carry contact_variant: hard, an extra column set of the same starts with contact.
  EXPECT_NE(r.output.find("mean I_r,x (contact)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("What ball contact (hard) changes"), std::string::npos) << r.output;
  EXPECT_EQ(count_lines(kOut + "/tables_contact.csv"), 1u + 8u);
  EXPECT_EQ(count_lines(kOut + "/runs/4.4/three_step_contact_hard.csv"), 1u + 16u);
  EXPECT_EQ(count_lines(kOut + "/runs/final/final_contact_hard.csv"), 1u + 16u);
  const std::string md = read_all(kOut + "/report.md");
  EXPECT_NE(md.find("| one-step, 19 s | 16 |"), std::string::npos);
  EXPECT_NE(md.find("wall time:"), std::string::npos);
  EXPECT_NE(md.find("## Verdicts"), std::string::npos);
  // The plots' data is written whether or not gnuplot runs.
  EXPECT_TRUE(std::filesystem::exists(kOut + "/plots/fig_4_7_final_positions.csv"));
  EXPECT_TRUE(std::filesystem::exists(kOut + "/plots/final_settling_histogram.csv"));
  EXPECT_TRUE(std::filesystem::exists(kOut + "/plots/final_positions_equilibrium_set.csv"));
}

TEST(ReproduceCli, WithoutGnuplotTheStudyRunsAndSaysWhichPlotsItSkipped) {
  const std::string out = kOut + "_nognuplot";
  std::filesystem::remove_all(out);
  const Result r = run("reproduce --runs 4 --only final --threads 1 --configs " + kConfigs + " --out " + out,
                       "ABUOPT_GNUPLOT=/nonexistent/gnuplot");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("final_settling_histogram: skipped"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("final_positions_equilibrium_set: skipped"), std::string::npos) << r.output;
  EXPECT_TRUE(std::filesystem::exists(out + "/report.md"));
  EXPECT_NE(read_all(out + "/report.md").find("skipped"), std::string::npos);
}

TEST(ReproduceCli, UnknownTableIdIsAUserError) {
  const Result r = run("reproduce --only 4.1,4.9 --configs " + kConfigs + " --out " + kOut + "_bad");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--only = 4.9"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("4.1, 4.2, 4.3, 4.4, final, mu"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(kOut + "_bad"));
}

}  // namespace
