// SAO: the surrogates of one iteration (see sao.hpp, step 3): weighted least squares on the fit
// zone in each response's intervening variables, or kriging; the zeroth-order correction; the
// residual noise probe of every response (sao_noise.hpp).
#include <cmath>
#include <functional>

#include "abuopt/surrogate/kriging.hpp"
#include "abuopt/surrogate/response_surface.hpp"
#include "sao_run.hpp"

namespace abuopt::opt::detail {

std::unique_ptr<surrogate::Surrogate> SaoRun::make_model(SurrogateKind basis) const {
  if (basis == SurrogateKind::Kriging) {
    surrogate::KrigingOptions k;
    k.nugget = sao_.kriging_nugget;
    if (noisy_) {  // noise detected: the likelihood chooses the nugget, kriging_nugget its floor
      k.estimate_nugget = true;
      k.max_nugget = std::max(1.0, 10 * sao_.kriging_nugget);
    }
    k.starts = 2;
    k.max_evaluations = 200;
    return surrogate::make_surrogate("kriging", &k);
  }
  return surrogate::make_surrogate(to_string(basis));
}

// Surrogates of every response on the fit zone: the richest basis of the order the points
// determine; nullopt when none can be fitted (too few ok points).
std::optional<Models> SaoRun::fit(SurrogateKind requested) {
  std::vector<Eigen::VectorXd> s;
  std::vector<double> w;
  std::vector<const KnownPoint*> pts;
  for (const KnownPoint& p : known_) {
    if (!p.fits()) continue;
    if (sampling_ && !fit_value(p, 0)) continue;  // a sample size the run cannot shift
    const Eigen::VectorXd sp = to_s(p.z);
    const double d = sp.cwiseAbs().maxCoeff();
    if (d > sao_.neighbourhood * (1 + 1e-9)) continue;
    s.push_back(sp);
    w.push_back((d <= 1 + 1e-9 ? 1.0 : 1.0 / std::pow(d, 4)) * sample_weight(p));
    pts.push_back(&p);
  }
  const int m = static_cast<int>(s.size());
  if (m < 2) return std::nullopt;
  InterveningData data;
  data.S.resize(m, n_);
  data.weights.resize(m);
  for (int i = 0; i < m; ++i) {
    data.S.row(i) = s[i].transpose();
    data.weights[i] = w[i];
  }
  // the original variables of the centre and the trust region's half-width in them
  data.centre.resize(n_);
  data.step.resize(n_);
  data.allowed.resize(n_);
  for (int i = 0; i < n_; ++i) {
    const Variable& v = variables_[i];
    data.centre[i] = v.lower + centre_z_[i] * (v.upper - v.lower);
    data.step[i] = radius_ * (v.upper - v.lower);
    data.allowed[i] = intervening_allowed(v.lower, v.upper);
  }
  const std::size_t responses = 1 + m_ineq_ + m_eq_;
  last_choice_.resize(responses);
  auto form_of = [&](std::size_t k) {
    const std::optional<InterveningKind>& specific =
        k == 0 ? sao_.intervening_objective : sao_.intervening_constraints;
    return specific.value_or(sao_.intervening);
  };

  using K = SurrogateKind;
  std::vector<SurrogateKind> order;
  if (requested == K::Auto) order = {K::Quadratic, K::PureQuadratic, K::Linear};
  else if (requested == K::Kriging) order = {K::Kriging, K::Linear};
  else order = {requested, K::Linear};
  for (const SurrogateKind basis : order) {
    const bool kriging = basis == K::Kriging;
    if (!kriging && surrogate::terms_count(surrogate::basis_from_string(to_string(basis)), n_) > m) continue;
    try {
      Models models;
      models.basis = to_string(basis);
      std::vector<InterveningChoice> choices(responses);
      std::vector<double> noise(responses, 0.0), noise_fraction(responses, 0.0);
      auto fit_one = [&](std::size_t k, const std::function<double(const KnownPoint&)>& value) {
        Eigen::VectorXd y(m);
        for (int i = 0; i < m; ++i) y[i] = sampling_ ? *fit_value(*pts[i], k) : value(*pts[i]);
        if (kriging) {
          // kriging interpolates: region points and neighbours alike; intervening variables only
          // when asked for explicitly (no leave-one-out error to choose them by)
          const bool reciprocal = form_of(k) == InterveningKind::Reciprocal;
          Eigen::VectorXd p = Eigen::VectorXd::Constant(n_, reciprocal ? -1.0 : 1.0);
          auto model = std::make_unique<InterveningSurrogate>(
              reciprocal ? InterveningMap(data.centre, data.step, p, data.allowed) : InterveningMap::identity(n_),
              make_model(basis), reciprocal ? "reciprocal" : "linear");
          model->fit(data.S, y);
          choices[k].form = reciprocal ? InterveningKind::Reciprocal : InterveningKind::Linear;
          choices[k].exponents = model->map().exponents();
          return std::unique_ptr<surrogate::Surrogate>(std::move(model));
        }
        const InterveningChoice* previous = last_choice_[k].exponents.size() == n_ ? &last_choice_[k] : nullptr;
        const surrogate::Basis rs_basis = surrogate::basis_from_string(to_string(basis));
        InterveningChoice c = fit_intervening(form_of(k), rs_basis, data, y, previous);
        // the noise probe: the residuals of this fit (none when it interpolates, m <= p)
        const int p = surrogate::terms_count(rs_basis, n_);
        if (m > p) {
          const ResidualNoise r = residual_noise(y, c.model->values(data.S), w, p);
          noise[k] = r.sigma;
          noise_fraction[k] = r.fraction;
        }
        choices[k].form = c.form;
        choices[k].exponents = c.exponents;
        choices[k].loo_error = c.loo_error;
        return std::unique_ptr<surrogate::Surrogate>(std::move(c.model));
      };
      models.fm = fit_one(0, [](const KnownPoint& p) { return p.f; });
      for (std::size_t i = 0; i < m_ineq_; ++i)
        models.gm.push_back(fit_one(1 + i, [i](const KnownPoint& p) { return p.g[i]; }));
      for (std::size_t j = 0; j < m_eq_; ++j)
        models.hm.push_back(fit_one(1 + m_ineq_ + j, [j](const KnownPoint& p) { return p.h[j]; }));
      models.g_offset.assign(m_ineq_, 0.0);
      models.h_offset.assign(m_eq_, 0.0);
      const KnownPoint& c = known_[centre_];
      if (sao_.correction && c.ok) {
        const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n_);
        models.f_offset = c.f - models.fm->value(zero);
        for (std::size_t i = 0; i < m_ineq_; ++i) models.g_offset[i] = c.g[i] - models.gm[i]->value(zero);
        for (std::size_t j = 0; j < m_eq_; ++j) models.h_offset[j] = c.h[j] - models.hm[j]->value(zero);
      }
      models.noise = std::move(noise);
      models.noise_fraction = std::move(noise_fraction);
      for (std::size_t k = 0; k < responses; ++k) {
        models.forms += (k == 0 ? "f:" : k <= m_ineq_ ? " g:" : " h:") + to_string(choices[k].form).substr(0, 1);
        last_choice_[k] = std::move(choices[k]);
      }
      return models;
    } catch (const surrogate::InsufficientData&) {
      continue;  // rank-deficient or too few points: a simpler basis
    }
  }
  return std::nullopt;
}

}  // namespace abuopt::opt::detail
