// Ordinary kriging: interpolation, prediction between points, analytic gradient, predictive
// variance, likelihood maximisation and noisy data (kriging.hpp).

#include "abuopt/surrogate/kriging.hpp"

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "expect_invalid_argument.hpp"

#include "abuopt/surrogate/doe.hpp"

namespace abuopt::surrogate {
namespace {

double smooth_2d(const Eigen::VectorXd& x) {
  return std::sin(2.0 * x[0]) + std::cos(1.5 * x[1]) + 0.5 * x[0] * x[1];
}

Eigen::VectorXd sample(const Eigen::MatrixXd& X, double (*f)(const Eigen::VectorXd&)) {
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) y[i] = f(X.row(i).transpose());
  return y;
}

Eigen::MatrixXd lhs_points(int n, int points, std::uint64_t seed) {
  LatinHypercubeOptions options;
  options.points = points;
  options.seed = seed;
  return latin_hypercube(n, options);
}

using test::invalid_argument_message;

TEST(Kriging, HandComputedTwoPointModel) {
  // x = 0, 1; y = 0, 1; l = 1, no nugget: rho = exp(-1/2), mu = 1/2 by symmetry,
  // alpha = (-1/2, 1/2) / (1 - rho). At x = 2: r = (exp(-2), exp(-1/2)).
  KrigingOptions options;
  options.optimize = false;
  options.nugget = 0.0;
  options.initial_length_scales = Eigen::VectorXd::Ones(1);
  Kriging k(options);
  k.fit(Eigen::Vector2d(0.0, 1.0), Eigen::Vector2d(0.0, 1.0));
  const double rho = std::exp(-0.5);
  EXPECT_NEAR(k.mean(), 0.5, 1e-14);
  // sigma^2 = (y - mu)^T R^-1 (y - mu) / 2 = (0.5 / (1 - rho)) / 2
  EXPECT_NEAR(k.process_variance(), 0.25 / (1.0 - rho), 1e-14);
  EXPECT_NEAR(k.value(Eigen::VectorXd::Constant(1, 0.5)), 0.5, 1e-14);
  const double expected = 0.5 + 0.5 * (rho - std::exp(-2.0)) / (1.0 - rho);
  EXPECT_NEAR(k.value(Eigen::VectorXd::Constant(1, 2.0)), expected, 1e-14);
  EXPECT_EQ(k.length_scales()[0], 1.0);
  EXPECT_EQ(k.likelihood_evaluations(), 0);
  EXPECT_EQ(k.name(), "kriging");
}

TEST(Kriging, InterpolatesTrainingPointsWithSmallNugget) {
  const Eigen::MatrixXd X = lhs_points(2, 20, 1);
  const Eigen::VectorXd y = sample(X, smooth_2d);
  Kriging k;  // nugget 1e-10
  k.fit(X, y);
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    EXPECT_NEAR(k.value(X.row(i).transpose()), y[i], 1e-6) << "point " << i;  // measured 1e-7
    EXPECT_LT(k.variance(X.row(i).transpose()), 1e-6 * k.process_variance()) << "point " << i;
  }
  EXPECT_GT(k.likelihood_evaluations(), 0);
}

TEST(Kriging, PredictsSmooth1DFunctionBetweenPoints) {
  // sin(3x) from 8 equally spaced points on [-1, 1]; checked at the 7 midpoints.
  const Eigen::MatrixXd X = full_factorial(1, 8);
  const auto f = [](double x) { return std::sin(3.0 * x); };
  Eigen::VectorXd y(8);
  for (int i = 0; i < 8; ++i) y[i] = f(X(i, 0));
  Kriging k;
  k.fit(X, y);
  for (int i = 0; i < 7; ++i) {
    const double mid = 0.5 * (X(i, 0) + X(i + 1, 0));
    const Eigen::VectorXd x = Eigen::VectorXd::Constant(1, mid);
    EXPECT_NEAR(k.value(x), f(mid), 2e-3) << "x = " << mid;  // measured max 3.3e-4
    EXPECT_GT(k.variance(x), 0.0);
  }
}

TEST(Kriging, PredictsSmooth2DFunctionBetweenPoints) {
  const Eigen::MatrixXd X = lhs_points(2, 30, 2);
  Kriging k;
  k.fit(X, sample(X, smooth_2d));
  // 200 test points inside [-0.9, 0.9]^2 (extrapolation to the corners is not tested).
  const Eigen::MatrixXd T = 0.9 * lhs_points(2, 200, 99);
  double max_error = 0.0;
  for (Eigen::Index i = 0; i < T.rows(); ++i) {
    max_error = std::max(max_error, std::abs(k.value(T.row(i).transpose()) -
                                             smooth_2d(T.row(i).transpose())));
  }
  EXPECT_LT(max_error, 2e-2);  // measured 1.3e-2; the function ranges over about 3
}

TEST(Kriging, GradientMatchesCentralDifferences) {
  const Eigen::MatrixXd X = lhs_points(3, 25, 4);
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    y[i] = std::exp(0.5 * X(i, 0)) * std::sin(X(i, 1)) + X(i, 2) * X(i, 2);
  }
  Kriging k;
  k.fit(X, y);
  // Central differences with h = 1e-4: truncation ~ h^2 f''' / 6 ~ 1e-9, round-off ~ 1e-10.
  const double h = 1e-4;
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(0.1, -0.3, 0.7), Eigen::Vector3d(-0.8, 0.5, 0.0),
                                  Eigen::Vector3d(X.row(3).transpose())}) {
    const Eigen::VectorXd g = k.gradient(x);
    for (int j = 0; j < 3; ++j) {
      Eigen::VectorXd xp = x, xm = x;
      xp[j] += h;
      xm[j] -= h;
      const double fd = (k.value(xp) - k.value(xm)) / (2.0 * h);
      EXPECT_NEAR(g[j], fd, 1e-6 * (1.0 + std::abs(fd))) << "component " << j;
    }
  }
}

// Condition number of the correlation matrix as the fit estimates it (LLT::rcond).
double condition_number(const Eigen::MatrixXd& X, const Eigen::VectorXd& scales, double nugget) {
  const Eigen::Index m = X.rows();
  Eigen::MatrixXd R(m, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    for (Eigen::Index j = 0; j < m; ++j) {
      const double d2 = ((X.row(i) - X.row(j)).transpose().array() / scales.array()).square().sum();
      R(i, j) = std::exp(-0.5 * d2) + (i == j ? nugget : 0.0);
    }
  }
  return 1.0 / R.llt().rcond();
}

TEST(Kriging, FittedLengthScalesMaximiseTheLikelihoodAndSeeAnisotropy) {
  // Strong variation along x0, almost none along x1: l_1 must come out much longer than l_0.
  const Eigen::MatrixXd X = lhs_points(2, 25, 5);
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) y[i] = std::sin(3.0 * X(i, 0)) + 0.05 * X(i, 1);
  Kriging k;
  k.fit(X, y);
  EXPECT_GT(k.length_scales()[1], 3.0 * k.length_scales()[0]);
  EXPECT_NEAR(kriging_log_likelihood(X, y, k.length_scales(), k.nugget()), k.log_likelihood(),
              1e-9 * std::abs(k.log_likelihood()));
  // The cap is a soft barrier: a factor 10 beyond it would cost m = 25 units of ln L.
  EXPECT_LE(condition_number(X, k.length_scales(), k.nugget()),
            10.0 * k.options().max_condition_number);
  // No candidate on a grid of length scales that respects the condition cap (the search's
  // feasible region) has a higher likelihood; nor does shrinking either fitted scale by 5 %.
  int feasible = 0;
  for (const double l0 : {0.05, 0.1, 0.2, 0.4, 0.8, 1.6, 3.2}) {
    for (const double l1 : {0.1, 0.4, 1.6, 6.4, 19.0}) {
      const Eigen::Vector2d scales(l0, l1);
      if (condition_number(X, scales, k.nugget()) > k.options().max_condition_number) continue;
      ++feasible;
      EXPECT_LE(kriging_log_likelihood(X, y, scales, k.nugget()), k.log_likelihood() + 1e-6)
          << "l = (" << l0 << ", " << l1 << ")";
    }
  }
  EXPECT_GE(feasible, 10);
  for (int j = 0; j < 2; ++j) {
    Eigen::VectorXd scales = k.length_scales();
    scales[j] *= 0.95;
    EXPECT_LE(kriging_log_likelihood(X, y, scales, k.nugget()), k.log_likelihood() + 1e-6)
        << "scale " << j;
  }
}

TEST(Kriging, SameOptionsGiveTheSameModel) {
  const Eigen::MatrixXd X = lhs_points(2, 15, 6);
  const Eigen::VectorXd y = sample(X, smooth_2d);
  Kriging a, b;
  a.fit(X, y);
  b.fit(X, y);
  EXPECT_EQ(a.length_scales(), b.length_scales());
  EXPECT_EQ(a.value(Eigen::Vector2d(0.2, 0.1)), b.value(Eigen::Vector2d(0.2, 0.1)));
}

TEST(Kriging, VarianceGrowsAwayFromTheData) {
  const Eigen::MatrixXd X = full_factorial(1, 6);
  Eigen::VectorXd y(6);
  for (int i = 0; i < 6; ++i) y[i] = std::cos(2.0 * X(i, 0));
  Kriging k;
  k.fit(X, y);
  const auto s2 = [&](double x) { return k.variance(Eigen::VectorXd::Constant(1, x)); };
  EXPECT_LT(s2(-1.0), 1e-8 * k.process_variance());
  EXPECT_GT(s2(-0.8), s2(-1.0));
  EXPECT_GT(s2(1.5), s2(-0.8));
  EXPECT_GT(s2(10.0), 0.99 * k.process_variance());  // far away: back to the prior variance
}

TEST(Kriging, NuggetSmoothsNoisyData) {
  // sin(2x) + noise (sd 0.05) at 40 points; an estimated nugget regresses instead of
  // interpolating and stays closer to the true function than the noisy data are.
  const Eigen::MatrixXd X = lhs_points(1, 40, 7);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  Eigen::VectorXd y(40);
  for (int i = 0; i < 40; ++i) y[i] = std::sin(2.0 * X(i, 0)) + noise(rng);

  KrigingOptions options;
  options.nugget = 1e-8;
  options.estimate_nugget = true;
  Kriging k(options);
  k.fit(X, y);
  EXPECT_GT(k.nugget(), 1e-4);
  double data_error = 0.0, model_error = 0.0;
  for (int i = 0; i < 40; ++i) {
    const double truth = std::sin(2.0 * X(i, 0));
    data_error += (y[i] - truth) * (y[i] - truth);
    const double e = k.value(X.row(i).transpose()) - truth;
    model_error += e * e;
  }
  EXPECT_LT(model_error, 0.5 * data_error);
}

TEST(Kriging, UsageErrors) {
  Kriging k;
  EXPECT_THROW(k.value(Eigen::Vector2d::Zero()), std::logic_error);
  EXPECT_EQ(invalid_argument_message([&] {
              k.fit(Eigen::MatrixXd::Zero(1, 2), Eigen::VectorXd::Zero(1));
            }),
            "Kriging::fit: kriging needs at least 2 points, got 1");
  EXPECT_THROW(k.fit(Eigen::MatrixXd::Zero(1, 2), Eigen::VectorXd::Zero(1)), InsufficientData);
  KrigingOptions fixed;
  fixed.optimize = false;
  Kriging no_scales(fixed);
  EXPECT_EQ(invalid_argument_message([&] {
              no_scales.fit(Eigen::Vector2d(0, 1), Eigen::Vector2d(0, 1));
            }),
            "KrigingOptions.initial_length_scales is empty: required when optimize = false");
  KrigingOptions bad;
  bad.nugget = -1.0;
  Kriging negative(bad);
  EXPECT_EQ(invalid_argument_message([&] {
              negative.fit(Eigen::Vector2d(0, 1), Eigen::Vector2d(0, 1));
            }),
            "KrigingOptions.nugget = -1.000000: must be finite and >= 0");
  k.fit(Eigen::Vector2d(0, 1), Eigen::Vector2d(0, 1));
  EXPECT_EQ(invalid_argument_message([&] { k.gradient(Eigen::Vector2d::Zero()); }),
            "Kriging: the surrogate was fitted in 1 variables, x has 2");
}

}  // namespace
}  // namespace abuopt::surrogate
