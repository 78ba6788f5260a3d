// The ADOPT suite's quick form end to end (configs/compare/adopt_suite_quick.yaml, issue 33): every
// method runs on the three startup problems (nominal, over issue 30's envelope, the ball count as a
// variable), every run's design is
// validated out of sample, and scripts/benchmarks_report.py turns the output into the table of
// docs/benchmarks.md with a row per method. About a minute on 2 cores: label long.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

int run(const std::string& cmd) {
  const int st = std::system(cmd.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

std::string read(const fs::path& p) {
  std::ifstream f(p);
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

}  // namespace

TEST(AdoptSuiteCli, QuickFormRunsEveryMethodAndFeedsTheReport) {
  const fs::path dir = fs::path(ABUOPT_BINARY_DIR) / "adopt_suite_quick";
  fs::remove_all(dir);
  const std::string src = ABUOPT_SOURCE_DIR;
  ASSERT_EQ(run(std::string(ABUOPT_EXE) + " compare " + src + "/configs/compare/adopt_suite_quick.yaml --out " +
                dir.string() + " > " + dir.string() + ".log 2>&1"),
            0)
      << read(dir.string() + ".log");
  std::istringstream runs(read(dir / "runs.csv"));
  std::string line;
  std::getline(runs, line);  // header
  std::map<std::string, int> per_solver;
  int lines = 0, validated = 0;
  while (std::getline(runs, line)) {
    ++lines;
    // the fields before `message` hold no comma: solver is field 2, validated_objective field 16
    std::vector<std::string> f;
    std::istringstream is(line);
    for (std::string cell; f.size() < 17 && std::getline(is, cell, ',');) f.push_back(cell);
    ASSERT_EQ(f.size(), 17u) << line;
    ++per_solver[f[2]];
    if (!f[16].empty()) ++validated;
  }
  EXPECT_EQ(lines, 3 * 2 * 7);  // problems x starts x methods
  EXPECT_EQ(validated, lines);  // every run's design checked out of sample
  for (const char* s : {"SAO", "COBYLA", "SBPLX", "CMA-ES", "xNES", "SADE", "PSO"}) EXPECT_EQ(per_solver[s], 6) << s;
  // two_ball_19s validates each run's incumbent at 4 checkpoints (6, 12, 18, 24 evaluations)
  std::istringstream checks(read(dir / "validated_convergence.csv"));
  std::getline(checks, line);
  int checkpoints = 0;
  while (std::getline(checks, line)) {
    ++checkpoints;
    EXPECT_EQ(line.rfind("two_ball_19s,", 0), 0u) << line;
  }
  EXPECT_GE(checkpoints, 2 * 7 * 3);  // a checkpoint before a run's first feasible point is left out
  EXPECT_LE(checkpoints, 2 * 7 * 4);
  if (run("python3 -c 'import sys' 2>/dev/null") != 0) GTEST_SKIP() << "no python3 for the report";
  const fs::path md = fs::path(ABUOPT_BINARY_DIR) / "adopt_suite_quick.md";
  ASSERT_EQ(run("python3 " + src + "/scripts/benchmarks_report.py " + dir.string() + " --out " + md.string()), 0);
  const std::string text = read(md);
  for (const char* p : {"### two_ball_19s", "### two_ball_envelope", "### ball_count_19s", "| PSO |", "| SAO |", "evals to 2 %",
                        "evals to 2 % (out)", "measured out of sample"})
    EXPECT_NE(text.find(p), std::string::npos) << p << "\n" << text;
  fs::remove_all(dir);
}
