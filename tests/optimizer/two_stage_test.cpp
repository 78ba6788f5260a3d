// Two optimisers on one budget (two_stage.hpp): DIRECT_L on the penalty form of a constrained
// problem, then COBYLA from its best point; one history in the problem's own values, the budget
// split as asked, the best point over both stages; and its compare solver entry.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/optimizer/benchmarking.hpp"
#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"
#include "abuopt/optimizer/two_stage.hpp"

namespace {

using namespace abuopt;

TEST(TwoStage, DirectThenCobylaOnAConstrainedProblem) {
  auto problem = opt::benchmarks::make_benchmark("hs071");
  const double f_star = problem->best_known()->objective;
  opt::TwoStageOptions t;
  t.first.algorithm = "DIRECT_L";
  t.first.constraint_tolerance = 1e-6;
  t.then.algorithm = "COBYLA";
  t.then.constraint_tolerance = 1e-6;
  t.first_fraction = 0.25;
  const opt::OptimizationResult r = opt::minimize_two_stage(*problem, t, 400);
  EXPECT_EQ(r.algorithm, "DIRECT_L->COBYLA");
  EXPECT_LE(r.evaluations, 400);
  ASSERT_EQ(static_cast<long>(r.history.size()), r.evaluations);
  // the first stage had 100 evaluations and recorded the problem's own values (not the penalty)
  long first = 0;
  for (std::size_t i = 0; i < r.history.size(); ++i) {
    EXPECT_EQ(r.history[i].index, static_cast<long>(i));
    if (i < 100) {
      const opt::Evaluation e = problem->evaluate(r.history[i].x);
      EXPECT_EQ(r.history[i].objective, e.objective) << i;
      EXPECT_EQ(r.history[i].equality, e.equality) << i;
      ++first;
    }
  }
  EXPECT_EQ(first, 100);
  // the second stage starts at the first stage's best (penalised) point and reaches the optimum
  ASSERT_TRUE(r.feasible) << r.full_report();
  EXPECT_NEAR(r.objective, f_star, 1e-3 * f_star) << r.full_report();
  for (const auto& h : r.history) {
    if (h.feasible) {
      EXPECT_GE(h.objective, r.objective);
    }
  }
}

TEST(TwoStage, BadSettingsAreConfigErrors) {
  auto problem = opt::benchmarks::make_benchmark("rosenbrock");
  opt::TwoStageOptions t;
  t.first.algorithm = "DIRECT_L";
  t.then.algorithm = "COBYLA";
  t.first_fraction = 1.5;
  EXPECT_THROW(opt::minimize_two_stage(*problem, t, 100), ConfigError);
  t.first_fraction = 0.5;
  t.penalty_weight = 0;
  EXPECT_THROW(opt::minimize_two_stage(*problem, t, 100), ConfigError);
  t.penalty_weight = 10;
  EXPECT_THROW(opt::minimize_two_stage(*problem, t, 1), ConfigError);
}

TEST(TwoStage, CompareSolverEntry) {
  YamlReader entry = YamlReader::load_string(
      "{label: DIRECT-COBYLA, algorithm: direct_l, first_fraction: 0.2, penalty_weight: 50, then: {algorithm: cobyla}}");
  const opt::SolverSpec s = opt::read_solver_spec(entry);
  ASSERT_TRUE(s.then.has_value());
  EXPECT_EQ(s.then->algorithm, "cobyla");
  EXPECT_EQ(s.first_fraction, 0.2);
  EXPECT_EQ(s.penalty_weight, 50);
  opt::ComparisonSetup setup;
  opt::ProblemSpec p;
  p.label = "hs071";
  p.make = [] { return opt::benchmarks::make_benchmark("hs071"); };
  p.max_evaluations = 100;
  setup.problems.push_back(p);
  setup.solvers.push_back(s);
  const opt::ComparisonResult r = opt::run_comparison(setup);
  ASSERT_EQ(r.runs.size(), 1u);
  EXPECT_EQ(r.runs[0].result.algorithm, "DIRECT_L->COBYLA");
  EXPECT_EQ(r.runs[0].result.evaluations, static_cast<long>(r.runs[0].result.history.size()));
  YamlReader nested = YamlReader::load_string("{algorithm: direct_l, then: {algorithm: cobyla, then: {algorithm: sbplx}}}");
  EXPECT_THROW(opt::read_solver_spec(nested), ConfigError);
}

}  // namespace
