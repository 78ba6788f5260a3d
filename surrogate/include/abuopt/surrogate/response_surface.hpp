#pragma once
// Polynomial response surfaces fitted by (weighted) least squares.
//
// Model: f(x) = sum_k beta_k phi_k(x), with the terms phi_k in this order:
//   1, x_1..x_n                          (all bases)
//   x_1^2..x_n^2                         (pure_quadratic, quadratic)
//   x_1 x_2, x_1 x_3, .., x_{n-1} x_n    (interactions, quadratic; i < j, i slowest)
// Number of terms p: linear n+1; interactions 1+n+n(n-1)/2; pure_quadratic 2n+1;
// quadratic (n+1)(n+2)/2.
//
// Fit: beta = argmin sum_i w_i (y_i - phi(x_i)^T beta)^2, solved by a column-pivoting
// Householder QR of W^(1/2) A (never the normal equations), A_ik = phi_k(x_i).
// Diagnostics (e_i = y_i - f(x_i), h_ii the diagonal of the hat matrix
// H = W^(1/2) A (A^T W A)^-1 A^T W^(1/2), obtained from the thin Q factor as h_ii = |Q_i|^2):
//   R^2      = 1 - SS_res / SS_tot, SS_res = sum w_i e_i^2, SS_tot = sum w_i (y_i - ybar_w)^2
//   adj R^2  = 1 - (1 - R^2) (m - 1) / (m - p)                     (NaN when m == p)
//   PRESS    = sum_i (e_i / (1 - h_ii))^2   -- exact leave-one-out residuals for least squares
//   LOO RMS  = sqrt(PRESS / m); residual RMS = sqrt(sum e_i^2 / m)
// A point with h_ii = 1 cannot be predicted without itself (removing it makes the fit
// rank-deficient); PRESS and LOO RMS are then +infinity. With weights, PRESS and the RMS values
// are unweighted sums over the points with w_i > 0.
//
// Work in scaled variables (e.g. [-1,1]^n from doe.hpp) for a well-conditioned design matrix.

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "abuopt/surrogate/surrogate.hpp"

namespace abuopt::surrogate {

enum class Basis {
  kLinear,         // 1, x_i
  kInteractions,   // 1, x_i, x_i x_j
  kPureQuadratic,  // 1, x_i, x_i^2
  kQuadratic,      // 1, x_i, x_i^2, x_i x_j
};

// "linear", "interactions", "pure_quadratic", "quadratic".
std::string to_string(Basis basis);
// Inverse of to_string(); throws std::invalid_argument listing the valid names.
Basis basis_from_string(const std::string& name);
// Human-readable description used in messages: "full quadratic", "linear", ...
std::string describe(Basis basis);

// Number of terms p of `basis` in n variables (n >= 1).
int terms_count(Basis basis, int n);
// The term values phi(x) (size terms_count(basis, x.size())).
Eigen::VectorXd basis_terms(Basis basis, const Eigen::VectorXd& x);
// Names of the terms: "1", "x0", "x0^2", "x0*x1" (0-based variable indices).
std::vector<std::string> term_names(Basis basis, int n);

struct FitDiagnostics {
  int points = 0;   // m: number of points with positive weight
  int terms = 0;    // p
  double r_squared = std::numeric_limits<double>::quiet_NaN();
  double adjusted_r_squared = std::numeric_limits<double>::quiet_NaN();
  double residual_rms = std::numeric_limits<double>::quiet_NaN();  // sqrt(sum e_i^2 / m)
  double press = std::numeric_limits<double>::quiet_NaN();         // sum of squared LOO residuals
  double loo_rms = std::numeric_limits<double>::quiet_NaN();       // sqrt(PRESS / m)
  double max_leverage = std::numeric_limits<double>::quiet_NaN();  // max h_ii
  Eigen::VectorXd residuals;  // e_i (all points, in input order)
  Eigen::VectorXd leverages;  // h_ii (0 for points with zero weight)
};

class ResponseSurface final : public Surrogate {
 public:
  explicit ResponseSurface(Basis basis = Basis::kQuadratic);

  // Unweighted least squares.
  void fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) override;
  // Weighted least squares: weights.size() == X.rows(), every w_i >= 0 and finite. Throws
  // std::invalid_argument if fewer points (with w_i > 0) than terms or the weighted design
  // matrix is rank-deficient ("full quadratic in 3 variables needs at least 10 points, got 7").
  void fit(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, const Eigen::VectorXd& weights);

  double value(const Eigen::VectorXd& x) const override;
  Eigen::VectorXd gradient(const Eigen::VectorXd& x) const override;
  // Hessian of the polynomial (constant for the quadratic bases, zero for linear).
  Eigen::MatrixXd hessian(const Eigen::VectorXd& x) const;
  std::string name() const override { return to_string(basis_); }

  Basis basis() const { return basis_; }
  bool fitted() const { return dimension_ > 0; }
  int dimension() const { return dimension_; }
  int terms() const { return static_cast<int>(coefficients_.size()); }
  // beta in the term order documented above (see term_names()).
  const Eigen::VectorXd& coefficients() const { return coefficients_; }
  const FitDiagnostics& diagnostics() const { return diagnostics_; }

 private:
  void check_point(const Eigen::VectorXd& x) const;

  Basis basis_;
  int dimension_ = 0;
  Eigen::VectorXd coefficients_;
  FitDiagnostics diagnostics_;
};

}  // namespace abuopt::surrogate
