#pragma once
// Ordinary kriging (Gaussian-process regression with a constant mean).
//
// Model: y(x) = mu + Z(x), Z a zero-mean Gaussian process with variance sigma^2 and Gaussian
// (squared-exponential) correlation with one length scale l_k per variable:
//   R(x, x') = exp(-1/2 sum_k (x_k - x'_k)^2 / l_k^2).
// With the m training points, R_ij = R(x_i, x_j) + lambda delta_ij (lambda = nugget, for
// conditioning or, larger, for noisy data), r(x)_i = R(x, x_i), and 1 the vector of ones:
//   mu      = 1^T R^-1 y / 1^T R^-1 1
//   sigma^2 = (y - mu 1)^T R^-1 (y - mu 1) / m
//   ln L    = -1/2 (m ln sigma^2 + ln det R)        (concentrated log-likelihood, constants
//                                                      dropped)
// The length scales (and optionally lambda) maximise ln L, over log l_k in
// [ln(min_length_scale * span_k), ln(max_length_scale * span_k)], span_k = the range of the
// training points in variable k; NLopt LN_BOBYQA from `starts` starting points (the first is
// initial_length_scales or 0.5 span_k, the others a seeded Latin hypercube in log space), with
// a soft penalty keeping cond(R) near max_condition_number (see KrigingOptions).
// Prediction (alpha = R^-1 (y - mu 1), computed once by a Cholesky factorisation R = L L^T):
//   yhat(x)      = mu + r(x)^T alpha
//   d yhat/dx_k  = - sum_i alpha_i r_i(x) (x_k - x_ik) / l_k^2
//   s^2(x)       = sigma^2 (1 - r^T R^-1 r + (1 - 1^T R^-1 r)^2 / 1^T R^-1 1)   (>= 0; the
//                  mean squared error of the latent function, including the estimation of mu)
// With a small nugget the model interpolates its training points; if R is not numerically
// positive definite with the requested nugget, the fit multiplies the nugget by 10 until it is
// (at most up to 1e-2) and reports the value used in nugget().

#include <cstdint>
#include <limits>
#include <string>

#include <Eigen/Dense>

#include "abuopt/surrogate/surrogate.hpp"

namespace abuopt::surrogate {

struct KrigingOptions {
  // Nugget lambda added to the correlation matrix diagonal (relative to the process variance).
  // 1e-10: interpolation of exact data; use e.g. 1e-3..1e-1 (or estimate_nugget) for noisy data.
  double nugget = 1e-10;
  // Also maximise the likelihood over lambda in [nugget, max_nugget] (log scale).
  bool estimate_nugget = false;
  double max_nugget = 1.0;
  // false: no likelihood maximisation, use initial_length_scales (required then).
  bool optimize = true;
  // Starting length scales in the units of x (size n); empty: 0.5 * span_k.
  Eigen::VectorXd initial_length_scales;
  // Bounds of the length scales as fractions of each variable's span.
  double min_length_scale = 1e-2;  // relative to span_k
  double max_length_scale = 1e1;   // relative to span_k
  // Soft cap on the condition number of R during the likelihood search: beyond it the searched
  // objective is ln L - m (log10(cond / cap))^2 (smooth data otherwise push the length scales
  // until R is numerically singular and predictions lose their digits). cond is the LLT::rcond
  // estimate; the reported log_likelihood() is always the unpenalised ln L.
  double max_condition_number = 1e8;
  int starts = 4;                  // optimiser starting points (>= 1)
  int max_evaluations = 400;       // likelihood evaluations per start (>= 10)
  std::uint64_t seed = 0;          // seed of the extra starting points (std::mt19937_64)
};

// Concentrated log-likelihood ln L of ordinary kriging for given length scales and nugget;
// -infinity if the correlation matrix is not numerically positive definite.
double kriging_log_likelihood(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                              const Eigen::VectorXd& length_scales, double nugget);

class Kriging final : public Surrogate {
 public:
  explicit Kriging(KrigingOptions options = {});

  // Needs m >= 2 points. Throws std::invalid_argument on bad data or options.
  void fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) override;
  double value(const Eigen::VectorXd& x) const override;
  Eigen::VectorXd gradient(const Eigen::VectorXd& x) const override;
  // Predictive variance s^2(x) (see above).
  double variance(const Eigen::VectorXd& x) const;
  std::string name() const override { return "kriging"; }

  const KrigingOptions& options() const { return options_; }
  bool fitted() const { return dimension_ > 0; }
  int dimension() const { return dimension_; }
  const Eigen::VectorXd& length_scales() const { return length_scales_; }
  double mean() const { return mu_; }                   // mu
  double process_variance() const { return sigma2_; }   // sigma^2
  double nugget() const { return nugget_; }             // lambda actually used
  double log_likelihood() const { return log_likelihood_; }
  int likelihood_evaluations() const { return evaluations_; }

 private:
  void check_point(const Eigen::VectorXd& x) const;
  Eigen::VectorXd correlations(const Eigen::VectorXd& x) const;

  KrigingOptions options_;
  int dimension_ = 0;
  Eigen::MatrixXd X_;
  Eigen::VectorXd length_scales_;
  Eigen::VectorXd inverse_squared_scales_;  // 1 / l_k^2
  Eigen::LLT<Eigen::MatrixXd> cholesky_;
  Eigen::VectorXd alpha_;        // R^-1 (y - mu 1)
  Eigen::VectorXd r_inv_ones_;   // R^-1 1
  double ones_r_inv_ones_ = 0.0; // 1^T R^-1 1
  double mu_ = 0.0;
  double sigma2_ = 0.0;
  double nugget_ = 0.0;
  double log_likelihood_ = -std::numeric_limits<double>::infinity();
  int evaluations_ = 0;
};

}  // namespace abuopt::surrogate
