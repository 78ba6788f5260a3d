// Comparison tooling: the data-profile and performance-profile arithmetic against a hand-worked
// case, the "solved" test, and a small end-to-end comparison with its files.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>

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

// A sampled problem (own size 256): a value on 64 runs (adaptive sample size) does not count as a
// value of the problem unless it carries the noise-free metric; at 256 runs, or without a `runs`
// metric, or for a problem that is not sampled, it does.
TEST(Profiles, ValuesOnFewerRunsDoNotCount) {
  opt::OptimizationResult r;
  auto add = [&](double f, double runs) {
    opt::EvaluationRecord h;
    h.index = static_cast<long>(r.history.size());
    h.objective = f;
    h.feasible = true;
    h.metrics["runs"] = runs;
    r.history.push_back(h);
  };
  add(10.05, 64);   // 1: within 1 % of 10, but on 64 runs
  add(10.5, 256);   // 2: on 256 runs, not within
  add(10.08, 256);  // 3: within, on 256 runs
  EXPECT_EQ(opt::evaluations_to_solve(r, 10.0, 0.01, "noise_free_objective", 256), 3);
  EXPECT_EQ(opt::evaluations_to_solve(r, 10.0, 0.01, "noise_free_objective", 0), 1);   // not sampled
  EXPECT_EQ(opt::evaluations_to_solve(r, 10.0, 0.01, "noise_free_objective", 64), 1);  // own size 64
  r.history[0].metrics["noise_free_objective"] = 10.05;  // a noise-free value counts at any size
  EXPECT_TRUE(opt::counts_as_problem_value(r.history[0], 256, "noise_free_objective"));
  EXPECT_EQ(opt::evaluations_to_solve(r, 10.0, 0.01, "noise_free_objective", 256), 1);
  r.history[1].metrics.erase("runs");
  EXPECT_TRUE(opt::counts_as_problem_value(r.history[1], 256, "noise_free_objective"));
  EXPECT_FALSE(opt::counts_as_problem_value(r.history[0], 256, ""));
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

// hs071 with the sampled noise: one run's relative noise 0.01, at most 32 runs.
std::unique_ptr<opt::Problem> sampled_noisy_hs071() {
  opt::benchmarks::BenchmarkSettings s;
  s.noise_amplitude = 0.01;
  s.noise_samples = 32;
  return opt::benchmarks::make_benchmark("noisy_hs071", s);
}

// Out-of-sample validation and simulation counts: ProblemSpec::validate is called on every run's
// result (here the noise-free hs071 at the result of a run on its sampled noisy variant), and
// runs.csv carries samples, validated_objective, validated_max_violation and validated_feasible.
TEST(Comparison, ValidatesEveryResultAndCountsSimulations) {
  opt::ComparisonSetup setup;
  opt::ProblemSpec spec;
  spec.label = "sampled_hs071";
  spec.make = sampled_noisy_hs071;
  spec.max_evaluations = 40;
  spec.starts = 2;
  spec.constraint_tolerance = 1e-2;
  int validated = 0;
  spec.validate = [&validated](const std::vector<double>& x) {
    ++validated;
    return opt::benchmarks::make_benchmark("hs071")->evaluate(x);
  };
  setup.problems.push_back(spec);
  setup.solvers.push_back(opt::solver_spec("COBYLA", "cobyla"));
  setup.solvers.push_back(opt::solver_spec("SAO", "sao"));
  const opt::ComparisonResult r = opt::run_comparison(setup);
  ASSERT_EQ(r.runs.size(), 4u);
  EXPECT_EQ(validated, 4);
  auto clean = opt::benchmarks::make_benchmark("hs071");
  for (const auto& run : r.runs) {
    ASSERT_TRUE(run.validation.has_value());
    EXPECT_EQ(run.validation->objective, clean->evaluate(run.result.x).objective);
    EXPECT_EQ(run.validation_feasible, opt::is_feasible(*run.validation, 1e-2));
    EXPECT_EQ(run.result.samples, 32 * run.result.evaluations);
  }
  const std::string dir = std::string(ABUOPT_BINARY_DIR) + "/benchmarking_validation_out";
  std::filesystem::remove_all(dir);
  opt::write_comparison(r, dir, /*make_plots=*/false);
  std::ifstream runs(std::filesystem::path(dir) / "runs.csv");
  std::string header, first;
  std::getline(runs, header);
  std::getline(runs, first);
  EXPECT_NE(header.find(",samples,validated_objective,validated_max_violation,validated_feasible,message"),
            std::string::npos)
      << header;
  EXPECT_NE(first.find("," + std::to_string(r.runs[0].result.samples) + "," +
                       opt::format_number(r.runs[0].validation->objective) + ","),
            std::string::npos)
      << first;
  std::filesystem::remove_all(dir);
}

// The out-of-sample trajectory (ProblemSpec::validation_checkpoints): at evaluations ceil(j B / C)
// the incumbent so far (the best feasible value that counts, as the convergence curve) is validated,
// each distinct point once per run, and validated_convergence.csv lists the checkpoints.
TEST(Comparison, ValidatesTheIncumbentAtCheckpoints) {
  opt::ComparisonSetup setup;
  opt::ProblemSpec spec;
  spec.label = "sampled_hs071";
  spec.make = sampled_noisy_hs071;
  spec.max_evaluations = 30;
  spec.validation_checkpoints = 4;  // at 8, 15, 23, 30
  spec.constraint_tolerance = 1e-2;
  std::map<std::vector<double>, int> calls;
  spec.validate = [&calls](const std::vector<double>& x) {
    ++calls[x];
    return opt::benchmarks::make_benchmark("hs071")->evaluate(x);
  };
  setup.problems.push_back(spec);
  setup.solvers.push_back(opt::solver_spec("COBYLA", "cobyla"));
  const opt::ComparisonResult r = opt::run_comparison(setup);
  ASSERT_EQ(r.runs.size(), 1u);
  const opt::RunRecord& run = r.runs[0];
  auto clean = opt::benchmarks::make_benchmark("hs071");
  std::vector<long> at;
  for (const opt::ValidatedCheckpoint& c : run.validated_convergence) {
    at.push_back(c.evaluation);
    // the incumbent after c.evaluation evaluations, recomputed from the history
    // (by the true objective: the noisy benchmark reports it as the metric noise_free_objective)
    const opt::EvaluationRecord* best = nullptr;
    auto f = [](const opt::EvaluationRecord& h) { return h.metrics.at("noise_free_objective"); };
    for (const auto& h : run.result.history)
      if (h.index < c.evaluation && h.feasible && (!best || f(h) < f(*best))) best = &h;
    ASSERT_NE(best, nullptr);
    const opt::Evaluation e = clean->evaluate(best->x);
    EXPECT_EQ(c.objective, e.objective);
    EXPECT_EQ(c.feasible, opt::is_feasible(e, 1e-2));
  }
  // a checkpoint before the first feasible point is left out; the ones kept are the last of the grid
  const std::vector<long> grid{8, 15, 23, 30};
  ASSERT_FALSE(at.empty());
  EXPECT_TRUE(std::equal(at.rbegin(), at.rend(), grid.rbegin()));
  for (const auto& [x, n] : calls) EXPECT_EQ(n, 1);  // each point validated once, the final result included
  EXPECT_EQ(run.validation->objective, clean->evaluate(run.result.x).objective);
  const std::string dir = std::string(ABUOPT_BINARY_DIR) + "/benchmarking_checkpoints_out";
  std::filesystem::remove_all(dir);
  opt::write_comparison(r, dir, /*make_plots=*/false);
  std::ifstream f(std::filesystem::path(dir) / "validated_convergence.csv");
  std::string line;
  std::getline(f, line);
  EXPECT_EQ(line, "problem,start,solver,evaluation,validated_objective,validated_max_violation,validated_feasible");
  std::size_t rows = 0;
  while (std::getline(f, line)) ++rows;
  EXPECT_EQ(rows, run.validated_convergence.size());
  std::filesystem::remove_all(dir);
}

// Resumable comparisons (ComparisonSetup::archive_directory): a rerun on the archives of a finished
// comparison computes nothing (every evaluation and validation answered from them) and gives the
// same runs bit for bit; a comparison cut short (here: a smaller budget, which ends COBYLA on the
// same path earlier) and then rerun with the full budget answers the stored evaluations and gives
// exactly the runs of a comparison without archives.
TEST(Comparison, ArchivesMakeAComparisonResumable) {
  const std::string dir = std::string(ABUOPT_BINARY_DIR) + "/benchmarking_resume_archive";
  std::filesystem::remove_all(dir);
  std::atomic<int> validated{0};  // the runs go two at a time
  auto setup_with = [&](long budget, const std::vector<std::string>& solvers, const std::string& archive) {
    opt::ComparisonSetup setup;
    opt::ProblemSpec spec;
    spec.label = "sampled hs071";  // a space: the archive's file names are made safe
    spec.identity = "noisy_hs071/a0.01/n32";
    spec.make = sampled_noisy_hs071;
    spec.max_evaluations = budget;
    spec.starts = 2;
    spec.seed = 4;
    spec.constraint_tolerance = 1e-2;
    spec.validate = [&validated](const std::vector<double>& x) {
      ++validated;
      return opt::benchmarks::make_benchmark("hs071")->evaluate(x);
    };
    setup.problems.push_back(spec);
    for (const auto& s : solvers) setup.solvers.push_back(opt::solver_spec(s, s));
    setup.threads = 2;
    setup.archive_directory = archive;
    return setup;
  };
  auto expect_same_runs = [](const opt::ComparisonResult& a, const opt::ComparisonResult& b) {
    ASSERT_EQ(a.runs.size(), b.runs.size());
    for (std::size_t i = 0; i < a.runs.size(); ++i) {
      const auto& x = a.runs[i];
      const auto& y = b.runs[i];
      EXPECT_EQ(x.solver, y.solver);
      EXPECT_EQ(x.start, y.start);
      EXPECT_EQ(x.result.evaluations, y.result.evaluations) << i;
      EXPECT_EQ(x.result.x, y.result.x) << i;
      EXPECT_EQ(x.result.objective, y.result.objective) << i;
      EXPECT_EQ(x.result.samples, y.result.samples) << i;
      EXPECT_EQ(x.result.reason, y.result.reason) << i;
      ASSERT_EQ(x.result.history.size(), y.result.history.size()) << i;
      for (std::size_t k = 0; k < x.result.history.size(); ++k) {
        EXPECT_EQ(x.result.history[k].x, y.result.history[k].x) << i << " " << k;
        EXPECT_EQ(x.result.history[k].objective, y.result.history[k].objective) << i << " " << k;
      }
      EXPECT_EQ(x.best_true_objective, y.best_true_objective) << i;
      EXPECT_EQ(x.evaluations_to_solve, y.evaluations_to_solve) << i;
      ASSERT_EQ(x.validation.has_value(), y.validation.has_value()) << i;
      if (x.validation) {
        EXPECT_EQ(x.validation->objective, y.validation->objective) << i;
      }
    }
  };

  // a finished comparison replayed: nothing computed, the same runs
  const std::vector<std::string> both = {"sao", "cobyla"};
  const opt::ComparisonResult first = opt::run_comparison(setup_with(40, both, dir + "/a"));
  EXPECT_EQ(validated, 4);
  std::size_t ended = 0;
  opt::ComparisonSetup again = setup_with(40, both, dir + "/a");
  again.on_run_ended = [&ended](const opt::RunRecord&, std::size_t n, std::size_t total) {
    EXPECT_EQ(n, ++ended);
    EXPECT_EQ(total, 4u);
  };
  const opt::ComparisonResult replay = opt::run_comparison(again);
  EXPECT_EQ(ended, 4u);
  EXPECT_EQ(validated, 4);  // the validations came from the archive too
  expect_same_runs(first, replay);
  for (const auto& run : replay.runs) {
    EXPECT_EQ(run.result.archive_hits, run.result.evaluations) << run.solver << " " << run.start;
    EXPECT_TRUE(run.validation_from_archive);
  }
  for (const auto& run : first.runs) EXPECT_EQ(run.result.archive_hits, 0) << run.solver << " " << run.start;
  EXPECT_TRUE(std::filesystem::exists(dir + "/a/sampled_hs071/start1-sao.sqlite"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/a/sampled_hs071/validation.sqlite"));

  // another validation (ProblemSpec::validation_identity, e.g. more runs): the runs still come from
  // the archive, the validations are computed anew and stored beside the first ones
  opt::ComparisonSetup other = setup_with(40, both, dir + "/a");
  other.problems[0].validation_identity = "runs2048";
  const opt::ComparisonResult revalidated = opt::run_comparison(other);
  EXPECT_EQ(validated, 8);
  for (const auto& run : revalidated.runs) {
    EXPECT_EQ(run.result.archive_hits, run.result.evaluations) << run.solver << " " << run.start;
    EXPECT_FALSE(run.validation_from_archive);
  }
  EXPECT_EQ(opt::run_comparison(other).runs.size(), 4u);  // and now answered: nothing validated
  EXPECT_EQ(validated, 8);
  EXPECT_EQ(opt::run_comparison(setup_with(40, both, dir + "/a")).runs.size(), 4u);  // the first ones kept
  EXPECT_EQ(validated, 8);

  // cut short at 15 evaluations, then the full 40: the same runs as without any archive
  const opt::ComparisonResult cut = opt::run_comparison(setup_with(15, {"cobyla"}, dir + "/b"));
  const opt::ComparisonResult resumed = opt::run_comparison(setup_with(40, {"cobyla"}, dir + "/b"));
  const opt::ComparisonResult plain = opt::run_comparison(setup_with(40, {"cobyla"}, ""));
  expect_same_runs(plain, resumed);
  for (std::size_t i = 0; i < resumed.runs.size(); ++i) {
    EXPECT_EQ(cut.runs[i].result.evaluations, 15);
    EXPECT_EQ(resumed.runs[i].result.archive_hits, 15) << i;  // the stored ones answered, the rest computed
    EXPECT_GT(resumed.runs[i].result.evaluations, 15) << i;
  }
  std::filesystem::remove_all(dir);
}
