// PenaltyProblem: the exact L1 penalty form f + w (sum max(0, g) + sum |h|) of a constrained
// problem, checked by hand on a two-variable problem with one inequality and one equality, and a
// bound-only optimiser (BOBYQA) that finds the constrained optimum through it.
#include "abuopt/optimizer/penalty_problem.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include "abuopt/optimizer/minimize.hpp"

namespace {

using namespace abuopt::opt;

// min x^2 + y^2  s.t.  g = 1 - x <= 0,  h = y - 0.5 = 0: optimum (1, 0.5), f* = 1.25, multipliers
// lambda_g = 2, lambda_h = -1 (grad f + lambda_g grad g + lambda_h grad h = 0 at the optimum).
FunctionProblem constrained() {
  return FunctionProblem(
      "c", {{"x", -3, 3, 1}, {"y", -3, 3, 1}},
      [](const std::vector<double>& v) {
        Evaluation e;
        e.objective = v[0] * v[0] + v[1] * v[1];
        e.inequality = {1 - v[0]};
        e.equality = {v[1] - 0.5};
        e.metrics["m"] = 7;
        return e;
      },
      {"g1"}, {"h1"});
}

TEST(PenaltyProblem, FoldsViolationsIntoTheObjectiveAndKeepsTheValuesAsMetrics) {
  FunctionProblem inner = constrained();
  PenaltyProblem p(inner, 10.0);
  EXPECT_TRUE(p.inequality_names().empty());
  EXPECT_TRUE(p.equality_names().empty());
  EXPECT_EQ(p.name(), "c");
  const Evaluation e = p.evaluate({0.5, 1.0});  // g = 0.5 (violated), h = 0.5
  ASSERT_TRUE(e.ok);
  EXPECT_TRUE(e.inequality.empty());
  EXPECT_TRUE(e.equality.empty());
  EXPECT_DOUBLE_EQ(e.objective, 1.25 + 10 * (0.5 + 0.5));
  EXPECT_DOUBLE_EQ(e.metrics.at("objective_without_penalty"), 1.25);
  EXPECT_DOUBLE_EQ(e.metrics.at("g_g1"), 0.5);
  EXPECT_DOUBLE_EQ(e.metrics.at("h_h1"), 0.5);
  EXPECT_DOUBLE_EQ(e.metrics.at("m"), 7);
  // a satisfied inequality adds nothing; |h| counts on both sides
  const Evaluation f = p.evaluate({2.0, 0.0});
  EXPECT_DOUBLE_EQ(f.objective, 4.0 + 10 * 0.5);
}

TEST(PenaltyProblem, FailedEvaluationsPassUnchanged) {
  FunctionProblem inner("f", {{"x", 0, 1, 1}}, [](const std::vector<double>&) { return Evaluation::failed("boom"); },
                        {"g"});
  PenaltyProblem p(inner, 2.0);
  const Evaluation e = p.evaluate({0.5});
  EXPECT_FALSE(e.ok);
  EXPECT_EQ(e.message, "boom");
}

TEST(PenaltyProblem, WeightMustBePositiveAndFinite) {
  FunctionProblem inner = constrained();
  EXPECT_THROW(PenaltyProblem(inner, 0.0), std::invalid_argument);
  EXPECT_THROW(PenaltyProblem(inner, -1.0), std::invalid_argument);
  EXPECT_THROW(PenaltyProblem(inner, std::nan("")), std::invalid_argument);
}

// Exact penalty theory: with w above the largest |multiplier| (2 here) the penalty form's minimiser
// is the constrained optimum; a bound-only optimiser finds it.
TEST(PenaltyProblem, ExactPenaltyAboveTheMultipliersRecoversTheConstrainedOptimum) {
  PenaltyProblem p(std::make_unique<FunctionProblem>(constrained()), 5.0);
  OptimizerOptions o;
  o.algorithm = "SBPLX";
  o.max_evaluations = 4000;
  o.xtol_rel = 1e-10;
  o.ftol_rel = 0;
  const OptimizationResult r = minimize(p, o, {0.0, 0.0});
  ASSERT_EQ(r.x.size(), 2u);
  EXPECT_NEAR(r.x[0], 1.0, 1e-4);
  EXPECT_NEAR(r.x[1], 0.5, 1e-4);
  EXPECT_NEAR(r.objective, 1.25, 1e-3);
}

}  // namespace
