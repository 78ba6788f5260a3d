// Polynomial response surfaces: exact recovery, diagnostics, weights and errors
// (response_surface.hpp).

#include "abuopt/surrogate/response_surface.hpp"

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "expect_invalid_argument.hpp"

#include "abuopt/surrogate/doe.hpp"

namespace abuopt::surrogate {
namespace {

constexpr Basis kBases[] = {Basis::kLinear, Basis::kInteractions, Basis::kPureQuadratic,
                            Basis::kQuadratic};

// Known full quadratic in 3 variables, coefficients in the documented term order:
// 1, x0, x1, x2, x0^2, x1^2, x2^2, x0x1, x0x2, x1x2.
Eigen::VectorXd known_coefficients() {
  Eigen::VectorXd beta(10);
  beta << 1.0, 2.0, -3.0, 0.5, 4.0, -1.0, 2.0, 1.5, -0.7, 0.3;
  return beta;
}

// The known polynomial restricted to `basis` (other coefficients zero).
Eigen::VectorXd restricted(const Eigen::VectorXd& full, Basis basis) {
  switch (basis) {
    case Basis::kLinear: return full.head(4);
    case Basis::kInteractions: {
      Eigen::VectorXd b(7);
      b << full.head(4), full.tail(3);
      return b;
    }
    case Basis::kPureQuadratic: return full.head(7);
    case Basis::kQuadratic: return full;
  }
  return {};
}

Eigen::VectorXd evaluate(Basis basis, const Eigen::VectorXd& beta, const Eigen::MatrixXd& X) {
  Eigen::VectorXd y(X.rows());
  for (Eigen::Index i = 0; i < X.rows(); ++i) y[i] = basis_terms(basis, X.row(i).transpose()).dot(beta);
  return y;
}

using test::invalid_argument_message;

TEST(TermsCount, MatchesFormulas) {
  EXPECT_EQ(terms_count(Basis::kLinear, 3), 4);
  EXPECT_EQ(terms_count(Basis::kInteractions, 3), 7);
  EXPECT_EQ(terms_count(Basis::kPureQuadratic, 3), 7);
  EXPECT_EQ(terms_count(Basis::kQuadratic, 3), 10);
  for (int n = 1; n <= 8; ++n) {
    EXPECT_EQ(terms_count(Basis::kQuadratic, n), (n + 1) * (n + 2) / 2) << "n = " << n;
  }
  EXPECT_THROW(terms_count(Basis::kLinear, 0), std::invalid_argument);
  const std::vector<std::string> names = term_names(Basis::kQuadratic, 3);
  ASSERT_EQ(names.size(), 10u);
  EXPECT_EQ(names[4], "x0^2");
  EXPECT_EQ(names[7], "x0*x1");
  EXPECT_EQ(names[9], "x1*x2");
}

TEST(BasisNames, RoundTripAndRejectUnknown) {
  for (const Basis b : kBases) EXPECT_EQ(basis_from_string(to_string(b)), b);
  EXPECT_EQ(invalid_argument_message([] { basis_from_string("cubic"); }),
            "response surface basis \"cubic\": must be one of linear, interactions, "
            "pure_quadratic, quadratic");
}

TEST(ResponseSurface, EveryBasisRecoversItsPolynomialExactly) {
  const Eigen::MatrixXd X = full_factorial(3, 3);  // 27 points, enough for every basis
  const Eigen::Vector3d probe(0.3, -0.8, 0.55);
  for (const Basis basis : kBases) {
    SCOPED_TRACE(to_string(basis));
    const Eigen::VectorXd beta = restricted(known_coefficients(), basis);
    ResponseSurface rs(basis);
    rs.fit(X, evaluate(basis, beta, X));
    ASSERT_EQ(rs.terms(), terms_count(basis, 3));
    EXPECT_LT((rs.coefficients() - beta).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_NEAR(rs.value(probe), basis_terms(basis, probe).dot(beta), 1e-10);
    EXPECT_NEAR(rs.diagnostics().r_squared, 1.0, 1e-12);
    EXPECT_NEAR(rs.diagnostics().adjusted_r_squared, 1.0, 1e-12);
    EXPECT_LT(rs.diagnostics().press, 1e-20);
    EXPECT_LT(rs.diagnostics().loo_rms, 1e-10);
    EXPECT_EQ(rs.diagnostics().points, 27);
    EXPECT_EQ(rs.diagnostics().terms, terms_count(basis, 3));
  }
}

TEST(ResponseSurface, QuadraticOnCentralCompositeGradientAndHessian) {
  const Eigen::MatrixXd X = central_composite(3);  // 15 points >= 10 terms
  const Eigen::VectorXd beta = known_coefficients();
  ResponseSurface rs(Basis::kQuadratic);
  rs.fit(X, evaluate(Basis::kQuadratic, beta, X));
  EXPECT_EQ(rs.name(), "quadratic");
  EXPECT_LT((rs.coefficients() - beta).cwiseAbs().maxCoeff(), 1e-10);

  // Analytic gradient and Hessian of the known polynomial.
  const Eigen::Vector3d x(0.3, -0.8, 0.55);
  Eigen::Vector3d g;
  g[0] = 2.0 + 2 * 4.0 * x[0] + 1.5 * x[1] - 0.7 * x[2];
  g[1] = -3.0 + 2 * -1.0 * x[1] + 1.5 * x[0] + 0.3 * x[2];
  g[2] = 0.5 + 2 * 2.0 * x[2] - 0.7 * x[0] + 0.3 * x[1];
  EXPECT_LT((rs.gradient(x) - g).cwiseAbs().maxCoeff(), 1e-10);
  Eigen::Matrix3d H;
  H << 8.0, 1.5, -0.7, 1.5, -2.0, 0.3, -0.7, 0.3, 4.0;
  EXPECT_LT((rs.hessian(x) - H).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT(rs.diagnostics().press, 1e-20);
}

TEST(ResponseSurface, NoisyDataDiagnosticsAndExactPress) {
  // Quadratic trend plus Gaussian noise (sd 0.1), fitted by a full quadratic on 30 LHS points.
  LatinHypercubeOptions lhs;
  lhs.points = 30;
  lhs.seed = 11;
  const Eigen::MatrixXd X = latin_hypercube(3, lhs);
  Eigen::VectorXd y = evaluate(Basis::kQuadratic, known_coefficients(), X);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.1);
  for (Eigen::Index i = 0; i < y.size(); ++i) y[i] += noise(rng);

  ResponseSurface rs(Basis::kQuadratic);
  rs.fit(X, y);
  const FitDiagnostics& d = rs.diagnostics();
  EXPECT_LT(d.r_squared, 1.0);
  EXPECT_GT(d.r_squared, 0.95);  // the trend's variance dwarfs the noise's
  EXPECT_LT(d.adjusted_r_squared, d.r_squared);
  EXPECT_GT(d.residual_rms, 0.03);  // noise sd 0.1, 20 degrees of freedom of 30
  EXPECT_LT(d.residual_rms, 0.2);
  EXPECT_GT(d.loo_rms, d.residual_rms);  // leave-one-out errors exceed the residuals
  EXPECT_NEAR(d.leverages.sum(), 10.0, 1e-10);  // trace(H) = p

  // PRESS from the hat matrix equals 30 explicit leave-one-out refits (to round-off).
  double press = 0.0;
  for (Eigen::Index out = 0; out < X.rows(); ++out) {
    Eigen::MatrixXd Xs(X.rows() - 1, 3);
    Eigen::VectorXd ys(X.rows() - 1);
    for (Eigen::Index i = 0, r = 0; i < X.rows(); ++i) {
      if (i == out) continue;
      Xs.row(r) = X.row(i);
      ys[r++] = y[i];
    }
    ResponseSurface loo(Basis::kQuadratic);
    loo.fit(Xs, ys);
    const double e = y[out] - loo.value(X.row(out).transpose());
    press += e * e;
  }
  EXPECT_NEAR(d.press, press, 1e-10 * press);
}

TEST(ResponseSurface, ZeroWeightIgnoresAnOutlierAndWeightsActLikeReplicates) {
  Eigen::MatrixXd X = full_factorial(2, 3);  // 9 points
  const Eigen::VectorXd beta = (Eigen::VectorXd(6) << 1, 2, 3, 4, 5, 6).finished();
  Eigen::VectorXd y = evaluate(Basis::kQuadratic, beta, X);
  y[4] += 100.0;  // outlier at the centre
  Eigen::VectorXd w = Eigen::VectorXd::Ones(9);
  w[4] = 0.0;
  ResponseSurface rs(Basis::kQuadratic);
  rs.fit(X, y, w);
  EXPECT_LT((rs.coefficients() - beta).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_EQ(rs.diagnostics().points, 8);

  // Weight 3 on one point == that point listed three times.
  y[4] -= 100.0;
  y[0] += 0.5;  // make the fit inexact so weights matter
  w.setOnes();
  w[0] = 3.0;
  rs.fit(X, y, w);
  Eigen::MatrixXd X3(11, 2);
  Eigen::VectorXd y3(11);
  X3 << X, X.row(0), X.row(0);
  y3 << y, y[0], y[0];
  ResponseSurface replicated(Basis::kQuadratic);
  replicated.fit(X3, y3);
  EXPECT_LT((rs.coefficients() - replicated.coefficients()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(rs.diagnostics().r_squared, replicated.diagnostics().r_squared, 1e-12);

  EXPECT_EQ(invalid_argument_message([&] {
              rs.fit(X, y, Eigen::VectorXd::Constant(9, -1.0));
            }),
            "ResponseSurface(quadratic)::fit: weights[0] = -1.000000: must be finite and >= 0");
}

TEST(ResponseSurface, SaturatedKoshalDesignHasInfinitePress) {
  const Eigen::MatrixXd X = koshal_linear(3);  // 4 points, 4 linear terms
  const Eigen::VectorXd beta = (Eigen::VectorXd(4) << 1, -2, 3, 0.5).finished();
  ResponseSurface rs(Basis::kLinear);
  rs.fit(X, evaluate(Basis::kLinear, beta, X));
  EXPECT_LT((rs.coefficients() - beta).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(rs.diagnostics().max_leverage, 1.0, 1e-12);
  EXPECT_TRUE(std::isinf(rs.diagnostics().press));
  EXPECT_TRUE(std::isnan(rs.diagnostics().adjusted_r_squared));
}

TEST(ResponseSurface, TooFewPointsNamesTheBasisAndCounts) {
  const Eigen::MatrixXd X = latin_hypercube(3, {.points = 7});
  const Eigen::VectorXd y = Eigen::VectorXd::Ones(7);
  ResponseSurface rs(Basis::kQuadratic);
  EXPECT_EQ(invalid_argument_message([&] { rs.fit(X, y); }),
            "full quadratic in 3 variables needs at least 10 points, got 7");
  ResponseSurface lin(Basis::kInteractions);
  EXPECT_EQ(invalid_argument_message([&] { lin.fit(X.topRows(6), y.head(6)); }),
            "linear with interactions in 3 variables needs at least 7 points, got 6");
  EXPECT_FALSE(rs.fitted());
}

TEST(ResponseSurface, RankDeficientDesignIsRejected) {
  // A two-level factorial, replicated: 8 points >= 6 terms, but x_i^2 == 1 == the constant.
  const Eigen::MatrixXd f = full_factorial(2, 2);
  Eigen::MatrixXd X(8, 2);
  X << f, f;
  ResponseSurface rs(Basis::kQuadratic);
  const std::string message =
      invalid_argument_message([&] { rs.fit(X, Eigen::VectorXd::Ones(8)); });
  EXPECT_NE(message.find("full quadratic in 2 variables needs at least 6 points in general "
                         "position, got 8 whose design matrix has rank 4"),
            std::string::npos)
      << message;
}

// Data that cannot determine the model is InsufficientData (a caller tries a simpler basis);
// inconsistent data is a plain invalid_argument (a programming error, not to be caught as the
// first).
TEST(ResponseSurface, InsufficientDataIsItsOwnErrorAndMisuseIsNot) {
  const Eigen::MatrixXd X = latin_hypercube(3, {.points = 7});
  ResponseSurface rs(Basis::kQuadratic);
  EXPECT_THROW(rs.fit(X, Eigen::VectorXd::Ones(7)), InsufficientData);
  const Eigen::MatrixXd f = full_factorial(2, 2);
  Eigen::MatrixXd R(8, 2);
  R << f, f;
  EXPECT_THROW(rs.fit(R, Eigen::VectorXd::Ones(8)), InsufficientData);
  bool insufficient = false, invalid = false;
  try {
    rs.fit(X, Eigen::VectorXd::Ones(6));  // sizes disagree
  } catch (const InsufficientData&) {
    insufficient = true;
  } catch (const std::invalid_argument&) {
    invalid = true;
  }
  EXPECT_FALSE(insufficient);
  EXPECT_TRUE(invalid);
}

TEST(ResponseSurface, UsageErrors) {
  ResponseSurface rs(Basis::kLinear);
  EXPECT_THROW(rs.value(Eigen::Vector2d(0, 0)), std::logic_error);
  rs.fit(koshal_linear(3), Eigen::VectorXd::Ones(4));
  EXPECT_EQ(invalid_argument_message([&] { rs.gradient(Eigen::Vector2d(0, 0)); }),
            "ResponseSurface(linear): the surrogate was fitted in 3 variables, x has 2");
  EXPECT_EQ(invalid_argument_message([&] { rs.fit(koshal_linear(3), Eigen::VectorXd::Ones(3)); }),
            "ResponseSurface(linear)::fit: X has 4 rows (points), y has 3 values: must be equal");
}

}  // namespace
}  // namespace abuopt::surrogate
