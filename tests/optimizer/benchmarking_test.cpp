// Comparison tooling: the data-profile and performance-profile arithmetic against a hand-worked
// case, the "solved" test, and a small end-to-end comparison with its files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/benchmarking.hpp"
#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"

namespace {

using namespace abuopt;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Hand-worked case: 4 instances, 2 solvers A and B; t = evaluations to solve (inf: never).
//   instance  n_p  t_A  t_B   alpha (n_p+1) threshold   best   r_A  r_B
//   p0        2    6    12    3 alpha                   6      1    2
//   p1        1    inf  4     2 alpha                   4      inf  1
//   p2        3    20   10    4 alpha                   10     2    1
//   p3        2    inf  inf   3 alpha                   -      inf  inf
// Data profile d(alpha) for alpha = 1, 2, 3, 5:
//   A: p0 needs alpha >= 2, p2 alpha >= 5           -> 0, 1/4, 1/4, 2/4
//   B: p1 alpha >= 2, p2 alpha >= 2.5, p0 alpha >= 4 -> 0, 1/4, 2/4, 3/4
// Performance profile rho(tau) for tau = 1, 1.5, 2, 100:
//   A: r = {1, inf, 2, inf} -> 1/4, 1/4, 2/4, 2/4
//   B: r = {2, 1, 1, inf}   -> 2/4, 2/4, 3/4, 3/4
const std::vector<std::vector<double>> kT = {{6, 12}, {kInf, 4}, {20, 10}, {kInf, kInf}};
const std::vector<std::size_t> kDims = {2, 1, 3, 2};

TEST(Profiles, DataProfileHandWorked) {
  const std::vector<double> alphas = {1, 2, 3, 5};
  EXPECT_EQ(opt::data_profile(kT, kDims, 0, alphas), (std::vector<double>{0, 0.25, 0.25, 0.5}));
  EXPECT_EQ(opt::data_profile(kT, kDims, 1, alphas), (std::vector<double>{0, 0.25, 0.5, 0.75}));
}

TEST(Profiles, PerformanceRatiosHandWorked) {
  const auto r = opt::performance_ratios(kT);
  EXPECT_EQ(r[0], (std::vector<double>{1, 2}));
  EXPECT_EQ(r[1], (std::vector<double>{kInf, 1}));
  EXPECT_EQ(r[2], (std::vector<double>{2, 1}));
  EXPECT_EQ(r[3], (std::vector<double>{kInf, kInf}));
}

TEST(Profiles, PerformanceProfileHandWorked) {
  const std::vector<double> taus = {1, 1.5, 2, 100};
  EXPECT_EQ(opt::performance_profile(kT, 0, taus), (std::vector<double>{0.25, 0.25, 0.5, 0.5}));
  EXPECT_EQ(opt::performance_profile(kT, 1, taus), (std::vector<double>{0.5, 0.5, 0.75, 0.75}));
}

// Solved = the first FEASIBLE evaluation with f - f* <= tau max(|f*|, 1), using the true
// (noise-free) objective when the evaluation reports it.
TEST(Profiles, EvaluationsToSolve) {
  opt::OptimizationResult r;
  auto add = [&](double f, bool feasible, std::optional<double> noise_free = std::nullopt) {
    opt::EvaluationRecord h;
    h.index = static_cast<long>(r.history.size());
    h.objective = f;
    h.feasible = feasible;
    if (noise_free) h.metrics["noise_free_objective"] = *noise_free;
    r.history.push_back(h);
  };
  add(30, true);        // 1: far
  add(10.0, false);     // 2: at f* but infeasible
  add(10.05, true, 10.2);  // 3: noisy value within, true value 10.2 > 10 + 0.1
  add(10.09, true);     // 4: within 0.01 * 10
  EXPECT_EQ(opt::evaluations_to_solve(r, 10.0, 0.01), 4);
  EXPECT_EQ(opt::evaluations_to_solve(r, 10.0, 0.01, ""), 3);  // metric ignored: noisy value counts
  EXPECT_EQ(opt::evaluations_to_solve(r, 10.0, 1e-4), -1);
  // |f*| < 1: the threshold is tau, not tau |f*|
  opt::OptimizationResult z;
  opt::EvaluationRecord h;
  h.index = 0;
  h.objective = 0.005;
  h.feasible = true;
  z.history.push_back(h);
  EXPECT_EQ(opt::evaluations_to_solve(z, 0.0, 0.01), 1);
}

TEST(Profiles, SolveMatrixFromRuns) {
  opt::ComparisonResult c;
  c.solvers = {"A", "B"};
  c.problems = {"p"};
  for (int start = 0; start < 2; ++start)
    for (const char* s : {"A", "B"}) {
      opt::RunRecord r;
      r.problem = "p";
      r.solver = s;
      r.start = start;
      r.dimension = 3;
      r.evaluations_to_solve = start == 0 ? (s[0] == 'A' ? 5 : -1) : 7;
      c.runs.push_back(r);
    }
  const auto t = c.solve_matrix();
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0], (std::vector<double>{5, kInf}));
  EXPECT_EQ(t[1], (std::vector<double>{7, 7}));
  EXPECT_EQ(c.instance_dimensions(), (std::vector<std::size_t>{3, 3}));
}

TEST(Comparison, RunsEverySolverFromEveryStartAndWritesFiles) {
  opt::ComparisonSetup setup;
  opt::ProblemSpec truss;
  truss.label = "two_bar_truss";
  truss.make = [] { return opt::benchmarks::make_benchmark("two_bar_truss"); };
  truss.max_evaluations = 150;
  truss.starts = 2;
  setup.problems.push_back(truss);
  opt::ProblemSpec rosen;
  rosen.label = "rosenbrock";
  rosen.make = [] { return opt::benchmarks::make_benchmark("rosenbrock"); };
  rosen.max_evaluations = 100;
  setup.problems.push_back(rosen);
  setup.solvers.push_back(opt::solver_spec("SAO", "sao"));
  setup.solvers.push_back(opt::solver_spec("COBYLA", "cobyla"));
  int callbacks = 0;
  setup.on_run = [&](const opt::RunRecord&) { ++callbacks; };
  const opt::ComparisonResult r = opt::run_comparison(setup);
  ASSERT_EQ(r.runs.size(), 6u);  // (2 + 1 starts) x 2 solvers
  EXPECT_EQ(callbacks, 6);
  EXPECT_EQ(r.f_star_source[0], "best_known");
  for (const auto& run : r.runs) {
    EXPECT_LE(run.result.evaluations, run.problem == "rosenbrock" ? 100 : 150);
    EXPECT_FALSE(run.result.history.empty());
  }
  // the second start is random but inside the bounds, and not the initial point
  EXPECT_NE(r.runs[2].x0, r.runs[0].x0);
  EXPECT_EQ(r.runs[2].x0, r.runs[3].x0);  // every solver starts from the same point
  // the truss is solved by SAO from its initial point
  EXPECT_GT(r.runs[0].evaluations_to_solve, 0);
  const std::string table = opt::format_table(r);
  EXPECT_NE(table.find("two_bar_truss"), std::string::npos);
  EXPECT_NE(table.find("COBYLA"), std::string::npos);

  const std::string dir = std::string(ABUOPT_BINARY_DIR) + "/benchmarking_test_out";
  std::filesystem::remove_all(dir);
  const opt::WrittenFiles files = opt::write_comparison(r, dir, /*make_plots=*/false);
  for (const char* name : {"runs.csv", "convergence.csv", "data_profile.csv", "performance_profile.csv", "plots.gp"})
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(dir) / name)) << name;
  EXPECT_EQ(files.skipped_plots.size(), 4u);  // 2 profiles + 2 convergence plots
  std::ifstream runs(std::filesystem::path(dir) / "runs.csv");
  std::string header;
  std::getline(runs, header);
  EXPECT_EQ(header.rfind("problem,start,solver,", 0), 0u);
  std::filesystem::remove_all(dir);
}

// The runs of a problem are independent: running 1 or 4 at a time gives the same runs, in the
// same order, evaluation for evaluation (only wall times differ). SAO, COBYLA and AUGLAG(COBYLA) on
// a smooth and a noisy problem, 5 starts each.
TEST(Comparison, ResultsDoNotDependOnHowManyRunsAtOnce) {
  auto setup_with = [](int threads) {
    opt::ComparisonSetup setup;
    for (const char* name : {"hs071", "noisy_cantilever"}) {
      opt::ProblemSpec p;
      p.label = name;
      p.make = [name] { return opt::benchmarks::make_benchmark(name); };
      // A budget of 60 is enough to exercise the interleaving of runs over threads (SAO's
      // model fits dominate the cost; under ASan 120 evaluations x 5 starts took minutes).
      p.max_evaluations = 60;
      p.starts = 3;
      p.seed = 9;
      setup.problems.push_back(p);
    }
    setup.solvers.push_back(opt::solver_spec("SAO", "sao"));
    setup.solvers.push_back(opt::solver_spec("COBYLA", "cobyla"));
    setup.solvers.push_back(opt::solver_spec("AUGLAG", "auglag"));
    setup.solvers.back().options.local_algorithm = "cobyla";
    setup.threads = threads;
    std::vector<std::string> order;
    setup.on_run = [&order](const opt::RunRecord& r) { order.push_back(r.problem + r.solver + std::to_string(r.start)); };
    opt::ComparisonResult r = opt::run_comparison(setup);
    return std::make_pair(std::move(r), order);
  };
  const auto [serial, serial_order] = setup_with(1);
  const auto [parallel, parallel_order] = setup_with(4);
  ASSERT_EQ(serial.runs.size(), 18u);  // 2 problems x 3 solvers x 3 starts
  ASSERT_EQ(parallel.runs.size(), serial.runs.size());
  EXPECT_EQ(parallel_order, serial_order);
  for (std::size_t i = 0; i < serial.runs.size(); ++i) {
    const auto& a = serial.runs[i].result;
    const auto& b = parallel.runs[i].result;
    EXPECT_EQ(serial.runs[i].solver, parallel.runs[i].solver);
    EXPECT_EQ(a.evaluations, b.evaluations) << i;
    EXPECT_EQ(a.x, b.x) << i;
    EXPECT_EQ(a.objective, b.objective) << i;
    ASSERT_EQ(a.history.size(), b.history.size()) << i;
    for (std::size_t k = 0; k < a.history.size(); ++k) EXPECT_EQ(a.history[k].x, b.history[k].x) << i << " " << k;
    EXPECT_EQ(serial.runs[i].evaluations_to_solve, parallel.runs[i].evaluations_to_solve) << i;
  }
}

TEST(Comparison, BadSetupIsAConfigError) {
  opt::ComparisonSetup setup;
  EXPECT_THROW(opt::run_comparison(setup), ConfigError);
  opt::ProblemSpec p;
  p.label = "truss";
  p.make = [] { return opt::benchmarks::make_benchmark("two_bar_truss"); };
  p.max_evaluations = 0;
  setup.problems.push_back(p);
  setup.solvers.push_back(opt::solver_spec("SAO", "sao"));
  try {
    opt::run_comparison(setup);
    FAIL() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "compare.problems[truss].max_evaluations = 0: must be > 0");
  }
  EXPECT_THROW(opt::solver_spec("X", "simplex"), ConfigError);
}

TEST(Comparison, ReadSolverSpec) {
  YamlReader root = YamlReader::load_string(
      "solvers:\n"
      "  - {label: SAO-q, algorithm: sao, sao: {surrogate: quadratic}}\n"
      "  - {algorithm: slsqp, options: {finite_difference: central}}\n"
      "  - {algorithm: cobyla, sao: {surrogate: linear}}\n");
  auto entries = root.children("solvers");
  const opt::SolverSpec a = opt::read_solver_spec(entries[0]);
  EXPECT_EQ(a.label, "SAO-q");
  EXPECT_EQ(a.options.sao.surrogate, opt::SurrogateKind::Quadratic);
  const opt::SolverSpec b = opt::read_solver_spec(entries[1]);
  EXPECT_EQ(b.label, "slsqp");
  EXPECT_EQ(b.options.finite_difference, opt::FiniteDifference::Central);
  try {
    opt::read_solver_spec(entries[2]);
    FAIL() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "solvers[2].sao = <section>: only for algorithm sao (this solver is cobyla)");
  }
}

}  // namespace
