// Runs made outside abuopt (e.g. examples/python/optuna_study.py) in a comparison
// (SolverSpec::external_runs, optimizer/src/external_runs.cpp): read, judged like the native runs,
// and bad files as ConfigErrors naming the file before anything runs.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/benchmarking.hpp"
#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"

namespace {

using namespace abuopt;

const std::string kHeader = "evaluation,ok,objective,max_violation,x1,x2,x3,x4\n";

void write(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream(path) << text;
}

opt::ComparisonSetup setup_with(const std::string& dir) {
  opt::ComparisonSetup setup;
  opt::ProblemSpec spec;
  spec.label = "hs071";
  spec.make = [] { return opt::benchmarks::make_benchmark("hs071"); };
  spec.max_evaluations = 50;
  spec.starts = 2;
  setup.problems.push_back(spec);
  setup.solvers.push_back(opt::solver_spec("COBYLA", "cobyla"));
  opt::SolverSpec ext;
  ext.label = "Outside";
  ext.external_runs = dir;
  setup.solvers.push_back(ext);
  return setup;
}

TEST(ExternalRuns, AreJudgedBesideTheNativeOnes) {
  const std::string dir = std::string(ABUOPT_BINARY_DIR) + "/external_runs_a";
  std::filesystem::remove_all(dir);
  // hs071: f* = 17.0140173 at (1, 4.743, 3.8211, 1.3794); start 0 reaches it at evaluation 3,
  // start 1 only infeasible or failed points
  write(opt::external_run_path(dir, "hs071", 0),
        kHeader + "1,1,16,1,1,5,5,1\n2,1,30,0,2,2,2,2\n3,1,17.02,0,1,4.743,3.8211,1.3794\n");
  write(opt::external_run_path(dir, "hs071", 1), kHeader + "1,0,inf,inf,1,1,1,1\n2,1,12,0.5,1,1,1,1\n");
  const opt::ComparisonResult r = opt::run_comparison(setup_with(dir));
  ASSERT_EQ(r.runs.size(), 4u);
  const opt::RunRecord& a = r.runs[1];  // start 0, Outside
  EXPECT_EQ(a.solver, "Outside");
  EXPECT_EQ(a.result.evaluations, 3);
  EXPECT_TRUE(a.feasible);
  EXPECT_DOUBLE_EQ(a.best_true_objective, 17.02);
  EXPECT_EQ(a.evaluations_to_solve, 3);  // 17.02 - 17.014 <= 0.01 * 17.014
  EXPECT_EQ((std::vector<double>{1, 4.743, 3.8211, 1.3794}), a.result.x);
  const opt::RunRecord& b = r.runs[3];  // start 1, Outside
  EXPECT_FALSE(b.feasible);
  EXPECT_EQ(b.result.failed_evaluations, 1);
  EXPECT_EQ(b.evaluations_to_solve, -1);
  EXPECT_DOUBLE_EQ(b.result.max_violation, 0.5);  // the least violation when none is feasible
  std::filesystem::remove_all(dir);
}

TEST(ExternalRuns, BadFilesAreConfigErrorsNamingThem) {
  const std::string dir = std::string(ABUOPT_BINARY_DIR) + "/external_runs_b";
  std::filesystem::remove_all(dir);
  write(opt::external_run_path(dir, "hs071", 0), kHeader + "1,1,20,0,1,5,5,1\n");
  // start 1 missing: refused before any run
  try {
    (void)opt::run_comparison(setup_with(dir));
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("start1.csv"), std::string::npos) << e.what();
  }
  auto problem = opt::benchmarks::make_benchmark("hs071");
  const std::string path = dir + "/bad.csv";
  write(path, "evaluation,ok,objective,max_violation,a,b,c,d\n");
  EXPECT_THROW((void)opt::read_external_run(path, *problem, 1e-6, 50), ConfigError);  // variable names
  write(path, kHeader + "1,1,20,0,1,5,5,9\n");  // x4 = 9 above its bound 5
  EXPECT_THROW((void)opt::read_external_run(path, *problem, 1e-6, 50), ConfigError);
  write(path, kHeader + "2,1,20,0,1,5,5,1\n");  // numbering
  EXPECT_THROW((void)opt::read_external_run(path, *problem, 1e-6, 50), ConfigError);
  write(path, kHeader + "1,1,20,0,1,5,5,1\n2,1,20,0,1,5,5,1\n");  // over a budget of 1
  EXPECT_THROW((void)opt::read_external_run(path, *problem, 1e-6, 1), ConfigError);
  write(path, kHeader + "1,1,twenty,0,1,5,5,1\n");
  try {
    (void)opt::read_external_run(path, *problem, 1e-6, 50);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("line 2 objective"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
