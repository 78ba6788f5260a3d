// SAO's optional global phase (docs/sao.md, "Global phase"): a maximin Latin hypercube over the
// whole box, then infill points that maximise the constrained expected improvement of kriging
// models (Schonlau, Welch and Jones 1998: EI times the probability of feasibility), and the local
// trust region starts from the known point of lowest merit. Without it a random start decides in
// which basin the trust region ends.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <random>

#include <nlopt.hpp>

#include "abuopt/surrogate/doe.hpp"
#include "abuopt/surrogate/kriging.hpp"
#include "sao_run.hpp"

namespace abuopt::opt::detail {

namespace {

// An equality h = 0 is relaxed in the global phase to |h| <= t with t = max(constraint tolerance,
// kEqualityBand * the range of h over the known points): the phase looks for the basin, the trust
// region enforces the equality (an exact equality has probability 0 under a kriging model).
constexpr double kEqualityBand = 0.05;
// Floor of EI and of the probability of feasibility before the logarithm (the acquisition is
// maximised as ln EI + sum ln P, which keeps its differences where both underflow).
constexpr double kTiny = 1e-300;

double normal_cdf(double u) { return 0.5 * std::erfc(-u / std::sqrt(2.0)); }
double normal_pdf(double u) { return std::exp(-0.5 * u * u) / std::sqrt(2.0 * std::numbers::pi); }

// Expected improvement below `best` of a normal prediction (mean, sd):
//   EI = (best - mean) Phi(u) + sd phi(u),  u = (best - mean) / sd;  max(0, best - mean) at sd = 0.
double expected_improvement(double mean, double sd, double best) {
  if (!(sd > 0)) return std::max(0.0, best - mean);
  const double u = (best - mean) / sd;
  return (best - mean) * normal_cdf(u) + sd * normal_pdf(u);
}

// P(lo <= Y <= hi) for Y ~ N(mean, sd^2) (a step at sd = 0).
double probability_between(double mean, double sd, double lo, double hi) {
  if (!(sd > 0)) return mean >= lo && mean <= hi ? 1.0 : 0.0;
  const double a = std::isfinite(lo) ? normal_cdf((lo - mean) / sd) : 0.0;
  const double b = std::isfinite(hi) ? normal_cdf((hi - mean) / sd) : 1.0;
  return std::max(0.0, b - a);
}

// The kriging models of every response on the known ok points (unit-box coordinates) and the
// acquisition built from them.
struct Acquisition {
  std::vector<surrogate::Kriging> models;  // objective, inequalities, equalities
  std::vector<double> lo, hi;               // feasible interval of every constraint
  bool has_incumbent = false;
  double best = 0;  // the lowest objective among the feasible points (has_incumbent)

  // ln(EI * P(feasible)); ln P(feasible) alone while no known point is feasible.
  double log_value(const Eigen::VectorXd& z) const {
    double log_p = 0;
    for (std::size_t k = 1; k < models.size(); ++k) {
      const double sd = std::sqrt(models[k].variance(z));
      log_p += std::log(std::max(kTiny, probability_between(models[k].value(z), sd, lo[k - 1], hi[k - 1])));
    }
    if (!has_incumbent) return log_p;
    const double sd = std::sqrt(models[0].variance(z));
    return log_p + std::log(std::max(kTiny, expected_improvement(models[0].value(z), sd, best)));
  }
};

}  // namespace

bool SaoRun::global_phase() {
  const SaoGlobalPhase& gp = sao_.global_phase;
  const std::uint64_t seed = options_.seed * 2654435761ULL + 97;
  // 1. the space-filling design over the whole box ([-1,1]^n from doe.hpp mapped to [0,1]^n)
  surrogate::LatinHypercubeOptions lhs;
  lhs.points = gp.points;
  lhs.candidates = 20;
  lhs.seed = seed;
  const Eigen::MatrixXd design = surrogate::latin_hypercube(n_, lhs);
  for (int r = 0; r < design.rows(); ++r) {
    const Eigen::VectorXd z = (0.5 * (design.row(r).transpose().array() + 1.0)).matrix();
    if (!evaluate(z)) return false;
  }

  // 2. infill by constrained expected improvement
  std::mt19937_64 rng(seed + 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double tol = options_.constraint_tolerance;
  for (int it = 0; it < gp.iterations; ++it) {
    std::vector<const KnownPoint*> pts;
    for (const KnownPoint& p : known_)
      if (p.ok) pts.push_back(&p);
    const int m = static_cast<int>(pts.size());
    if (m < 2) break;
    Eigen::MatrixXd X(m, n_);
    for (int i = 0; i < m; ++i) X.row(i) = pts[i]->z.transpose();
    Acquisition acq;
    const std::size_t responses = 1 + m_ineq_ + m_eq_;
    auto value = [&](const KnownPoint& p, std::size_t k) {
      return k == 0 ? p.f : k <= m_ineq_ ? p.g[k - 1] : p.h[k - 1 - m_ineq_];
    };
    try {
      for (std::size_t k = 0; k < responses; ++k) {
        Eigen::VectorXd y(m);
        for (int i = 0; i < m; ++i) y[i] = value(*pts[i], k);
        surrogate::KrigingOptions ko;
        ko.nugget = 1e-8;
        ko.estimate_nugget = true;  // noise: the likelihood chooses the nugget (smooth data: ~0)
        ko.max_nugget = 0.1;
        ko.starts = 2;
        ko.max_evaluations = 200;
        ko.seed = seed + static_cast<std::uint64_t>(it);
        acq.models.emplace_back(ko);
        acq.models.back().fit(X, y);
        if (k == 0) continue;
        if (k <= m_ineq_) {
          acq.lo.push_back(-kInf);
          acq.hi.push_back(tol);
        } else {
          const double band = std::max(tol, kEqualityBand * (y.maxCoeff() - y.minCoeff()));
          acq.lo.push_back(-band);
          acq.hi.push_back(band);
        }
      }
    } catch (const std::invalid_argument&) {
      break;  // no model (e.g. a degenerate design): the trust region takes over
    }
    for (const KnownPoint* p : pts) {
      bool feasible = true;
      for (std::size_t k = 1; k < responses; ++k) {
        const double v = value(*p, k);
        feasible = feasible && v >= acq.lo[k - 1] && v <= acq.hi[k - 1];
      }
      if (feasible && (!acq.has_incumbent || p->f < acq.best)) {
        acq.has_incumbent = true;
        acq.best = p->f;
      }
    }

    // maximise: random candidates, then COBYLA from the best three
    auto distance_to_known = [&](const Eigen::VectorXd& z) {
      double d = kInf;
      for (const KnownPoint& p : known_) d = std::min(d, (z - p.z).cwiseAbs().maxCoeff());
      return d;
    };
    const int candidates = 500 + 200 * n_;
    std::vector<std::pair<double, Eigen::VectorXd>> ranked;
    ranked.reserve(candidates);
    for (int c = 0; c < candidates; ++c) {
      Eigen::VectorXd z(n_);
      for (int i = 0; i < n_; ++i) z[i] = unit(rng);
      ranked.emplace_back(acq.log_value(z), z);
    }
    std::sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    Eigen::VectorXd chosen = ranked.front().second;
    double chosen_value = -kInf;
    for (std::size_t c = 0; c < std::min<std::size_t>(3, ranked.size()); ++c) {
      nlopt::opt local(nlopt::LN_COBYLA, static_cast<unsigned>(n_));
      local.set_lower_bounds(std::vector<double>(n_, 0.0));
      local.set_upper_bounds(std::vector<double>(n_, 1.0));
      local.set_maxeval(100 * n_);
      local.set_xtol_rel(1e-6);
      local.set_initial_step(0.02);
      auto objective = [](const std::vector<double>& x, std::vector<double>&, void* data) {
        const Acquisition& a = *static_cast<const Acquisition*>(data);
        const double v = a.log_value(Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size())));
        return std::isfinite(v) ? -v : 1e300;
      };
      local.set_min_objective(+objective, &acq);
      std::vector<double> x(ranked[c].second.data(), ranked[c].second.data() + n_);
      double f = 0;
      try {
        local.optimize(x, f);
      } catch (const std::exception&) {
        x.assign(ranked[c].second.data(), ranked[c].second.data() + n_);
      }
      Eigen::VectorXd z = Eigen::Map<Eigen::VectorXd>(x.data(), n_).cwiseMax(0.0).cwiseMin(1.0);
      double v = acq.log_value(z);
      if (distance_to_known(z) < 1e-4) {  // a known point teaches nothing: the raw candidate
        z = ranked[c].second;
        v = ranked[c].first;
      }
      if (v > chosen_value && distance_to_known(z) >= 1e-4) {
        chosen_value = v;
        chosen = z;
      }
    }
    if (!evaluate(chosen)) return false;
  }

  // 3. the trust region starts from the incumbent of the acquisition: the lowest objective among
  // the points that satisfy every inequality (within the constraint tolerance) and every equality
  // within its band (the phase's information on the objective); without one, from the point of
  // lowest merit
  std::vector<double> band(m_eq_, tol);
  for (std::size_t j = 0; j < m_eq_; ++j) {
    double lo = kInf, hi = -kInf;
    for (const KnownPoint& p : known_)
      if (p.ok) {
        lo = std::min(lo, p.h[j]);
        hi = std::max(hi, p.h[j]);
      }
    if (hi >= lo) band[j] = std::max(tol, kEqualityBand * (hi - lo));
  }
  std::optional<std::size_t> start;
  for (std::size_t i = 0; i < known_.size(); ++i) {
    const KnownPoint& p = known_[i];
    if (!p.ok) continue;
    bool feasible = true;
    for (std::size_t k = 0; k < m_ineq_; ++k) feasible = feasible && p.g[k] <= tol;
    for (std::size_t j = 0; j < m_eq_; ++j) feasible = feasible && std::fabs(p.h[j]) <= band[j];
    if (feasible && (!start || p.f < known_[*start].f)) start = i;
  }
  if (!start) {
    start = centre_;
    for (std::size_t i = 0; i < known_.size(); ++i)
      if (merit(known_[i]) < merit(known_[*start])) start = i;
  }
  centre_ = *start;
  centre_z_ = known_[centre_].z;
  return true;
}

}  // namespace abuopt::opt::detail
