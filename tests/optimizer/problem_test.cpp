// The problem contract's central checks (messages state both values) and the scaling helpers.
#include "abuopt/optimizer/problem.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "abuopt/common/config_error.hpp"

namespace {

using namespace abuopt::opt;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const abuopt::ConfigError& e) {
    return e.what();
  } catch (const std::logic_error& e) {
    return std::string("logic_error: ") + e.what();
  }
  return "<no error>";
}

std::vector<Variable> durations() {
  return {{"dt0", 0, 10, 1}, {"dt1", 0, 10, 1}, {"dt2", 0, 10, 1}, {"amp", -1, 1, 0.5}, {"f", 5, 50, 20}};
}

FunctionProblem problem_with(std::vector<Variable> vars) {
  return FunctionProblem("p", std::move(vars), [](const std::vector<double>&) { return Evaluation{}; });
}

TEST(CheckDesignVector, WrongSizeStatesBothSizes) {
  EXPECT_EQ(error_of([] { check_design_vector(durations(), {1, 2, 3, 0}); }),
            "design vector: the problem has 5 variables, the design vector has 4");
  EXPECT_EQ(error_of([] { check_design_vector(durations(), {1, 2, 3, 0, 6, 7}, "optimizer.x0"); }),
            "optimizer.x0: the problem has 5 variables, the design vector has 6");
}

TEST(CheckDesignVector, OutOfBoundsStatesValueAndBound) {
  EXPECT_EQ(error_of([] { check_design_vector(durations(), {1, 2, 12, 0, 6}); }),
            "design vector: x[2] (dt2) = 12 is above its upper bound 10");
  EXPECT_EQ(error_of([] { check_design_vector(durations(), {1, 2, 3, -1.5, 6}, "starting point"); }),
            "starting point: x[3] (amp) = -1.5 is below its lower bound -1");
}

TEST(CheckDesignVector, NanIsNamed) {
  EXPECT_EQ(error_of([] { check_design_vector(durations(), {1, std::nan(""), 3, 0, 6}); }),
            "design vector: x[1] (dt1) = nan is not a number");
}

TEST(CheckDesignVector, BoundsThemselvesAreInside) {
  EXPECT_NO_THROW(check_design_vector(durations(), {0, 10, 0, -1, 50}));
}

TEST(CheckProblem, ReversedBoundsAndBadScaleAreNamed) {
  EXPECT_EQ(error_of([] { check_problem(problem_with({{"a", 3, 1, 1}})); }),
            "problem 'p': variable x[0] (a): lower bound 3 is not below upper bound 1");
  EXPECT_EQ(error_of([] { check_problem(problem_with({{"a", 0, 1, 1}, {"b", 0, 1, 0}})); }),
            "problem 'p': variable x[1] (b): scale 0 must be > 0");
  EXPECT_EQ(error_of([] { check_problem(problem_with({{"a", 0, 1, 1}, {"a", 0, 1, 1}})); }),
            "problem 'p': variable name 'a' is used twice");
  EXPECT_EQ(error_of([] { check_problem(problem_with({{"a", 0, INFINITY, 1}})); }),
            "problem 'p': variable x[0] (a): bounds [0, inf] must be finite");
  EXPECT_EQ(error_of([] { check_problem(problem_with({})); }), "problem 'p': has no design variables");
}

TEST(CheckEvaluationShape, MismatchIsALogicErrorWithBothCounts) {
  Evaluation e;
  e.inequality = {1.0};
  EXPECT_EQ(error_of([&] { check_evaluation_shape(2, 0, e); }),
            "logic_error: the problem declares 2 inequality constraints, the evaluation returned 1");
  EXPECT_NO_THROW(check_evaluation_shape(2, 1, Evaluation::failed("x")));  // failures carry no values
}

TEST(Scaling, UnitBoxAndUnitScaleRoundTrip) {
  const auto vars = durations();
  const std::vector<double> x{2.5, 0, 10, 0.5, 27.5};
  const auto u = to_unit_box(vars, x);
  EXPECT_EQ(u, (std::vector<double>{0.25, 0, 1, 0.75, 0.5}));
  const auto back = from_unit_box(vars, u);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(back[i], x[i], 1e-14);
  const auto y = to_unit_scale(vars, x);
  EXPECT_DOUBLE_EQ(y[3], 1.0);
  EXPECT_DOUBLE_EQ(y[4], 27.5 / 20);
  EXPECT_EQ(from_unit_scale(vars, y), x);
}

TEST(Scaling, ClipToBounds) {
  EXPECT_EQ(clip_to_bounds(durations(), {-1, 11, 5, 2, 4}), (std::vector<double>{0, 10, 5, 1, 5}));
}

TEST(Feasibility, ViolationAndTolerance) {
  Evaluation e;
  e.objective = 1;
  e.inequality = {-1.0, 2e-7};
  e.equality = {-3e-7};
  EXPECT_DOUBLE_EQ(max_constraint_violation(e), 3e-7);
  EXPECT_TRUE(is_feasible(e, 1e-6));
  EXPECT_FALSE(is_feasible(e, 1e-7));
  EXPECT_FALSE(is_feasible(Evaluation::failed("no"), 1.0));
  EXPECT_EQ(max_constraint_violation(Evaluation::failed("no")), std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isinf(Evaluation::failed("no").objective));
}

TEST(Problem, DefaultInitialPointIsTheMiddleOfTheBounds) {
  auto p = problem_with(durations());
  EXPECT_EQ(p.initial_point(), (std::vector<double>{5, 5, 5, 0, 27.5}));
  p.set_initial_point({1, 1, 1, 0, 10});
  EXPECT_EQ(p.initial_point(), (std::vector<double>{1, 1, 1, 0, 10}));
  EXPECT_FALSE(p.best_known().has_value());
}

TEST(FormatNumber, ShortestRoundTrip) {
  EXPECT_EQ(format_number(12), "12");
  EXPECT_EQ(format_number(0.1), "0.1");
  EXPECT_EQ(format_number(-INFINITY), "-inf");
  EXPECT_EQ(std::stod(format_number(1.0 / 3)), 1.0 / 3);
}

}  // namespace
