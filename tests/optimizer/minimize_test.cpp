// minimize(): the evaluation wrapper every adapter goes through (budget, time, callback, SIGINT,
// exceptions, bounds, finite differences), the NLopt and Ipopt adapters' stop and constraint
// handling, and the errors raised before a run starts.
#include "abuopt/optimizer/minimize.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <stdexcept>
#include <thread>

#include "abuopt/common/config_error.hpp"

namespace {

using namespace abuopt::opt;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const abuopt::ConfigError& e) {
    return e.what();
  }
  return "<no error>";
}

// f = (x0 - 0.3)^2 + 2 (x1 + 0.2)^2 on [-1, 1]^2; minimum 0 at (0.3, -0.2).
FunctionProblem quadratic() {
  return FunctionProblem("quadratic", {{"a", -1, 1, 1}, {"b", -1, 1, 1}}, [](const std::vector<double>& x) {
    Evaluation e;
    e.objective = (x[0] - 0.3) * (x[0] - 0.3) + 2 * (x[1] + 0.2) * (x[1] + 0.2);
    return e;
  });
}

// min x0 + x1 s.t. x0^2 + x1^2 <= 1 (g), x0 - x1 = 0.2 (h), box [-2, 2]^2.
// Optimum on the circle: x = (0.1 - sqrt(0.49), -0.1 - sqrt(0.49)) = (-0.6, -0.8), f = -1.4.
FunctionProblem disc(bool with_equality) {
  return FunctionProblem(
      "disc", {{"a", -2, 2, 1}, {"b", -2, 2, 1}},
      [with_equality](const std::vector<double>& x) {
        Evaluation e;
        e.objective = x[0] + x[1];
        e.inequality = {x[0] * x[0] + x[1] * x[1] - 1};
        if (with_equality) e.equality = {x[0] - x[1] - 0.2};
        return e;
      },
      {"radius"}, with_equality ? std::vector<std::string>{"offset"} : std::vector<std::string>{});
}

double best_in_history(const OptimizationResult& r) {
  double best = INFINITY;
  for (const auto& h : r.history)
    if (h.feasible) best = std::min(best, h.objective);
  return best;
}

OptimizerOptions with(const std::string& algorithm, long budget = 1000) {
  OptimizerOptions o;
  o.algorithm = algorithm;
  o.max_evaluations = budget;
  return o;
}

TEST(Minimize, StopsAtTheBudgetAndReturnsTheBestSoFar) {
  for (const char* alg : {"COBYLA", "SLSQP", "IPOPT", "DIRECT_L"}) {
    auto p = quadratic();
    const auto r = minimize(p, with(alg, 7));
    EXPECT_EQ(r.reason, TerminationReason::MaxEvaluations) << alg << ": " << r.message;
    EXPECT_EQ(r.evaluations, 7) << alg;
    ASSERT_EQ(r.history.size(), 7u) << alg;
    EXPECT_EQ(r.objective, best_in_history(r)) << alg;
    EXPECT_TRUE(r.has_feasible_point());
    EXPECT_FALSE(r.success());
  }
}

TEST(Minimize, CallbackCanStopTheRun) {
  auto p = quadratic();
  long seen = 0;
  const auto r = minimize(p, with("NELDERMEAD"), {}, [&](const Progress& pr) {
    seen = pr.evaluations;
    EXPECT_EQ(pr.last.index, pr.evaluations - 1);
    return pr.evaluations < 5;
  });
  EXPECT_EQ(r.reason, TerminationReason::StoppedByCallback);
  EXPECT_EQ(r.evaluations, 5);
  EXPECT_EQ(seen, 5);
  EXPECT_EQ(r.objective, best_in_history(r));
}

TEST(Minimize, AnExceptionInsideAnEvaluationEndsTheRunWithTheBestSoFar) {
  for (const char* alg : {"COBYLA", "SLSQP", "IPOPT"}) {
    int calls = 0;
    FunctionProblem p("throws", {{"a", -1, 1, 1}, {"b", -1, 1, 1}}, [&](const std::vector<double>& x) {
      if (++calls == 10) throw std::runtime_error("simulator exploded");
      Evaluation e;
      e.objective = (x[0] - 0.3) * (x[0] - 0.3) + x[1] * x[1];
      return e;
    });
    OptimizationResult r;
    ASSERT_NO_THROW(r = minimize(p, with(alg)));
    EXPECT_EQ(r.reason, TerminationReason::EvaluationError) << alg;
    EXPECT_NE(r.message.find("simulator exploded"), std::string::npos) << r.message;
    EXPECT_EQ(r.evaluations, 10) << alg;
    EXPECT_TRUE(r.has_feasible_point());
    EXPECT_EQ(r.objective, best_in_history(r));
  }
}

TEST(Minimize, SigintInterruptsAndRestoresThePreviousHandler) {
  struct sigaction before {};
  sigaction(SIGINT, nullptr, &before);
  auto p = quadratic();
  const auto r = minimize(p, with("SBPLX"), {}, [](const Progress& pr) {
    if (pr.evaluations == 6) std::raise(SIGINT);  // what Ctrl-C does
    return true;
  });
  EXPECT_EQ(r.reason, TerminationReason::Interrupted);
  EXPECT_EQ(r.evaluations, 6);
  EXPECT_EQ(r.objective, best_in_history(r));
  struct sigaction after {};
  sigaction(SIGINT, nullptr, &after);
  EXPECT_EQ(after.sa_handler, before.sa_handler);
  // and the next run is not affected by the old interrupt
  auto q = quadratic();
  EXPECT_TRUE(minimize(q, with("SBPLX")).success());
}

// SAO runs behind the same SIGINT guard (one mechanism for every algorithm).
TEST(Minimize, SigintInterruptsSaoAndRestoresThePreviousHandler) {
  struct sigaction before {};
  sigaction(SIGINT, nullptr, &before);
  auto p = quadratic();
  const auto r = minimize(p, with("SAO"), {}, [](const Progress& pr) {
    if (pr.evaluations == 5) std::raise(SIGINT);
    return true;
  });
  EXPECT_EQ(r.reason, TerminationReason::Interrupted);
  EXPECT_EQ(r.evaluations, 5);
  EXPECT_EQ(r.algorithm, "SAO(auto)");
  struct sigaction after {};
  sigaction(SIGINT, nullptr, &after);
  EXPECT_EQ(after.sa_handler, before.sa_handler);
}

TEST(Minimize, RequestStopInterruptsIpopt) {
  auto p = quadratic();
  const auto r = minimize(p, with("IPOPT"), {0.9, 0.9}, [](const Progress& pr) {
    if (pr.evaluations == 4) request_stop();
    return true;
  });
  EXPECT_EQ(r.reason, TerminationReason::Interrupted);
  EXPECT_EQ(r.evaluations, 4);
}

TEST(Minimize, NoAlgorithmEvaluatesOutsideTheBounds) {
  // The unconstrained minimum (3, -3) lies outside the box, so every algorithm pushes on it.
  for (const auto& name : algorithm_names()) {
    long outside = 0;
    FunctionProblem p("pushing", {{"a", -1, 1, 1}, {"b", -0.5, 2, 1}}, [&](const std::vector<double>& x) {
      if (x[0] < -1 || x[0] > 1 || x[1] < -0.5 || x[1] > 2) ++outside;
      Evaluation e;
      e.objective = (x[0] - 3) * (x[0] - 3) + (x[1] + 3) * (x[1] + 3) + x[0] * x[1];
      return e;
    });
    const auto r = minimize(p, with(name, 300));
    EXPECT_EQ(outside, 0) << name;
    EXPECT_LE(r.evaluations, 300) << name;
    for (const auto& h : r.history) {
      EXPECT_GE(h.x[0], -1.0);
      EXPECT_LE(h.x[0], 1.0);
      EXPECT_GE(h.x[1], -0.5);
      EXPECT_LE(h.x[1], 2.0);
    }
    // minimum at the corner (1, -0.5): f = 4 + 6.25 - 0.5 = 9.75 (global methods: 300 evaluations)
    const double tol = find_algorithm(name).family == AlgorithmFamily::Global ? 0.5 : 0.05;
    EXPECT_NEAR(r.objective, 9.75, tol) << name << ": " << r.brief_report();
  }
}

TEST(Minimize, FailedEvaluationsAreInfiniteAndDoNotEndTheRun) {
  // Fails for a > 0.6 (status) and b > 0.7 (NaN); the minimum (0.3, 0) is in the working region.
  auto problem = [] {
    return FunctionProblem("fails", {{"a", -1, 1, 1}, {"b", -1, 1, 1}}, [](const std::vector<double>& x) {
      if (x[0] > 0.6) return Evaluation::failed("simulation did not finish");
      Evaluation e;
      e.objective = (x[0] - 0.3) * (x[0] - 0.3) + x[1] * x[1];
      if (x[1] > 0.7) e.objective = std::nan("");  // NaN counts as a failure too
      return e;
    });
  };
  for (const char* alg : {"COBYLA", "BOBYQA", "NELDERMEAD", "SLSQP", "IPOPT"}) {
    auto p = problem();
    OptimizerOptions o = with(alg);
    o.initial_step = 0.5;  // first steps reach into the failing region
    const auto r = minimize(p, o, {0.5, 0.5});
    if (find_algorithm(alg).family == AlgorithmFamily::LocalDerivativeFree) {
      EXPECT_GT(r.failed_evaluations, 0) << alg;  // (gradient methods may never step there)
    }
    EXPECT_TRUE(r.success()) << alg << ": " << r.full_report();
    EXPECT_NEAR(r.x[0], 0.3, 1e-3) << alg;
    EXPECT_NEAR(r.x[1], 0.0, 1e-3) << alg;
    for (const auto& h : r.history) {
      if (!h.ok) {
        EXPECT_TRUE(std::isinf(h.objective));
      }
    }
  }
  // Starting inside the failing region with every neighbour failing: no success is claimed.
  auto p = problem();
  const auto r = minimize(p, with("COBYLA"), {0.9, 0.9});
  EXPECT_FALSE(r.success());
  EXPECT_EQ(r.reason, TerminationReason::Infeasible);
  EXPECT_EQ(r.failed_evaluations, r.evaluations);
}

TEST(Minimize, ConvergenceAtAnInfeasiblePointIsNotASuccess) {
  // g = 2.5 - x0 - x1 <= 0 cannot hold in [0, 1]^2.
  for (const char* alg : {"COBYLA", "SLSQP", "IPOPT", "AUGLAG", "MMA"}) {
    FunctionProblem p(
        "infeasible", {{"a", 0, 1, 1}, {"b", 0, 1, 1}},
        [](const std::vector<double>& x) {
          Evaluation e;
          e.objective = x[0] * x[0] + x[1] * x[1];
          e.inequality = {2.5 - x[0] - x[1]};
          return e;
        },
        {"sum"});
    const auto r = minimize(p, with(alg, 500));
    EXPECT_FALSE(r.success()) << alg << ": " << r.full_report();
    EXPECT_FALSE(r.feasible) << alg;
    EXPECT_NE(r.reason, TerminationReason::Converged) << alg;
    EXPECT_NEAR(r.max_violation, 0.5, 1e-3) << alg << ": the least infeasible point is (1, 1)";
  }
}

TEST(Minimize, ReportedSuccessIsFeasibleForEveryConstrainedAlgorithm) {
  for (const char* alg : {"COBYLA", "SLSQP", "IPOPT", "AUGLAG", "ISRES", "MMA", "CCSAQ", "BOBYQA", "SBPLX"}) {
    for (bool eq : {false, true}) {
      auto p = disc(eq);
      OptimizerOptions o = with(alg, 4000);
      const auto r = minimize(p, o, {1.0, 0.5});
      if (r.success()) {
        EXPECT_TRUE(r.feasible) << alg;
        EXPECT_LE(r.max_violation, o.constraint_tolerance) << alg;
      }
      if (std::string(alg) != "ISRES") {
        EXPECT_TRUE(r.success()) << alg << (eq ? " with equality: " : ": ") << r.full_report();
        EXPECT_NEAR(r.objective, eq ? -1.4 : -std::sqrt(2.0), 1e-3) << alg;
      }
    }
  }
}

TEST(Minimize, BoundOnlyLocalAlgorithmsAreWrappedInAuglag) {
  auto p = disc(true);
  const auto r = minimize(p, with("bobyqa", 4000), {1.0, 0.5});
  EXPECT_EQ(r.algorithm, "AUGLAG(BOBYQA)");
  EXPECT_NE(r.message.find("wrapped in AUGLAG"), std::string::npos);
  auto q = disc(true);
  EXPECT_EQ(minimize(q, with("mma", 4000), {1.0, 0.5}).algorithm, "AUGLAG_EQ(MMA)");
}

TEST(Minimize, TargetStopsAtTheFirstFeasiblePointBelowIt) {
  auto p = quadratic();
  OptimizerOptions o = with("NELDERMEAD");
  o.target = 0.01;
  const auto r = minimize(p, o, {0.9, 0.9});
  EXPECT_EQ(r.reason, TerminationReason::TargetReached);
  EXPECT_LE(r.objective, 0.01);
  EXPECT_GT(r.history[r.history.size() - 2].objective, 0.0);  // stopped right after reaching it
  EXPECT_TRUE(r.success());
}

TEST(Minimize, TimeLimitStopsTheRun) {
  FunctionProblem p("slow", {{"a", -1, 1, 1}, {"b", -1, 1, 1}}, [](const std::vector<double>& x) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    Evaluation e;
    e.objective = x[0] * x[0] + x[1] * x[1];
    return e;
  });
  OptimizerOptions o = with("DIRECT_L");
  o.max_time_s = 0.1;
  const auto r = minimize(p, o);
  EXPECT_EQ(r.reason, TerminationReason::MaxTime);
  EXPECT_LE(r.evaluations, 12);
  EXPECT_LT(r.wall_time_s, 0.5);
}

TEST(Minimize, FiniteDifferenceStepIsRelativeToMaxOfValueAndScale) {
  // One variable of scale 100: the step is h * max(|x|, 100).
  auto run = [](double x0, FiniteDifference kind, double upper) {
    FunctionProblem p("fd", {{"v", -500, upper, 100}}, [](const std::vector<double>& x) {
      Evaluation e;
      e.objective = (x[0] - 7) * (x[0] - 7);
      return e;
    });
    OptimizerOptions o = with("LBFGS", 3);
    o.fd_relative_step = 1e-3;
    o.finite_difference = kind;
    return minimize(p, o, {x0});
  };
  auto r = run(50, FiniteDifference::Forward, 500);
  ASSERT_EQ(r.history.size(), 3u);
  EXPECT_FALSE(r.history[0].for_gradient);
  EXPECT_TRUE(r.history[1].for_gradient);
  EXPECT_NEAR(r.history[1].x[0] - 50, 0.1, 1e-9);  // 1e-3 * max(50, 100)
  r = run(300, FiniteDifference::Central, 500);
  EXPECT_NEAR(r.history[1].x[0] - 300, 0.3, 1e-9);  // 1e-3 * max(300, 100)
  EXPECT_NEAR(r.history[2].x[0] - 300, -0.3, 1e-9);
  r = run(500, FiniteDifference::Central, 500);  // at the upper bound: one-sided, backward
  EXPECT_NEAR(r.history[1].x[0] - 500, -0.5, 1e-9);
  EXPECT_EQ(r.gradient_evaluations, 1 + (r.history[2].for_gradient ? 1 : 0));
}

TEST(Minimize, StochasticAlgorithmsRepeatWithTheSameSeed) {
  auto run = [](unsigned long seed) {
    auto p = quadratic();
    OptimizerOptions o = with("ISRES", 200);
    o.seed = seed;
    std::vector<double> xs;
    for (const auto& h : minimize(p, o).history) xs.insert(xs.end(), h.x.begin(), h.x.end());
    return xs;
  };
  EXPECT_EQ(run(5), run(5));
  EXPECT_NE(run(5), run(6));
}

TEST(Minimize, IpoptBudgetIsEnforcedByTheWrapper) {
  FunctionProblem p("rosen", {{"a", -2, 2, 1}, {"b", -2, 2, 1}}, [](const std::vector<double>& x) {
    Evaluation e;
    e.objective = 100 * std::pow(x[1] - x[0] * x[0], 2) + std::pow(1 - x[0], 2);
    return e;
  });
  const auto r = minimize(p, with("ipopt", 20), {-1.2, 1});
  EXPECT_EQ(r.reason, TerminationReason::MaxEvaluations);
  EXPECT_EQ(r.evaluations, 20);
  EXPECT_LT(r.objective, 24.2);  // better than the start
}

TEST(Minimize, BadInputsAreClearErrorsBeforeAnyEvaluation) {
  auto p = quadratic();
  EXPECT_EQ(error_of([&] { minimize(p, with("simplex")); }).substr(0, 58),
            "optimizer.algorithm = simplex: unknown algorithm; valid (c");
  EXPECT_EQ(error_of([&] { minimize(p, with("cobyla"), {0.5, 1.5}); }),
            "starting point: x[1] (b) = 1.5 is above its upper bound 1");
  EXPECT_EQ(error_of([&] { minimize(p, with("cobyla"), {0.5}); }),
            "starting point: the problem has 2 variables, the design vector has 1");
  FunctionProblem reversed("reversed", {{"a", 1, -1, 1}}, [](const std::vector<double>&) { return Evaluation{}; });
  EXPECT_EQ(error_of([&] { minimize(reversed, with("cobyla")); }),
            "problem 'reversed': variable x[0] (a): lower bound 1 is not below upper bound -1");
  auto d = disc(false);
  EXPECT_EQ(error_of([&] { minimize(d, with("direct_l")); }),
            "optimizer.algorithm = direct_l: the global algorithm DIRECT_L handles bounds only and problem 'disc' "
            "has 1 inequality constraint; use ISRES (global, constrained), COBYLA, SLSQP or IPOPT (local), or AUGLAG");
  FunctionProblem one("one", {{"a", -1, 1, 1}}, [](const std::vector<double>& x) {
    Evaluation e;
    e.objective = x[0] * x[0];
    return e;
  });
  EXPECT_EQ(error_of([&] { minimize(one, with("bobyqa")); }),
            "optimizer.algorithm = bobyqa: BOBYQA needs at least 2 variables; problem 'one' has 1 (use COBYLA or SBPLX)");
  EXPECT_TRUE(minimize(one, with("auglag")).success());  // AUGLAG's default local is SBPLX for 1 variable
  OptimizerOptions bad = with("cobyla");
  bad.max_evaluations = -3;
  EXPECT_EQ(error_of([&] { minimize(p, bad); }), "optimizer.max_evaluations = -3: must be > 0");
}

TEST(Minimize, ShapeMismatchIsAnEvaluationError) {
  FunctionProblem p(
      "shape", {{"a", -1, 1, 1}},
      [](const std::vector<double>& x) {
        Evaluation e;
        e.objective = x[0];
        return e;  // declares one inequality, returns none
      },
      {"g"});
  const auto r = minimize(p, with("cobyla"));
  EXPECT_EQ(r.reason, TerminationReason::EvaluationError);
  EXPECT_NE(r.message.find("declares 1 inequality constraints, the evaluation returned 0"), std::string::npos);
}

TEST(Minimize, HistoryIsOrderedAndTimed) {
  auto p = quadratic();
  const auto r = minimize(p, with("SLSQP"));
  ASSERT_EQ(static_cast<long>(r.history.size()), r.evaluations);
  for (std::size_t i = 0; i < r.history.size(); ++i) {
    EXPECT_EQ(r.history[i].index, static_cast<long>(i));
    if (i) {
      EXPECT_GE(r.history[i].elapsed_s, r.history[i - 1].elapsed_s);
    }
  }
  EXPECT_GT(r.gradient_evaluations, 0);
  EXPECT_EQ(r.x0, (std::vector<double>{0, 0}));
  EXPECT_NE(r.full_report().find("a "), std::string::npos);
}

}  // namespace
