// The benchmark problems: their stated optima are verified from the definitions (feasibility,
// objective value and the KKT conditions with multipliers of the right sign), and the factory and
// the noise wrapper behave as documented.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"
#include "abuopt/optimizer/benchmarks/cantilever.hpp"
#include "abuopt/optimizer/benchmarks/hs071.hpp"
#include "abuopt/optimizer/benchmarks/noisy_problem.hpp"
#include "abuopt/optimizer/benchmarks/rosenbrock.hpp"
#include "abuopt/optimizer/benchmarks/two_bar_truss.hpp"

namespace {

using namespace abuopt;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no error>";
}

// Central-difference gradient of output k (0: objective, 1..: g then h) at x.
Eigen::VectorXd gradient(opt::Problem& p, const std::vector<double>& x, std::size_t k) {
  auto value = [&](const std::vector<double>& y) {
    const opt::Evaluation e = p.evaluate(y);
    if (k == 0) return e.objective;
    if (k - 1 < e.inequality.size()) return e.inequality[k - 1];
    return e.equality[k - 1 - e.inequality.size()];
  };
  Eigen::VectorXd g(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double h = 1e-6 * std::max(1.0, std::fabs(x[i]));
    std::vector<double> a = x, b = x;
    a[i] += h;
    b[i] -= h;
    g[static_cast<Eigen::Index>(i)] = (value(a) - value(b)) / (a[i] - b[i]);
  }
  return g;
}

struct Kkt {
  double relative_residual;   // ||grad f + sum mu_i grad c_i|| / ||grad f||
  double min_inequality_mu;   // smallest multiplier of an active inequality or bound (>= 0 at a minimum)
  int active;                 // number of active constraints and bounds
};

// KKT check at x (a minimum of f s.t. g <= 0, h = 0, bounds): multipliers of the active set by
// least squares. Bounds closer than 1e-9 and constraints with |g| <= 1e-6 are active. The
// evaluation at x is done without moving outside the bounds: a bound's neighbours are clipped.
Kkt kkt_at(opt::Problem& p, const std::vector<double>& x) {
  const auto vars = p.variables();
  const opt::Evaluation e = p.evaluate(x);
  const std::size_t n = x.size();
  std::vector<Eigen::VectorXd> cols;
  std::vector<bool> is_inequality;
  // Bounds: the gradient of lower - x <= 0 is -e_i, of x - upper <= 0 is +e_i.
  for (std::size_t i = 0; i < n; ++i) {
    if (std::fabs(x[i] - vars[i].lower) < 1e-9) {
      cols.push_back(-Eigen::VectorXd::Unit(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(i)));
      is_inequality.push_back(true);
    } else if (std::fabs(x[i] - vars[i].upper) < 1e-9) {
      cols.push_back(Eigen::VectorXd::Unit(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(i)));
      is_inequality.push_back(true);
    }
  }
  // Gradients near an active bound: evaluate on the inside by shifting x a little.
  std::vector<double> xin = x;
  for (std::size_t i = 0; i < n; ++i) {
    xin[i] = std::min(std::max(x[i], vars[i].lower + 2e-6), vars[i].upper - 2e-6);
  }
  for (std::size_t j = 0; j < e.inequality.size(); ++j)
    if (std::fabs(e.inequality[j]) <= 1e-6) {
      cols.push_back(gradient(p, xin, 1 + j));
      is_inequality.push_back(true);
    }
  for (std::size_t j = 0; j < e.equality.size(); ++j) {
    cols.push_back(gradient(p, xin, 1 + e.inequality.size() + j));
    is_inequality.push_back(false);
  }
  const Eigen::VectorXd gf = gradient(p, xin, 0);
  Kkt k{gf.norm() == 0 ? 0.0 : 1.0, 0.0, static_cast<int>(cols.size())};
  if (cols.empty()) {
    k.relative_residual = gf.norm();
    return k;
  }
  Eigen::MatrixXd a(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t c = 0; c < cols.size(); ++c) a.col(static_cast<Eigen::Index>(c)) = cols[c];
  const Eigen::VectorXd mu = a.colPivHouseholderQr().solve(-gf);
  k.relative_residual = (gf + a * mu).norm() / gf.norm();
  k.min_inequality_mu = INFINITY;
  for (std::size_t c = 0; c < cols.size(); ++c)
    if (is_inequality[c]) k.min_inequality_mu = std::min(k.min_inequality_mu, mu[static_cast<Eigen::Index>(c)]);
  return k;
}

void expect_feasible(opt::Problem& p, const std::vector<double>& x, double tol) {
  const opt::Evaluation e = p.evaluate(x);
  for (double g : e.inequality) EXPECT_LE(g, tol);
  for (double h : e.equality) EXPECT_LE(std::fabs(h), tol);
}

TEST(Rosenbrock, OptimumIsZeroAtOnesWithZeroGradient) {
  for (int n = 2; n <= 10; ++n) {
    opt::benchmarks::Rosenbrock p(n);
    const auto best = *p.best_known();
    EXPECT_EQ(p.evaluate(best.x).objective, 0.0);
    for (double g : p.gradient(best.x)) EXPECT_EQ(g, 0.0);
    EXPECT_EQ(p.initial_point().size(), static_cast<std::size_t>(n));
  }
  opt::benchmarks::Rosenbrock p2(2);
  EXPECT_DOUBLE_EQ(p2.evaluate({-1.2, 1.0}).objective, 24.2);  // the classic starting value
}

TEST(Rosenbrock, AnalyticGradientMatchesCentralDifferences) {
  opt::benchmarks::Rosenbrock p(4);
  const std::vector<double> x{-1.2, 1.0, 0.3, -0.7};
  const Eigen::VectorXd fd = gradient(p, x, 0);
  const auto g = p.gradient(x);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(fd[i], g[static_cast<std::size_t>(i)], 1e-6 * std::max(1.0, std::fabs(g[i])));
}

TEST(Rosenbrock, DimensionOutsideTwoToTenIsAConfigError) {
  EXPECT_EQ(error_of([] { opt::benchmarks::Rosenbrock p(1); }), "rosenbrock dimension = 1: must be in [2, 10]");
  EXPECT_EQ(error_of([] { opt::benchmarks::Rosenbrock p(11); }), "rosenbrock dimension = 11: must be in [2, 10]");
}

TEST(Hs071, PublishedOptimumSatisfiesKkt) {
  opt::benchmarks::Hs071 p;
  const auto best = *p.best_known();
  EXPECT_NEAR(best.objective, 17.0140173, 1e-7);                    // the value in the brief
  EXPECT_NEAR(p.evaluate(best.x).objective, best.objective, 1e-12);
  expect_feasible(p, best.x, 1e-12);
  const Kkt k = kkt_at(p, best.x);
  EXPECT_EQ(k.active, 3);  // x1 = 1 (lower bound), product = 25, sum of squares = 40
  EXPECT_LT(k.relative_residual, 1e-6);
  EXPECT_GT(k.min_inequality_mu, 0.0);
  // The rounded point of the brief is feasible only to 1e-4.
  expect_feasible(p, {1, 4.74300, 3.82115, 1.37941}, 1e-4);
}

TEST(Cantilever, ClosedFormOptimumSatisfiesKkt) {
  opt::benchmarks::Cantilever p;
  const auto best = *p.best_known();
  EXPECT_NEAR(best.objective, 1.33996, 1e-5);  // Svanberg's published value
  const std::vector<double> published{6.016, 5.309, 4.494, 3.502, 2.153};
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(best.x[static_cast<std::size_t>(i)], published[static_cast<std::size_t>(i)], 1e-3);
  EXPECT_NEAR(p.evaluate(best.x).inequality[0], 0.0, 1e-12);  // the deflection constraint is active
  EXPECT_NEAR(p.evaluate(best.x).objective, best.objective, 1e-12);
  const Kkt k = kkt_at(p, best.x);
  EXPECT_EQ(k.active, 1);
  EXPECT_LT(k.relative_residual, 1e-7);
  EXPECT_GT(k.min_inequality_mu, 0.0);
}

TEST(TwoBarTruss, DerivedOptimumSatisfiesKkt) {
  opt::benchmarks::TwoBarTruss p;
  const auto best = *p.best_known();
  EXPECT_NEAR(best.objective, 1.5087, 1e-4);  // Svanberg's published value (4 digits)
  EXPECT_NEAR(best.x[0], 1.4116, 1e-4);
  EXPECT_NEAR(best.x[1], 0.3771, 1e-4);
  const opt::Evaluation e = p.evaluate(best.x);
  EXPECT_NEAR(e.inequality[0], 0.0, 1e-12);  // stress_1 active
  EXPECT_LT(e.inequality[1], -0.4);          // stress_2 inactive
  const Kkt k = kkt_at(p, best.x);
  EXPECT_EQ(k.active, 1);
  EXPECT_LT(k.relative_residual, 1e-7);
  EXPECT_GT(k.min_inequality_mu, 0.0);
  // and it is a minimum along the active constraint: neighbours on stress_1 = 0 weigh more
  for (double x2 : {best.x[1] - 0.01, best.x[1] + 0.01}) {
    const double r = std::sqrt(1 + x2 * x2);
    const double x1 = 0.124 * r * (8 + 1 / x2);
    EXPECT_GT(x1 * r, best.objective);
  }
}

TEST(BestKnown, EveryBenchmarkIsInsideItsBounds) {
  for (const auto& name : opt::benchmarks::benchmark_names()) {
    auto p = opt::benchmarks::make_benchmark(name);
    EXPECT_NO_THROW(opt::check_problem(*p)) << name;
    EXPECT_NO_THROW(opt::check_design_vector(*p, p->best_known()->x)) << name;
    EXPECT_NO_THROW(opt::check_design_vector(*p, p->initial_point())) << name;
  }
}

TEST(BenchmarkFactory, MakesEveryNamedProblem) {
  EXPECT_EQ(opt::benchmarks::make_benchmark("rosenbrock", {.dimension = 6})->dimension(), 6u);
  EXPECT_EQ(opt::benchmarks::make_benchmark("hs071")->name(), "hs071");
  EXPECT_EQ(opt::benchmarks::make_benchmark("noisy_two_bar_truss")->name(), "noisy_two_bar_truss");
  EXPECT_EQ(opt::benchmarks::make_benchmark("noisy_cantilever")->inequality_names(), std::vector<std::string>{"tip_deflection"});
  EXPECT_EQ(opt::benchmarks::benchmark_names().size(), 8u);
}

TEST(BenchmarkFactory, UnknownNameListsTheValidOnes) {
  EXPECT_EQ(error_of([] { opt::benchmarks::make_benchmark("rosenbrok"); }),
            "benchmark = rosenbrok: unknown benchmark problem; valid: rosenbrock, hs071, cantilever, "
            "two_bar_truss, noisy_rosenbrock, noisy_hs071, noisy_cantilever, noisy_two_bar_truss");
  EXPECT_EQ(error_of([] { opt::benchmarks::make_benchmark("noisy_x"); }).substr(0, 20), "benchmark = noisy_x:");
}

TEST(NoisyProblem, RepeatsAreIdenticalAndNoiseIsBoundedBySetAmplitude) {
  auto p = opt::benchmarks::make_benchmark("noisy_hs071", {.noise_amplitude = 0.01, .noise_seed = 7});
  opt::benchmarks::Hs071 clean;
  const std::vector<double> x{1.5, 4.0, 3.5, 1.5};
  const opt::Evaluation a = p->evaluate(x), b = p->evaluate(x), c = clean.evaluate(x);
  EXPECT_EQ(a.objective, b.objective);  // bitwise: common random numbers
  EXPECT_EQ(a.inequality, b.inequality);
  EXPECT_EQ(a.equality, b.equality);
  EXPECT_NE(a.objective, c.objective);
  EXPECT_LE(std::fabs(a.objective - c.objective), 0.01 * (1 + std::fabs(c.objective)));
  EXPECT_LE(std::fabs(a.equality[0] - c.equality[0]), 0.01 * (1 + std::fabs(c.equality[0])));
  EXPECT_EQ(a.metrics.at("noise_free_objective"), c.objective);
  // another seed, other noise; a neighbouring x, other noise
  auto q = opt::benchmarks::make_benchmark("noisy_hs071", {.noise_amplitude = 0.01, .noise_seed = 8});
  EXPECT_NE(q->evaluate(x).objective, a.objective);
  std::vector<double> y = x;
  y[0] = std::nextafter(y[0], 2.0);
  EXPECT_NE(p->evaluate(y).objective, a.objective);
  EXPECT_EQ(error_of([] { opt::benchmarks::make_benchmark("noisy_cantilever", {.noise_amplitude = 1.5}); }),
            "noise_amplitude = 1.5: must be in [0, 1)");
}

TEST(NoisyProblem, UnitNoiseIsUniformInMinusOneToOne) {
  double lo = 1, hi = -1, sum = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double u = opt::benchmarks::NoisyProblem::unit_noise({0.001 * i}, 3, 0);
    lo = std::min(lo, u);
    hi = std::max(hi, u);
    sum += u;
  }
  EXPECT_GE(lo, -1.0);
  EXPECT_LT(hi, 1.0);
  EXPECT_LT(lo, -0.99);
  EXPECT_GT(hi, 0.99);
  EXPECT_NEAR(sum / n, 0.0, 0.02);  // mean of U(-1,1): 0, sd of the mean 0.004
}

}  // namespace
