// pagmo2's optimisers behind minimize() (optimizer/src/pagmo_adapter.cpp): the analytic benchmarks
// with known optima reached within stated tolerances, seeds that fix the run, the budget, batches
// of a whole population, resumption from an evaluation archive, and bad settings as ConfigErrors.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/benchmarking.hpp"
#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"
#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/multi_objective.hpp"

namespace {

using namespace abuopt;

opt::OptimizerOptions options(const std::string& algorithm, long budget, unsigned long seed = 1) {
  opt::OptimizerOptions o;
  o.algorithm = algorithm;
  o.max_evaluations = budget;
  o.seed = seed;
  o.handle_sigint = false;
  o.evaluation_threads = 1;
  return o;
}

double relative_gap(const opt::OptimizationResult& r, double f_star) {
  return (r.objective - f_star) / std::max(std::abs(f_star), 1.0);
}

// Rosenbrock (2 variables, f* = 0 at (1, 1)), bounds only: every method gets close, CMA-ES and
// xNES to 1e-6, DE and PSO (slower on the curved valley) to 1e-3.
TEST(PagmoAdapter, RosenbrockToItsKnownMinimum) {
  struct Case {
    const char* algorithm;
    long budget;
    double tol;
  };
  for (const Case c : {Case{"pagmo_cmaes", 1500, 1e-6}, Case{"pagmo_xnes", 3000, 1e-6}, Case{"pagmo_sade", 3000, 1e-3},
                       Case{"pagmo_pso", 3000, 1e-3}}) {
    auto p = opt::benchmarks::make_benchmark("rosenbrock");
    const opt::OptimizationResult r = opt::minimize(*p, options(c.algorithm, c.budget));
    EXPECT_LE(r.objective, c.tol) << c.algorithm << ": " << r.message;
    EXPECT_LE(r.evaluations, c.budget) << c.algorithm;
    EXPECT_TRUE(r.has_feasible_point()) << c.algorithm;
  }
}

// Constrained benchmarks through the feasibility rules: a feasible point within 1 % of f*.
TEST(PagmoAdapter, ConstrainedBenchmarksFeasibleWithinOnePercent) {
  for (const char* problem : {"two_bar_truss", "cantilever"}) {
    for (const char* algorithm : {"pagmo_cmaes", "pagmo_sade"}) {
      auto p = opt::benchmarks::make_benchmark(problem);
      const double f_star = p->best_known()->objective;
      const opt::OptimizationResult r = opt::minimize(*p, options(algorithm, 3000));
      ASSERT_TRUE(r.has_feasible_point()) << problem << " " << algorithm << ": " << r.message;
      EXPECT_LE(r.max_violation, 1e-6) << problem << " " << algorithm;
      EXPECT_LE(relative_gap(r, f_star), 1e-2) << problem << " " << algorithm << ": f = " << r.objective;
      EXPECT_GE(relative_gap(r, f_star), -1e-6) << problem << " " << algorithm;  // not below the optimum
    }
  }
}

TEST(PagmoAdapter, TheSeedFixesTheRunAndAnotherSeedChangesIt) {
  for (const char* algorithm : {"pagmo_cmaes", "pagmo_xnes", "pagmo_sade", "pagmo_pso"}) {
    auto run = [&](unsigned long seed) {
      auto p = opt::benchmarks::make_benchmark("hs071");
      return opt::minimize(*p, options(algorithm, 120, seed));
    };
    const opt::OptimizationResult a = run(7), b = run(7), c = run(8);
    ASSERT_EQ(a.history.size(), b.history.size()) << algorithm;
    for (std::size_t k = 0; k < a.history.size(); ++k) {
      EXPECT_EQ(a.history[k].x, b.history[k].x) << algorithm << " " << k;
      EXPECT_EQ(a.history[k].objective, b.history[k].objective) << algorithm << " " << k;
    }
    EXPECT_NE(a.history.back().x, c.history.back().x) << algorithm;
    // the first point is the starting point, whatever the seed
    EXPECT_EQ(a.history.front().x, c.history.front().x) << algorithm;
    EXPECT_EQ(a.evaluations, 120) << algorithm << ": " << a.message;
    EXPECT_EQ(a.reason, opt::TerminationReason::MaxEvaluations) << algorithm;
  }
}

// Counts the sizes of the batches the driver hands to the problem.
class CountingBatches : public opt::FunctionProblem {
 public:
  using FunctionProblem::FunctionProblem;
  std::vector<opt::BatchEvaluation> evaluate_batch(const std::vector<std::vector<double>>& xs,
                                                   opt::EvaluationScheduler& scheduler) override {
    sizes.push_back(xs.size());
    return FunctionProblem::evaluate_batch(xs, scheduler);
  }
  std::vector<std::size_t> sizes;
};

// PSO's generations and every method's initial population reach the problem as whole batches.
TEST(PagmoAdapter, PopulationsAreEvaluatedAsBatches) {
  auto sphere = [](const std::vector<double>& x) {
    opt::Evaluation e;
    e.objective = 0;
    for (double v : x) e.objective += (v - 0.3) * (v - 0.3);
    return e;
  };
  const std::vector<opt::Variable> vars = {{"a", -1, 1, 1}, {"b", -1, 1, 1}, {"c", -1, 1, 1}};
  {
    CountingBatches p("sphere", vars, sphere);
    opt::OptimizerOptions o = options("pagmo_pso", 100);
    o.population = 10;
    const opt::OptimizationResult r = opt::minimize(p, o);
    EXPECT_EQ(r.evaluations, 100);
    ASSERT_GE(p.sizes.size(), 5u);
    for (std::size_t k = 0; k + 1 < p.sizes.size(); ++k) EXPECT_EQ(p.sizes[k], 10u) << k;  // all but the cut one
  }
  {
    CountingBatches p("sphere", vars, sphere);
    opt::OptimizerOptions o = options("pagmo_cmaes", 60);
    o.population = 9;
    (void)opt::minimize(p, o);
    ASSERT_FALSE(p.sizes.empty());
    EXPECT_EQ(p.sizes.front(), 9u);  // the initial population
  }
}

TEST(PagmoAdapter, BadSettingsAreConfigErrors) {
  auto p = opt::benchmarks::make_benchmark("hs071");
  opt::OptimizerOptions o = options("pagmo_sade", 100);
  o.population = 5;
  try {
    (void)opt::minimize(*p, o);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("optimizer.population"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("at least 7"), std::string::npos) << e.what();
  }
  o = options("pagmo_cmaes", 4);
  EXPECT_THROW((void)opt::minimize(*p, o), ConfigError);  // less than one population (8)
}

// Resumption as for every method: a comparison cut short at 30 evaluations and rerun with 90
// answers the 30 stored ones from its archive and gives the runs of an uninterrupted comparison.
TEST(PagmoAdapter, ResumesFromTheArchive) {
  const std::string dir = std::string(ABUOPT_BINARY_DIR) + "/pagmo_resume_archive";
  std::filesystem::remove_all(dir);
  auto setup_with = [&](long budget, const std::string& archive) {
    opt::ComparisonSetup setup;
    opt::ProblemSpec spec;
    spec.label = "hs071";
    spec.make = [] { return opt::benchmarks::make_benchmark("hs071"); };
    spec.max_evaluations = budget;
    spec.starts = 2;
    spec.seed = 3;
    setup.problems.push_back(spec);
    setup.solvers.push_back(opt::solver_spec("CMA-ES", "pagmo_cmaes"));
    setup.solvers.push_back(opt::solver_spec("PSO", "pagmo_pso"));
    setup.archive_directory = archive;
    return setup;
  };
  const opt::ComparisonResult cut = opt::run_comparison(setup_with(30, dir));
  const opt::ComparisonResult resumed = opt::run_comparison(setup_with(90, dir));
  const opt::ComparisonResult plain = opt::run_comparison(setup_with(90, ""));
  ASSERT_EQ(resumed.runs.size(), plain.runs.size());
  for (std::size_t i = 0; i < plain.runs.size(); ++i) {
    EXPECT_EQ(cut.runs[i].result.evaluations, 30) << i;
    EXPECT_EQ(resumed.runs[i].result.archive_hits, 30) << i;
    EXPECT_EQ(resumed.runs[i].result.evaluations, plain.runs[i].result.evaluations) << i;
    EXPECT_EQ(resumed.runs[i].result.x, plain.runs[i].result.x) << i;
    EXPECT_EQ(resumed.runs[i].result.objective, plain.runs[i].result.objective) << i;
  }
  std::filesystem::remove_all(dir);
}

// Hand-worked: (1, 3), (2, 2), (3, 1) against (4, 4) dominate 3 + 2 + 1 = 6; a dominated point and
// one beyond the reference add nothing.
TEST(TwoObjectives, HypervolumeOfAHandWorkedFront) {
  EXPECT_DOUBLE_EQ(opt::hypervolume_2d({{1, 3}, {2, 2}, {3, 1}}, {4, 4}), 6.0);
  EXPECT_DOUBLE_EQ(opt::hypervolume_2d({{3, 1}, {3, 3}, {1, 3}, {2, 2}, {5, 0}}, {4, 4}), 6.0);
  EXPECT_EQ(opt::non_dominated_2d({{3, 3}, {1, 3}, {2, 2}}).size(), 2u);
}

// ZDT1 in two variables: f1 = x0, f2 = g (1 - sqrt(f1 / g)), g = 1 + 9 x1; the front is x1 = 0,
// f2 = 1 - sqrt(f1), whose hypervolume against (1, 1) is the integral of sqrt(f1) = 2/3. With the
// constraint x0 >= 0.2 the front starts at f1 = 0.2: 2/3 (1 - 0.2^1.5) = 0.60704.
opt::FunctionProblem zdt1(bool constrained) {
  auto f = [constrained](const std::vector<double>& x) {
    opt::Evaluation e;
    const double g = 1 + 9 * x[1];
    e.objective = x[0];
    e.metrics["f2"] = g * (1 - std::sqrt(x[0] / g));
    if (constrained) e.inequality = {0.2 - x[0]};
    return e;
  };
  return opt::FunctionProblem(constrained ? "zdt1_c" : "zdt1", {{"x0", 0, 1, 1}, {"x1", 0, 1, 1}}, f,
                              constrained ? std::vector<std::string>{"x0_min"} : std::vector<std::string>{});
}

// A front of 800 evaluations on ZDT1: at least 10 points, all feasible (x0 >= 0.2 with the
// constraint), hypervolume against (1, 1) within 3 % of the exact front's and never above it.
static void expect_near_zdt1_front(const opt::TwoObjectiveResult& r, bool constrained, const std::string& what) {
  ASSERT_GE(r.front.size(), 10u) << what;
  const double exact = constrained ? 2.0 / 3.0 * (1 - std::pow(0.2, 1.5)) : 2.0 / 3.0;
  const double hv = opt::hypervolume_2d(r.front_objectives(), {1, 1});
  EXPECT_LE(hv, exact + 1e-12) << what;  // nothing beats the true front
  EXPECT_GE(hv, 0.97 * exact) << what;
  for (std::size_t i : r.front) {
    EXPECT_TRUE(r.run.history[i].feasible) << what;
    if (constrained) {
      EXPECT_GE(r.run.history[i].x[0], 0.2 - 1e-6) << what;
    }
  }
}

TEST(TwoObjectives, Nsga2ApproachesTheZdt1Front) {
  for (const bool constrained : {false, true}) {
    opt::FunctionProblem p = zdt1(constrained);
    opt::OptimizerOptions o = options("pagmo_cmaes", 800, 5);  // the algorithm key is not used
    o.population = 20;
    const opt::TwoObjectiveResult r = opt::minimize_two_objectives(p, "f2", o);
    EXPECT_EQ(r.run.evaluations, 800);
    expect_near_zdt1_front(r, constrained, constrained ? "constrained" : "unconstrained");
  }
  opt::FunctionProblem p = zdt1(false);
  opt::OptimizerOptions o = options("cobyla", 100);
  o.population = 10;  // not a multiple of 4
  EXPECT_THROW((void)opt::minimize_two_objectives(p, "f2", o), ConfigError);
  o.population = 0;
  EXPECT_THROW((void)opt::minimize_two_objectives(p, "", o), ConfigError);
}

TEST(TwoObjectives, MoeadApproachesTheZdt1Front) {
  // Same problems, budget and tolerance as NSGA-II above, from two seeds each; the constraint is
  // folded into both fitness values (no point below x0 = 0.2 may enter the front).
  for (const bool constrained : {false, true})
    for (const unsigned long seed : {5ul, 6ul}) {
      opt::FunctionProblem p = zdt1(constrained);
      opt::OptimizerOptions o = options("cobyla", 800, seed);
      o.population = 20;
      const opt::TwoObjectiveResult r =
          opt::minimize_two_objectives(p, "f2", o, {}, opt::TwoObjectiveMethod::Moead);
      EXPECT_EQ(r.run.evaluations, 800);
      EXPECT_EQ(r.run.algorithm, "PAGMO_MOEAD");
      expect_near_zdt1_front(r, constrained, (constrained ? "constrained, seed " : "unconstrained, seed ") +
                                                 std::to_string(seed));
    }
  opt::FunctionProblem p = zdt1(false);
  opt::OptimizerOptions o = options("cobyla", 100);
  o.population = 10;  // MOEA/D takes any population of 4 or more
  EXPECT_EQ(opt::minimize_two_objectives(p, "f2", o, {}, opt::TwoObjectiveMethod::Moead).run.evaluations, 100);
  o.population = 3;
  EXPECT_THROW((void)opt::minimize_two_objectives(p, "f2", o, {}, opt::TwoObjectiveMethod::Moead), ConfigError);
  EXPECT_EQ(opt::two_objective_method_from_string("moead", "k"), opt::TwoObjectiveMethod::Moead);
  EXPECT_EQ(opt::two_objective_method_from_string("pagmo_nsga2", "k"), opt::TwoObjectiveMethod::Nsga2);
  EXPECT_THROW((void)opt::two_objective_method_from_string("spea2", "k"), ConfigError);
}


}  // namespace
