// The result type: reason names round-trip, success needs feasibility, reports show the numbers.
#include "abuopt/optimizer/optimization_result.hpp"

#include <gtest/gtest.h>

#include "abuopt/common/config_error.hpp"

namespace {

using namespace abuopt::opt;

TEST(TerminationReason, NamesRoundTrip) {
  for (int i = 0; i <= static_cast<int>(TerminationReason::Failure); ++i) {
    const auto r = static_cast<TerminationReason>(i);
    EXPECT_EQ(termination_reason_from_string(to_string(r)), r);
  }
  EXPECT_EQ(to_string(TerminationReason::MaxEvaluations), "max_evaluations");
  EXPECT_THROW(termination_reason_from_string("done"), abuopt::ConfigError);
  EXPECT_TRUE(is_convergence(TerminationReason::ConvergedXtol));
  EXPECT_FALSE(is_convergence(TerminationReason::MaxEvaluations));
}

OptimizationResult sample() {
  OptimizationResult r;
  r.problem_name = "demo";
  r.algorithm = "SLSQP";
  r.reason = TerminationReason::ConvergedFtol;
  r.message = "NLopt: ftol_rel or ftol_abs reached";
  r.x = {1.5, 2};
  r.x0 = {1, 1};
  r.objective = 3.25;
  r.inequality = {-0.5};
  r.equality = {2e-7};
  r.metrics = {{"spread", 0.125}};
  r.feasible = true;
  r.max_violation = 2e-7;
  r.constraint_tolerance = 1e-6;
  r.evaluations = 42;
  r.archive_hits = 10;
  r.variable_names = {"duration_s", "amplitude"};
  r.inequality_names = {"torque_margin"};
  r.equality_names = {"balance"};
  return r;
}

TEST(OptimizationResult, SuccessRequiresConvergenceAndFeasibility) {
  OptimizationResult r = sample();
  EXPECT_TRUE(r.success());
  r.feasible = false;
  EXPECT_FALSE(r.success());
  r = sample();
  r.reason = TerminationReason::MaxEvaluations;
  EXPECT_FALSE(r.success());
  EXPECT_TRUE(r.has_feasible_point());
}

TEST(OptimizationResult, BriefReportIsOneLineWithTheNumbers) {
  const std::string b = sample().brief_report();
  EXPECT_EQ(b.find('\n'), std::string::npos);
  EXPECT_EQ(b, "SLSQP on demo: converged_ftol, f = 3.25 (feasible), 42 evaluations (10 from archive), 0 s");
  OptimizationResult r = sample();
  r.feasible = false;
  r.max_violation = 0.5;
  EXPECT_NE(r.brief_report().find("INFEASIBLE, max violation 0.5"), std::string::npos);
}

TEST(OptimizationResult, FullReportNamesVariablesConstraintsAndMetrics) {
  const std::string f = sample().full_report();
  for (const char* s : {"converged_ftol (success)", "duration_s", "1 -> 1.5", "amplitude", "torque_margin", "balance",
                        "spread", "0.125", "42 (10 from archive"})
    EXPECT_NE(f.find(s), std::string::npos) << s << "\n" << f;
}

}  // namespace
