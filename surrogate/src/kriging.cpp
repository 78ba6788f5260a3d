#include "abuopt/surrogate/kriging.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <stdexcept>
#include <vector>

#include <nlopt.hpp>

#include "abuopt/surrogate/doe.hpp"
#include "surrogate_checks.hpp"

namespace abuopt::surrogate {
namespace {

constexpr double kNegativeInfinity = -std::numeric_limits<double>::infinity();
// The fit escalates a failing nugget by x10 up to this value before giving up.
constexpr double kLargestAutomaticNugget = 1e-2;

// Everything the prediction needs from one factorisation of R.
struct Factorisation {
  bool ok = false;
  Eigen::LLT<Eigen::MatrixXd> llt;
  Eigen::VectorXd r_inv_ones;
  double ones_r_inv_ones = 0.0;
  double mu = 0.0;
  Eigen::VectorXd alpha;
  double sigma2 = 0.0;
  double log_likelihood = kNegativeInfinity;
  double reciprocal_condition = 0.0;  // LLT estimate of 1 / cond_1(R)
};

Eigen::MatrixXd correlation_matrix(const Eigen::MatrixXd& X,
                                   const Eigen::VectorXd& inverse_squared_scales,
                                   double nugget) {
  const Eigen::Index m = X.rows();
  Eigen::MatrixXd R(m, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    R(i, i) = 1.0 + nugget;
    for (Eigen::Index j = i + 1; j < m; ++j) {
      const double d2 =
          (X.row(i) - X.row(j)).cwiseAbs2().dot(inverse_squared_scales.transpose());
      R(i, j) = R(j, i) = std::exp(-0.5 * d2);
    }
  }
  return R;
}

Factorisation factorise(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                        const Eigen::VectorXd& inverse_squared_scales, double nugget) {
  Factorisation f;
  f.llt.compute(correlation_matrix(X, inverse_squared_scales, nugget));
  if (f.llt.info() != Eigen::Success) return f;
  const Eigen::Index m = X.rows();
  const Eigen::MatrixXd& L = f.llt.matrixLLT();
  double log_det = 0.0;
  for (Eigen::Index i = 0; i < m; ++i) {
    const double d = L(i, i);
    if (!(d > 0.0) || !std::isfinite(d)) return f;
    log_det += 2.0 * std::log(d);
  }
  f.reciprocal_condition = f.llt.rcond();
  f.r_inv_ones = f.llt.solve(Eigen::VectorXd::Ones(m));
  f.ones_r_inv_ones = f.r_inv_ones.sum();
  if (!(f.ones_r_inv_ones > 0.0) || !std::isfinite(f.ones_r_inv_ones)) return f;
  f.mu = f.r_inv_ones.dot(y) / f.ones_r_inv_ones;
  const Eigen::VectorXd centred = y.array() - f.mu;
  f.alpha = f.llt.solve(centred);
  // A constant response gives sigma^2 = 0; keep the logarithm finite.
  f.sigma2 = std::max(centred.dot(f.alpha) / static_cast<double>(m),
                      std::numeric_limits<double>::min());
  f.log_likelihood = -0.5 * (static_cast<double>(m) * std::log(f.sigma2) + log_det);
  f.ok = std::isfinite(f.log_likelihood) && f.alpha.allFinite();
  return f;
}

Eigen::VectorXd inverse_squares(const Eigen::VectorXd& length_scales) {
  return length_scales.array().square().inverse().matrix();
}

void validate(const KrigingOptions& o, int n) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("KrigingOptions." + what);
  };
  if (!(std::isfinite(o.nugget) && o.nugget >= 0.0)) {
    fail("nugget = " + std::to_string(o.nugget) + ": must be finite and >= 0");
  }
  if (o.estimate_nugget) {
    if (!(o.nugget > 0.0)) {
      fail("nugget = " + std::to_string(o.nugget) + ": must be > 0 when estimate_nugget");
    }
    if (!(std::isfinite(o.max_nugget) && o.max_nugget > o.nugget)) {
      fail("max_nugget = " + std::to_string(o.max_nugget) + ": must be > nugget = " +
           std::to_string(o.nugget) + " when estimate_nugget");
    }
  }
  if (!(o.min_length_scale > 0.0)) {
    fail("min_length_scale = " + std::to_string(o.min_length_scale) + ": must be > 0");
  }
  if (!(std::isfinite(o.max_length_scale) && o.max_length_scale > o.min_length_scale)) {
    fail("max_length_scale = " + std::to_string(o.max_length_scale) +
         ": must be finite and > min_length_scale = " + std::to_string(o.min_length_scale));
  }
  if (!(o.max_condition_number >= 1.0)) {
    fail("max_condition_number = " + std::to_string(o.max_condition_number) + ": must be >= 1");
  }
  if (o.starts < 1) fail("starts = " + std::to_string(o.starts) + ": must be >= 1");
  if (o.max_evaluations < 10) {
    fail("max_evaluations = " + std::to_string(o.max_evaluations) + ": must be >= 10");
  }
  if (o.initial_length_scales.size() != 0) {
    if (o.initial_length_scales.size() != n) {
      fail("initial_length_scales has " + std::to_string(o.initial_length_scales.size()) +
           " values, the data has " + std::to_string(n) + " variables: must be equal");
    }
    if (!(o.initial_length_scales.array() > 0.0).all() ||
        !o.initial_length_scales.allFinite()) {
      fail("initial_length_scales: every value must be finite and > 0");
    }
  } else if (!o.optimize) {
    fail("initial_length_scales is empty: required when optimize = false");
  }
}

// State of the likelihood maximisation: variables z = (ln l_1, .., ln l_n[, ln lambda]).
struct LikelihoodProblem {
  const Eigen::MatrixXd* X = nullptr;
  const Eigen::VectorXd* y = nullptr;
  int n = 0;
  bool estimate_nugget = false;
  double fixed_nugget = 0.0;
  double max_condition_number = 0.0;
  int evaluations = 0;
  double best = kNegativeInfinity;
  std::vector<double> best_z;

  double log_likelihood(const std::vector<double>& z) {
    ++evaluations;
    Eigen::VectorXd scales(n);
    for (int k = 0; k < n; ++k) scales[k] = std::exp(z[static_cast<std::size_t>(k)]);
    const double nugget =
        estimate_nugget ? std::exp(z[static_cast<std::size_t>(n)]) : fixed_nugget;
    const Factorisation f = factorise(*X, *y, inverse_squares(scales), nugget);
    double value = f.log_likelihood;
    // Smooth barrier beyond the condition-number cap: ln L - m (log10(cond / cap))^2. Without
    // it, smooth data drive the length scales up until R is singular to working precision and
    // r^T alpha loses most of its digits.
    const double excess =
        std::log10(max_condition_number * std::max(f.reciprocal_condition, 1e-300));
    if (std::isfinite(value) && excess < 0.0) {
      value -= static_cast<double>(X->rows()) * excess * excess;
    }
    if (value > best) {
      best = value;
      best_z = z;
    }
    return value;
  }
};

double negative_log_likelihood(const std::vector<double>& z, std::vector<double>& /*grad*/,
                               void* data) {
  const double value = static_cast<LikelihoodProblem*>(data)->log_likelihood(z);
  // A failed factorisation is a large finite penalty: BOBYQA's models need finite values.
  return std::isfinite(value) ? -value : 1e300;
}

}  // namespace

double kriging_log_likelihood(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                              const Eigen::VectorXd& length_scales, double nugget) {
  detail::check_training_data("kriging_log_likelihood", X, y);
  if (length_scales.size() != X.cols()) {
    throw std::invalid_argument("kriging_log_likelihood: X has " + std::to_string(X.cols()) +
                                " variables, length_scales has " +
                                std::to_string(length_scales.size()) + " values");
  }
  return factorise(X, y, inverse_squares(length_scales), nugget).log_likelihood;
}

Kriging::Kriging(KrigingOptions options) : options_(std::move(options)) {}

void Kriging::fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  detail::check_training_data("Kriging::fit", X, y);
  if (X.rows() < 2) {
    throw InsufficientData("Kriging::fit: kriging needs at least 2 points, got " +
                                std::to_string(X.rows()));
  }
  const int n = static_cast<int>(X.cols());
  validate(options_, n);

  Eigen::VectorXd span = X.colwise().maxCoeff() - X.colwise().minCoeff();
  for (int k = 0; k < n; ++k) {
    if (!(span[k] > 0.0)) span[k] = 1.0;  // a constant column: any length scale is equivalent
  }
  const Eigen::VectorXd lower = (options_.min_length_scale * span).array().log();
  const Eigen::VectorXd upper = (options_.max_length_scale * span).array().log();
  const Eigen::VectorXd initial = options_.initial_length_scales.size() == n
                                      ? options_.initial_length_scales
                                      : Eigen::VectorXd(0.5 * span);

  Eigen::VectorXd scales = initial;
  double nugget = options_.nugget;
  int evaluations = 0;
  if (options_.optimize) {
    const int vars = n + (options_.estimate_nugget ? 1 : 0);
    std::vector<double> lo(static_cast<std::size_t>(vars));
    std::vector<double> hi(static_cast<std::size_t>(vars));
    for (int k = 0; k < n; ++k) {
      lo[static_cast<std::size_t>(k)] = lower[k];
      hi[static_cast<std::size_t>(k)] = upper[k];
    }
    if (options_.estimate_nugget) {
      lo.back() = std::log(options_.nugget);
      hi.back() = std::log(options_.max_nugget);
    }
    // Starting points: the initial guess (clamped to the bounds), then a seeded Latin
    // hypercube over the log box.
    std::vector<std::vector<double>> starts;
    std::vector<double> z0(static_cast<std::size_t>(vars));
    for (int k = 0; k < n; ++k) {
      z0[static_cast<std::size_t>(k)] =
          std::clamp(std::log(initial[k]), lower[k], upper[k]);
    }
    if (options_.estimate_nugget) z0.back() = 0.5 * (lo.back() + hi.back());
    starts.push_back(z0);
    if (options_.starts > 1) {
      LatinHypercubeOptions lhs;
      lhs.points = options_.starts - 1;
      lhs.candidates = 10;
      lhs.seed = options_.seed;
      const Eigen::MatrixXd unit = latin_hypercube(vars, lhs);
      for (Eigen::Index s = 0; s < unit.rows(); ++s) {
        std::vector<double> z(static_cast<std::size_t>(vars));
        for (int k = 0; k < vars; ++k) {
          const auto kk = static_cast<std::size_t>(k);
          z[kk] = lo[kk] + 0.5 * (unit(s, k) + 1.0) * (hi[kk] - lo[kk]);
        }
        starts.push_back(std::move(z));
      }
    }

    LikelihoodProblem problem;
    problem.X = &X;
    problem.y = &y;
    problem.n = n;
    problem.estimate_nugget = options_.estimate_nugget;
    problem.fixed_nugget = options_.nugget;
    problem.max_condition_number = options_.max_condition_number;
    for (auto& z : starts) {
      nlopt::opt opt(nlopt::LN_BOBYQA, static_cast<unsigned>(vars));
      opt.set_lower_bounds(lo);
      opt.set_upper_bounds(hi);
      opt.set_min_objective(negative_log_likelihood, &problem);
      opt.set_maxeval(options_.max_evaluations);
      opt.set_xtol_abs(1e-4);  // in ln(length scale): 0.01 % of a length scale
      opt.set_ftol_abs(1e-10);
      double f = 0.0;
      try {
        opt.optimize(z, f);
      } catch (const std::exception&) {
        // Round-off or a failed step: the best point seen so far is kept by `problem`.
      }
    }
    evaluations = problem.evaluations;
    if (!problem.best_z.empty()) {
      for (int k = 0; k < n; ++k) scales[k] = std::exp(problem.best_z[static_cast<std::size_t>(k)]);
      if (options_.estimate_nugget) nugget = std::exp(problem.best_z.back());
    }
  }

  const Eigen::VectorXd inv_sq = inverse_squares(scales);
  Factorisation f = factorise(X, y, inv_sq, nugget);
  while (!f.ok && nugget < kLargestAutomaticNugget) {
    nugget = nugget > 0.0 ? 10.0 * nugget : 1e-12;
    f = factorise(X, y, inv_sq, nugget);
  }
  if (!f.ok) {
    throw InsufficientData(
        "Kriging::fit: the correlation matrix is not positive definite even with nugget " +
        std::to_string(nugget) + " (duplicate points or far too long length scales?)");
  }

  dimension_ = n;
  X_ = X;
  length_scales_ = scales;
  inverse_squared_scales_ = inv_sq;
  cholesky_ = std::move(f.llt);
  alpha_ = std::move(f.alpha);
  r_inv_ones_ = std::move(f.r_inv_ones);
  ones_r_inv_ones_ = f.ones_r_inv_ones;
  mu_ = f.mu;
  sigma2_ = f.sigma2;
  nugget_ = nugget;
  log_likelihood_ = f.log_likelihood;
  evaluations_ = evaluations;
}

void Kriging::check_point(const Eigen::VectorXd& x) const {
  detail::check_query_point("Kriging", dimension_, x);
}

Eigen::VectorXd Kriging::correlations(const Eigen::VectorXd& x) const {
  const Eigen::MatrixXd diff = X_.rowwise() - x.transpose();
  return (-0.5 * (diff.cwiseAbs2() * inverse_squared_scales_)).array().exp().matrix();
}

double Kriging::value(const Eigen::VectorXd& x) const {
  check_point(x);
  return mu_ + correlations(x).dot(alpha_);
}

Eigen::VectorXd Kriging::gradient(const Eigen::VectorXd& x) const {
  check_point(x);
  const Eigen::VectorXd weights = correlations(x).cwiseProduct(alpha_);  // alpha_i r_i
  // d r_i / d x_k = -r_i (x_k - x_ik) / l_k^2
  const Eigen::MatrixXd diff = X_.rowwise() - x.transpose();  // x_ik - x_k
  return (diff.transpose() * weights).cwiseProduct(inverse_squared_scales_);
}

double Kriging::variance(const Eigen::VectorXd& x) const {
  check_point(x);
  const Eigen::VectorXd r = correlations(x);
  const Eigen::VectorXd v = cholesky_.matrixL().solve(r);  // r^T R^-1 r = |L^-1 r|^2
  const double u = 1.0 - r_inv_ones_.dot(r);
  const double s2 = sigma2_ * (1.0 - v.squaredNorm() + u * u / ones_r_inv_ones_);
  return std::max(s2, 0.0);
}

}  // namespace abuopt::surrogate
