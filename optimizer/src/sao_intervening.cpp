// Intervening variables for SAO's surrogates (see sao_intervening.hpp).
#include "abuopt/optimizer/sao_intervening.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace abuopt::opt {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMinRatio = 1e-12;  // x / c is kept above it (the trust region keeps x >= lower > 0)
// auto: a transformed form must predict the left-out points clearly better than the linear one
// (which the rest of SAO, the correction and the ratio test, handles well): reciprocal when its
// leave-one-out error is below 1/4 of the linear one, fitted exponents (n parameters more, chosen
// on the same points, so their error is optimistic) below 1/50 of the better fixed form. Measured
// on the benchmarks from 5 starts each (docs/sao.md); smaller margins switched forms on noise-level
// differences and cost hs071 evaluations.
constexpr double kReciprocalMargin = 0.25;
constexpr double kExponentialMargin = 0.02;

// The exponents tried for one variable by the exponential form.
const std::vector<double>& exponent_grid() {
  static const std::vector<double> grid = {-3, -2.5, -2, -1.5, -1, -0.5, 0, 0.5, 1, 1.5, 2, 2.5, 3};
  return grid;
}

}  // namespace

bool intervening_allowed(double lower, double upper) {
  return std::isfinite(lower) && std::isfinite(upper) && lower > 0 && upper >= lower;
}

// ---------------------------------------------------------------------------------------------
// InterveningMap

InterveningMap::InterveningMap(Eigen::VectorXd centre, Eigen::VectorXd step, Eigen::VectorXd exponents,
                               const std::vector<bool>& allowed)
    : c_(std::move(centre)), d_(std::move(step)), p_(std::move(exponents)) {
  const Eigen::Index n = p_.size();
  if (c_.size() != n || d_.size() != n || static_cast<Eigen::Index>(allowed.size()) != n)
    throw std::invalid_argument("InterveningMap: centre, step, exponents and allowed must have the same size");
  for (Eigen::Index i = 0; i < n; ++i) {
    const bool ok = allowed[i] && c_[i] > 0 && std::isfinite(c_[i]) && d_[i] > 0 && std::isfinite(d_[i]) &&
                    std::isfinite(p_[i]);
    if (!ok) p_[i] = 1.0;  // refused: the variable stays linear
    if (!(d_[i] > 0) || !std::isfinite(d_[i])) d_[i] = 1.0;
  }
}

InterveningMap InterveningMap::identity(int n) {
  InterveningMap m;
  m.c_ = Eigen::VectorXd::Ones(n);
  m.d_ = Eigen::VectorXd::Ones(n);
  m.p_ = Eigen::VectorXd::Ones(n);
  return m;
}

bool InterveningMap::is_identity() const { return (p_.array() == 1.0).all(); }

double InterveningMap::ratio(int i, double s) const { return std::max(kMinRatio, 1.0 + d_[i] * s / c_[i]); }

Eigen::VectorXd InterveningMap::u(const Eigen::VectorXd& s) const {
  if (s.size() != p_.size())
    throw std::invalid_argument("the intervening map has " + std::to_string(p_.size()) + " variables, s has " +
                                std::to_string(s.size()));
  Eigen::VectorXd out(s.size());
  for (int i = 0; i < s.size(); ++i) {
    const double p = p_[i];
    if (p == 1.0) {
      out[i] = s[i];  // exactly the untransformed coordinate
      continue;
    }
    const double q = ratio(i, s[i]);
    const double scale = c_[i] / d_[i];
    out[i] = p == 0.0 ? scale * std::log(q) : scale * (std::pow(q, p) - 1.0) / p;
  }
  return out;
}

Eigen::VectorXd InterveningMap::du_ds(const Eigen::VectorXd& s) const {
  if (s.size() != p_.size())
    throw std::invalid_argument("the intervening map has " + std::to_string(p_.size()) + " variables, s has " +
                                std::to_string(s.size()));
  Eigen::VectorXd out(s.size());
  for (int i = 0; i < s.size(); ++i) out[i] = p_[i] == 1.0 ? 1.0 : std::pow(ratio(i, s[i]), p_[i] - 1.0);
  return out;
}

// ---------------------------------------------------------------------------------------------
// InterveningSurrogate

InterveningSurrogate::InterveningSurrogate(InterveningMap map, std::unique_ptr<surrogate::Surrogate> inner,
                                           std::string form)
    : map_(std::move(map)), inner_(std::move(inner)), form_(std::move(form)) {
  if (!inner_) throw std::invalid_argument("InterveningSurrogate needs an inner surrogate");
}

Eigen::MatrixXd InterveningSurrogate::map_rows(const Eigen::MatrixXd& S) const {
  if (map_.is_identity()) return S;
  Eigen::MatrixXd U(S.rows(), S.cols());
  for (Eigen::Index r = 0; r < S.rows(); ++r) U.row(r) = map_.u(S.row(r).transpose()).transpose();
  return U;
}

void InterveningSurrogate::fit(const Eigen::MatrixXd& S, const Eigen::VectorXd& y) { inner_->fit(map_rows(S), y); }

void InterveningSurrogate::fit(const Eigen::MatrixXd& S, const Eigen::VectorXd& y, const Eigen::VectorXd& weights) {
  if (auto* rs = dynamic_cast<surrogate::ResponseSurface*>(inner_.get())) rs->fit(map_rows(S), y, weights);
  else inner_->fit(map_rows(S), y);
}

double InterveningSurrogate::value(const Eigen::VectorXd& s) const { return inner_->value(map_.u(s)); }

Eigen::VectorXd InterveningSurrogate::gradient(const Eigen::VectorXd& s) const {
  return inner_->gradient(map_.u(s)).cwiseProduct(map_.du_ds(s));
}

// ---------------------------------------------------------------------------------------------
// Fitting and selection

double weighted_press(const surrogate::ResponseSurface& rs, const Eigen::VectorXd& weights) {
  if (!rs.fitted()) return kInf;
  const surrogate::FitDiagnostics& d = rs.diagnostics();
  if (d.residuals.size() != weights.size() || d.leverages.size() != weights.size()) return kInf;
  double sum = 0, wsum = 0;
  for (Eigen::Index i = 0; i < weights.size(); ++i) {
    if (!(weights[i] > 0)) continue;
    const double one_minus_h = 1.0 - d.leverages[i];
    if (!(one_minus_h > 1e-8)) return kInf;
    const double e = d.residuals[i] / one_minus_h;
    sum += weights[i] * e * e;
    wsum += weights[i];
  }
  if (!(wsum > 0) || !std::isfinite(sum)) return kInf;
  return sum / wsum;
}

namespace {

struct Candidate {
  std::unique_ptr<InterveningSurrogate> model;
  double error = kInf;
};

Candidate fit_candidate(const InterveningData& data, const Eigen::VectorXd& y, const Eigen::VectorXd& p,
                        surrogate::Basis basis, const std::string& form) {
  Candidate c;
  try {
    auto model = std::make_unique<InterveningSurrogate>(InterveningMap(data.centre, data.step, p, data.allowed),
                                                        std::make_unique<surrogate::ResponseSurface>(basis), form);
    model->fit(data.S, y, data.weights);
    c.error = weighted_press(static_cast<const surrogate::ResponseSurface&>(model->inner()), data.weights);
    c.model = std::move(model);
  } catch (const surrogate::InsufficientData&) {
    c.error = kInf;
  }
  return c;
}

double error_of(const InterveningData& data, const Eigen::VectorXd& y, const Eigen::VectorXd& p,
                surrogate::Basis basis) {
  return fit_candidate(data, y, p, basis, "").error;
}

}  // namespace

InterveningChoice fit_intervening(InterveningKind requested, surrogate::Basis basis, const InterveningData& data,
                                  const Eigen::VectorXd& y, const InterveningChoice* previous) {
  const int n = static_cast<int>(data.S.cols());
  const bool any_allowed = std::find(data.allowed.begin(), data.allowed.end(), true) != data.allowed.end();
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(n);
  Eigen::VectorXd reciprocal = ones;
  for (int i = 0; i < n; ++i)
    if (data.allowed[i]) reciprocal[i] = -1.0;

  // the final fit with `basis`; a transformed fit that fails falls back to the linear form
  auto finish = [&](InterveningKind form, const Eigen::VectorXd& p) {
    Candidate c = fit_candidate(data, y, p, basis, to_string(form));
    InterveningChoice out;
    if (!c.model) {
      c = fit_candidate(data, y, ones, basis, "linear");
      if (!c.model) {
        // let the response surface say why (too few points, rank-deficient)
        surrogate::ResponseSurface rs(basis);
        rs.fit(data.S, y, data.weights);
        throw surrogate::InsufficientData("the " + surrogate::to_string(basis) + " surrogate could not be fitted");
      }
      out.form = InterveningKind::Linear;
      out.exponents = ones;
    } else {
      out.form = form;
      out.exponents = c.model->map().exponents();
    }
    out.loo_error = c.error;
    out.model = std::move(c.model);
    return out;
  };

  if (requested == InterveningKind::Linear || !any_allowed) return finish(InterveningKind::Linear, ones);
  if (requested == InterveningKind::Reciprocal) return finish(InterveningKind::Reciprocal, reciprocal);

  // the forms are compared by the leave-one-out error of a LINEAR model in their variables (the
  // form in which the response is most nearly linear): the comparison with the most points to
  // spare, measurable once the zone holds n + 2 points
  const surrogate::Basis selection = surrogate::Basis::kLinear;
  const double e_linear = error_of(data, y, ones, selection);
  const double e_reciprocal = error_of(data, y, reciprocal, selection);
  if (!std::isfinite(e_linear) && !std::isfinite(e_reciprocal)) {
    // nothing to compare with: keep this response's previous choice
    if (previous && previous->exponents.size() == n &&
        (requested == InterveningKind::Auto || previous->form == InterveningKind::Exponential))
      return finish(previous->form, previous->exponents);
    return finish(InterveningKind::Linear, ones);
  }

  double mean = 0, wsum = 0;
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    mean += data.weights[i] * y[i];
    wsum += data.weights[i];
  }
  mean /= wsum;
  double variance = 0;
  for (Eigen::Index i = 0; i < y.size(); ++i) variance += data.weights[i] * (y[i] - mean) * (y[i] - mean);
  variance /= wsum;
  const double tiny = 1e-12 * variance + 1e-300;
  // a < factor * b, by more than round-off
  auto below = [&](double a, double factor, double b) { return a < factor * b - tiny; };

  // exponential: coordinate search over the grid, from the better fixed form
  Eigen::VectorXd p = below(e_reciprocal, 1.0, e_linear) ? reciprocal : ones;
  double e_exponential = std::min(e_linear, e_reciprocal);
  for (int sweep = 0; sweep < 3; ++sweep) {
    bool changed = false;
    for (int i = 0; i < n; ++i) {
      if (!data.allowed[i]) continue;
      for (double q : exponent_grid()) {
        if (q == p[i]) continue;
        Eigen::VectorXd trial = p;
        trial[i] = q;
        const double e = error_of(data, y, trial, selection);
        if (below(e, 1.0, e_exponential)) {
          e_exponential = e;
          p = trial;
          changed = true;
        }
      }
    }
    if (!changed) break;
  }
  if (requested == InterveningKind::Exponential) return finish(InterveningKind::Exponential, p);

  // auto: linear unless a transformed form predicts the left-out points better
  InterveningKind form = InterveningKind::Linear;
  Eigen::VectorXd chosen = ones;
  double best = e_linear;
  if (below(e_reciprocal, kReciprocalMargin, e_linear)) {
    form = InterveningKind::Reciprocal;
    chosen = reciprocal;
    best = e_reciprocal;
  }
  if (below(e_exponential, kExponentialMargin, best)) {
    form = InterveningKind::Exponential;
    chosen = p;
  }
  return finish(form, chosen);
}

}  // namespace abuopt::opt
