// The NLopt adapter (internal, optimizer/src/adapters.hpp) with and without a local algorithm.
// Before the fix it bound a reference to *local for every run, also when local was null (every
// plain NLopt run): undefined behaviour that UBSan aborts on, and a null dereference when an
// algorithm that needs a local one got none.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "abuopt/optimizer/algorithms.hpp"
#include "abuopt/optimizer/problem.hpp"
#include "adapters.hpp"
#include "evaluation_driver.hpp"

namespace {

using namespace abuopt::opt;

// (x - 1)^2 + (y + 0.5)^2 on [-2, 2]^2: minimum 0 at (1, -0.5).
FunctionProblem bowl() {
  return FunctionProblem("bowl", {{"x", -2, 2, 1}, {"y", -2, 2, 1}}, [](const std::vector<double>& v) {
    Evaluation e;
    e.objective = (v[0] - 1) * (v[0] - 1) + (v[1] + 0.5) * (v[1] + 0.5);
    return e;
  });
}

TEST(NloptAdapter, PlainRunWithoutLocalAlgorithmConverges) {
  FunctionProblem p = bowl();
  OptimizerOptions o;
  o.algorithm = "COBYLA";
  o.max_evaluations = 500;
  const EvaluationCallback none;
  detail::EvaluationDriver driver(p, o, none);
  const detail::AdapterOutcome out = detail::run_nlopt(driver, find_algorithm("COBYLA"), nullptr, false, o, {0, 0});
  EXPECT_EQ(out.algorithm_label, "COBYLA");
  OptimizationResult r;
  driver.fill(r);
  ASSERT_EQ(r.x.size(), 2u);
  EXPECT_NEAR(r.x[0], 1.0, 1e-3);
  EXPECT_NEAR(r.x[1], -0.5, 1e-3);
}

TEST(NloptAdapter, AlgorithmThatNeedsALocalOneWithoutItIsMisuse) {
  FunctionProblem p = bowl();
  OptimizerOptions o;
  o.algorithm = "MLSL_LDS";
  o.max_evaluations = 50;
  const EvaluationCallback none;
  detail::EvaluationDriver driver(p, o, none);
  EXPECT_THROW(detail::run_nlopt(driver, find_algorithm("MLSL_LDS"), nullptr, false, o, {0, 0}),
               std::invalid_argument);
  EXPECT_EQ(driver.evaluations(), 0);
}

TEST(NloptAdapter, LocalAlgorithmIsUsedWhenGiven) {
  FunctionProblem p = bowl();
  OptimizerOptions o;
  o.algorithm = "MLSL_LDS";
  o.max_evaluations = 300;
  const EvaluationCallback none;
  detail::EvaluationDriver driver(p, o, none);
  const detail::AdapterOutcome out =
      detail::run_nlopt(driver, find_algorithm("MLSL_LDS"), &find_algorithm("BOBYQA"), false, o, {0, 0});
  EXPECT_EQ(out.algorithm_label, "MLSL_LDS(BOBYQA)");
  OptimizationResult r;
  driver.fill(r);
  EXPECT_LT(r.objective, 1e-4);
}

}  // namespace
