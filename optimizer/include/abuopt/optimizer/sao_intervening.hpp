#pragma once
// Intervening variables for SAO's surrogates (the ADOPT / CONLIN / MMA / TPEA idea): a response
// is fitted as a polynomial in y_i = x_i^p_i instead of in x_i, so that e.g. a deflection
// sum a_i / x_i^3 of sizing variables is linear (p = -3) or nearly so (p = -1), and the
// trust-region step of a linear-objective, curved-constraint problem no longer overshoots.
//
// The transformation (one exponent p_i per variable, Box-Cox form, normalised at the centre):
//   x_i(s) = c_i + d_i s_i            (c: centre, d: r * (upper - lower), s: local coordinates)
//   u_i(s) = c_i / (p_i d_i) * ((x_i / c_i)^p_i - 1)    p_i != 0
//          = c_i / d_i * ln(x_i / c_i)                 p_i == 0
//   du_i/ds_i = (x_i / c_i)^(p_i - 1)
// u is an affine function of x^p (of ln x for p = 0) with u(0) = 0 and du/ds(0) = 1, so the
// polynomial lives in coordinates of the same size as s; p = 1 is exactly u = s (the linear form
// reproduces the untransformed SAO bit for bit), p = -1 is the reciprocal form u = s c / x.
// Only a variable whose lower bound is > 0 can be transformed (x^p and ln x need x > 0; the
// trust region never leaves the bounds): for any other variable p is forced to 1.
//
// Forms: linear (every p = 1), reciprocal (every allowed p = -1), exponential (p_i fitted per
// variable on [-3, 3] by coordinate search over a grid of step 0.5, at most 3 sweeps, minimising
// the weighted leave-one-out error), auto (linear unless a transformed form has a much smaller
// weighted leave-one-out error, see fit_intervening()).
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "abuopt/optimizer/sao_options.hpp"
#include "abuopt/surrogate/response_surface.hpp"
#include "abuopt/surrogate/surrogate.hpp"

namespace abuopt::opt {

// true when variable bounds allow x^p and ln x: lower > 0 (finite).
bool intervening_allowed(double lower, double upper);

// The map s -> u of one response (see the header comment).
class InterveningMap {
 public:
  InterveningMap() = default;
  // centre c (> 0 where allowed), step d (> 0), exponents p; allowed[i] false forces p_i = 1.
  InterveningMap(Eigen::VectorXd centre, Eigen::VectorXd step, Eigen::VectorXd exponents,
                 const std::vector<bool>& allowed);
  // The linear map (u = s) in n variables.
  static InterveningMap identity(int n);

  Eigen::VectorXd u(const Eigen::VectorXd& s) const;
  Eigen::VectorXd du_ds(const Eigen::VectorXd& s) const;  // diagonal of the Jacobian
  const Eigen::VectorXd& exponents() const { return p_; }
  int dimension() const { return static_cast<int>(p_.size()); }
  bool is_identity() const;

 private:
  double ratio(int i, double s) const;  // x_i / c_i, kept > 0
  Eigen::VectorXd c_, d_, p_;
};

// A surrogate of s composed of an inner surrogate of u(s): value(s) = inner(u(s)),
// gradient(s) = inner'(u(s)) .* du/ds (chain rule; the map is diagonal).
class InterveningSurrogate final : public surrogate::Surrogate {
 public:
  InterveningSurrogate(InterveningMap map, std::unique_ptr<surrogate::Surrogate> inner, std::string form);

  void fit(const Eigen::MatrixXd& S, const Eigen::VectorXd& y) override;
  // Weighted least squares when the inner model is a ResponseSurface (else the weights are ignored).
  void fit(const Eigen::MatrixXd& S, const Eigen::VectorXd& y, const Eigen::VectorXd& weights);
  double value(const Eigen::VectorXd& s) const override;
  Eigen::VectorXd gradient(const Eigen::VectorXd& s) const override;
  std::string name() const override { return inner_->name() + "/" + form_; }

  const InterveningMap& map() const { return map_; }
  const std::string& form() const { return form_; }
  const surrogate::Surrogate& inner() const { return *inner_; }
  // Rows mapped to u.
  Eigen::MatrixXd map_rows(const Eigen::MatrixXd& S) const;

 private:
  InterveningMap map_;
  std::unique_ptr<surrogate::Surrogate> inner_;
  std::string form_;
};

// Weighted leave-one-out error of a weighted least-squares response surface:
// sum w_i (e_i / (1 - h_ii))^2 / sum w_i; +infinity when some h_ii ~ 1 (a point that cannot be
// predicted without itself) or the fit failed.
double weighted_press(const surrogate::ResponseSurface& rs, const Eigen::VectorXd& weights);

// Everything a fit of one response needs besides its values.
struct InterveningData {
  Eigen::MatrixXd S;          // points, local coordinates s (rows)
  Eigen::VectorXd weights;    // > 0
  Eigen::VectorXd centre;     // c (original variables)
  Eigen::VectorXd step;       // d = r * (upper - lower)
  std::vector<bool> allowed;  // intervening_allowed() per variable
};

// The chosen form of one response and its fitted model.
struct InterveningChoice {
  InterveningKind form = InterveningKind::Linear;  // Linear, Reciprocal or Exponential (never Auto)
  Eigen::VectorXd exponents;    // p (1 for linear)
  double loo_error = 0;         // weighted_press() of the choice (+inf: not measurable)
  std::unique_ptr<InterveningSurrogate> model;
};

// Fits one response y with polynomial `basis` in the intervening variables of `requested`
// (linear, reciprocal, exponential, auto). Selection (auto) and the exponent search (exponential)
// minimise weighted_press() of a LINEAR model in the candidate's variables (the form in which the
// response is most nearly linear; measurable from n + 2 points on); with fewer points the
// `previous` choice of this response is kept (its form and exponents), else linear. auto prefers
// linear: reciprocal only when its error is below 1/4 of the linear one, exponential only when its
// error is below 1/50 of the better fixed form (it has n fitted exponents more). The final model
// has `basis`. Throws surrogate::InsufficientData when the basis cannot be fitted (too few points,
// rank-deficient).
InterveningChoice fit_intervening(InterveningKind requested, surrogate::Basis basis, const InterveningData& data,
                                  const Eigen::VectorXd& y, const InterveningChoice* previous = nullptr);

}  // namespace abuopt::opt
