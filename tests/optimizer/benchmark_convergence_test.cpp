// Every algorithm family reaches the best known solution of the benchmarks that suit it, within a
// stated tolerance and evaluation budget. Each case prints "[measure]" with the number of
// evaluations it needed to come within 1% of best_known (the numbers in docs/optimizers.md).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"

namespace {

using namespace abuopt;

struct Case {
  std::string problem;      // factory name
  int dimension;            // rosenbrock only
  std::string algorithm;
  std::string local;        // local_algorithm ("" default)
  long budget;              // max_evaluations
  double f_tol;             // |f - f*| <= f_tol * max(1, |f*|), f noise-free
  bool must_converge;       // success() required (local methods); globals run to their budget
  double noise = 1e-3;      // noisy_* only
  double constraint_tol = 1e-6;
  double fd_step = 0.0;
  std::string fd = "forward";
};

std::string case_name(const testing::TestParamInfo<Case>& info) {
  const Case& c = info.param;
  std::string n = c.problem + (c.problem.find("rosenbrock") != std::string::npos ? std::to_string(c.dimension) : "") +
                  "_" + c.algorithm + (c.local.empty() ? "" : "_" + c.local) + (c.fd == "central" ? "_central" : "");
  for (char& ch : n)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return n;
}

// The noise-free objective of a record (noisy problems report it as a metric).
double true_objective(const opt::EvaluationRecord& r) {
  auto it = r.metrics.find("noise_free_objective");
  return it == r.metrics.end() ? r.objective : it->second;
}

class BenchmarkConvergence : public testing::TestWithParam<Case> {};

TEST_P(BenchmarkConvergence, ReachesBestKnown) {
  const Case& c = GetParam();
  opt::benchmarks::BenchmarkSettings s;
  s.dimension = c.dimension;
  s.noise_amplitude = c.noise;
  auto problem = opt::benchmarks::make_benchmark(c.problem, s);
  const opt::BestKnown best = *problem->best_known();

  opt::OptimizerOptions o;
  o.algorithm = c.algorithm;
  o.local_algorithm = c.local;
  o.max_evaluations = c.budget;
  o.constraint_tolerance = c.constraint_tol;
  o.fd_relative_step = c.fd_step;
  o.finite_difference = c.fd == "central" ? opt::FiniteDifference::Central : opt::FiniteDifference::Forward;
  const opt::OptimizationResult r = opt::minimize(*problem, o);

  const double scale = std::max(1.0, std::fabs(best.objective));
  long to_one_percent = -1;
  for (const auto& h : r.history)
    if (h.feasible && std::fabs(true_objective(h) - best.objective) <= 0.01 * scale) {
      to_one_percent = h.index + 1;
      break;
    }
  std::cout << "[measure] " << case_name({c, 0}) << ": " << r.brief_report() << "; evaluations to 1%: "
            << to_one_percent << "\n";

  ASSERT_TRUE(r.has_feasible_point()) << r.full_report();
  double f = r.objective;
  if (auto it = r.metrics.find("noise_free_objective"); it != r.metrics.end()) f = it->second;
  EXPECT_LE(std::fabs(f - best.objective), c.f_tol * scale) << r.full_report();
  EXPECT_LE(r.evaluations, c.budget);
  if (c.must_converge) {
    EXPECT_TRUE(r.success()) << r.full_report();
  }
  if (r.success()) {
    EXPECT_TRUE(r.feasible);  // a reported success is always feasible
  }
}

const double kTight = 1e-4;  // local methods on smooth problems
const double kLoose = 1e-2;  // global methods, slow local ones, noisy problems

INSTANTIATE_TEST_SUITE_P(
    LocalDerivativeFree, BenchmarkConvergence,
    testing::Values(Case{"rosenbrock", 2, "COBYLA", "", 5000, kLoose, false},
                    Case{"rosenbrock", 2, "BOBYQA", "", 1000, kTight, true},
                    Case{"rosenbrock", 2, "NEWUOA_BOUND", "", 1000, kTight, true},
                    Case{"rosenbrock", 2, "SBPLX", "", 1000, kTight, true},
                    Case{"rosenbrock", 2, "NELDERMEAD", "", 1000, kTight, true},
                    Case{"rosenbrock", 2, "PRAXIS", "", 1000, kTight, true},
                    Case{"rosenbrock", 4, "NELDERMEAD", "", 3000, kTight, true},
                    Case{"rosenbrock", 4, "PRAXIS", "", 3000, kTight, true},
                    Case{"cantilever", 0, "COBYLA", "", 1000, kTight, true},
                    Case{"cantilever", 0, "BOBYQA", "", 3000, kTight, true},  // wrapped in AUGLAG
                    Case{"two_bar_truss", 0, "COBYLA", "", 1000, kTight, true},
                    Case{"hs071", 0, "COBYLA", "", 1000, kTight, true}),
    case_name);

INSTANTIATE_TEST_SUITE_P(
    LocalGradient, BenchmarkConvergence,
    testing::Values(Case{"rosenbrock", 2, "SLSQP", "", 1000, kTight, true},
                    Case{"rosenbrock", 2, "LBFGS", "", 1000, kTight, true},
                    Case{"rosenbrock", 2, "MMA", "", 4000, kLoose, false},
                    Case{"rosenbrock", 2, "CCSAQ", "", 4000, kLoose, false},
                    Case{"rosenbrock", 2, "IPOPT", "", 1000, kTight, true},
                    Case{"rosenbrock", 4, "SLSQP", "", 2000, kTight, true},
                    Case{"rosenbrock", 4, "LBFGS", "", 2000, kTight, true},
                    // Ipopt reaches 4e-11 either way, but whether it then declares convergence on
                    // finite-difference gradients depends on the BLAS behind MUMPS (reference BLAS:
                    // yes; OpenBLAS, as a fresh Debian install pulls in: it spends the budget).
                    Case{"rosenbrock", 4, "IPOPT", "", 2000, kTight, false},
                    Case{"rosenbrock", 4, "SLSQP", "", 2000, kTight, true, 0, 1e-6, 0, "central"},
                    Case{"cantilever", 0, "SLSQP", "", 1000, kTight, true},
                    Case{"cantilever", 0, "MMA", "", 1000, kTight, true},
                    Case{"cantilever", 0, "CCSAQ", "", 1000, kTight, true},
                    Case{"cantilever", 0, "IPOPT", "", 1000, kTight, true},
                    Case{"two_bar_truss", 0, "SLSQP", "", 1000, kTight, true},
                    Case{"two_bar_truss", 0, "MMA", "", 1000, kTight, true},
                    Case{"two_bar_truss", 0, "CCSAQ", "", 1000, kTight, true},
                    Case{"two_bar_truss", 0, "IPOPT", "", 1000, kTight, true},
                    Case{"hs071", 0, "SLSQP", "", 1000, kTight, true},
                    Case{"hs071", 0, "IPOPT", "", 1000, kTight, true},
                    Case{"hs071", 0, "IPOPT", "", 1000, kTight, true, 0, 1e-6, 0, "central"},
                    Case{"hs071", 0, "MMA", "", 2000, kTight, true}),  // equality: AUGLAG_EQ(MMA)
    case_name);

INSTANTIATE_TEST_SUITE_P(
    AugmentedLagrangian, BenchmarkConvergence,
    testing::Values(Case{"cantilever", 0, "AUGLAG", "", 3000, kTight, true},
                    Case{"two_bar_truss", 0, "AUGLAG", "", 3000, kTight, true},
                    Case{"hs071", 0, "AUGLAG", "", 3000, kTight, true},
                    Case{"hs071", 0, "AUGLAG", "LBFGS", 3000, kTight, true},
                    Case{"cantilever", 0, "AUGLAG", "SLSQP", 3000, kTight, true}),
    case_name);

// Global methods on Rosenbrock's small box [-2, 2]^n, run to their budget.
INSTANTIATE_TEST_SUITE_P(
    Global, BenchmarkConvergence,
    testing::Values(Case{"rosenbrock", 2, "DIRECT_L", "", 1000, kLoose, false},
                    Case{"rosenbrock", 2, "CRS2_LM", "", 2000, kLoose, false},
                    Case{"rosenbrock", 2, "ISRES", "", 3000, kLoose, false},
                    Case{"rosenbrock", 2, "ESCH", "", 3000, kLoose, false},
                    Case{"rosenbrock", 2, "MLSL_LDS", "", 1000, kLoose, false},
                    Case{"rosenbrock", 4, "CRS2_LM", "", 6000, kLoose, false},
                    Case{"two_bar_truss", 0, "ISRES", "", 3000, kLoose, false}),
    case_name);

// Relative noise 1e-3 on objective and constraints (constraint tolerance loosened to match).
INSTANTIATE_TEST_SUITE_P(
    Noisy, BenchmarkConvergence,
    testing::Values(Case{"noisy_rosenbrock", 2, "NELDERMEAD", "", 2000, kLoose, false},
                    Case{"noisy_rosenbrock", 2, "SBPLX", "", 2000, kLoose, false},
                    Case{"noisy_cantilever", 0, "COBYLA", "", 2000, kLoose, false, 1e-3, 1e-2},
                    Case{"noisy_two_bar_truss", 0, "COBYLA", "", 2000, kLoose, false, 1e-3, 1e-2},
                    Case{"noisy_cantilever", 0, "SLSQP", "", 2000, kLoose, false, 1e-3, 1e-2, 1e-2, "central"},
                    Case{"noisy_hs071", 0, "COBYLA", "", 2000, kLoose, false, 1e-3, 1e-2}),
    case_name);

}  // namespace
