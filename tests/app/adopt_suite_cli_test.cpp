// The ADOPT suite's quick form end to end (configs/compare/adopt_suite_quick.yaml, issue 33): every
// method runs on the three startup problems (nominal, over issue 30's envelope, the ball count as a
// variable), every run's design is
// validated out of sample, the two-objective problem's fronts (NSGA-II, epsilon-constraint) are
// written with their hypervolumes, and scripts/benchmarks_report.py turns the output into the
// tables of docs/benchmarks.md with a row per method. 8 s on a quiet 2-core machine, about a minute loaded; in the default suite, so CI
// runs the suite's quick form.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
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

  // the two-objective problem: hypervolume.csv has a row per method and run, finite and >= 0, each
  // method with a positive hypervolume in and out of sample in some run, and fronts.csv its points
  std::istringstream hv(read(dir / "hypervolume.csv"));
  std::getline(hv, line);
  EXPECT_EQ(line.rfind("problem,method,run,evaluations,budget,inner_budget,hv_in,hv_out,points_in,points_out", 0), 0u)
      << line;
  std::map<std::string, double> best_in, best_out;
  int hv_rows = 0;
  while (std::getline(hv, line)) {
    ++hv_rows;
    std::vector<std::string> f;
    std::istringstream is(line);
    for (std::string cell; std::getline(is, cell, ',');) f.push_back(cell);
    ASSERT_GE(f.size(), 10u) << line;
    const double in = std::stod(f[6]), out = std::stod(f[7]);
    EXPECT_TRUE(std::isfinite(in) && in >= 0 && std::isfinite(out) && out >= 0) << line;
    EXPECT_LE(std::stol(f[3]), std::stol(f[4])) << line;  // evaluations within the budget
    best_in[f[1]] = std::max(best_in[f[1]], in);
    best_out[f[1]] = std::max(best_out[f[1]], out);
  }
  EXPECT_EQ(hv_rows, 2 * 2);  // methods x seeds
  for (const char* m : {"NSGA-II", "eps-constraint"}) {
    EXPECT_GT(best_in[m], 0.0) << m;
    EXPECT_GT(best_out[m], 0.0) << m;
  }
  const std::string fronts = read(dir / "fronts.csv");
  EXPECT_NE(fronts.find("\ntime_vs_imbalance,NSGA-II,"), std::string::npos) << fronts;
  EXPECT_NE(fronts.find("\ntime_vs_imbalance,eps-constraint,"), std::string::npos) << fronts;
  if (run("python3 -c 'import sys' 2>/dev/null") != 0) GTEST_SKIP() << "no python3 for the report";
  const fs::path md = fs::path(ABUOPT_BINARY_DIR) / "adopt_suite_quick.md";
  ASSERT_EQ(run("python3 " + src + "/scripts/benchmarks_report.py " + dir.string() + " --out " + md.string()), 0);
  const std::string text = read(md);
  for (const char* p : {"### two_ball_19s", "### two_ball_envelope", "### ball_count_19s", "| PSO |", "| SAO |", "evals to 2 %",
                        "evals to 2 % (out)", "measured out of sample", "### time_vs_imbalance (two objectives)",
                        "| NSGA-II | 2 |", "| eps-constraint | 2 |", "Best front"})
    EXPECT_NE(text.find(p), std::string::npos) << p << "\n" << text;
  fs::remove_all(dir);
}
