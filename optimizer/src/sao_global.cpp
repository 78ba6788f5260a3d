// SAO's global phase (docs/sao.md, "Global phase"; on by default on stochastic problems): a
// maximin Latin hypercube over the whole box, then infill points that maximise the constrained
// expected improvement of kriging models (Schonlau, Welch and Jones 1998: EI times the probability
// of feasibility), and the local trust region starts from the incumbent. Without it a random start
// decides in which basin the trust region ends. Also the restarts: after the trust region
// converges with budget left, n + 1 more infill points and a new trust region at the incumbent.
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
// The kriging models of the infill see at most kModelPointsPerDimension (n + 1) points: the best
// half by merit and a maximin-spread rest (docs/sao.md, "Global phase"). A kriging fit costs
// O(m^3) per likelihood evaluation; without the cap, restarts late in a run of 400 evaluations fit
// 400 points (tens of seconds per infill point). The phase at its automatic size, 8 (n + 1) + 1
// points, stays under it.
constexpr int kModelPointsPerDimension = 10;

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
  const long budget = options_.max_evaluations;
  // 1. the space-filling design over the whole box ([-1,1]^n from doe.hpp mapped to [0,1]^n)
  surrogate::LatinHypercubeOptions lhs;
  lhs.points = gp.design_points(n_, budget);
  lhs.candidates = 20;
  lhs.seed = seed;
  const Eigen::MatrixXd design = surrogate::latin_hypercube(n_, lhs);
  for (int r = 0; r < design.rows(); ++r) {
    const Eigen::VectorXd z = (0.5 * (design.row(r).transpose().array() + 1.0)).matrix();
    if (!evaluate(z)) return false;
  }

  // 2. infill by constrained expected improvement
  if (!global_infill(gp.infill_points(n_, budget))) return false;
  // 3. the trust region starts from the incumbent
  centre_ = incumbent();
  centre_z_ = known_[centre_].z;
  return true;
}

bool SaoRun::global_infill(int count) {
  // one random stream per call (the calls of a run are in a fixed order: results repeat)
  const std::uint64_t seed = options_.seed * 2654435761ULL + 97 + 1000003ULL * infill_calls_++;
  std::mt19937_64 rng(seed + 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double tol = options_.constraint_tolerance;
  for (int it = 0; it < count; ++it) {
    const std::size_t responses = 1 + m_ineq_ + m_eq_;
    // every ok point whose values at the current sample size are known (sao_sampling.cpp)
    std::vector<const KnownPoint*> pts;
    for (const KnownPoint& p : known_) {
      bool usable = p.ok;
      for (std::size_t k = 0; usable && k < responses; ++k) usable = fit_value(p, k).has_value();
      if (usable) pts.push_back(&p);
    }
    const std::size_t cap = static_cast<std::size_t>(kModelPointsPerDimension * (n_ + 1));
    if (pts.size() > cap) {
      // the best half by merit (stable: ties keep the order of evaluation) ...
      std::stable_sort(pts.begin(), pts.end(),
                       [&](const KnownPoint* a, const KnownPoint* b) { return merit(*a) < merit(*b); });
      std::vector<const KnownPoint*> chosen(pts.begin(), pts.begin() + cap / 2);
      std::vector<const KnownPoint*> rest(pts.begin() + cap / 2, pts.end());
      // ... then, one at a time, the remaining point farthest (infinity norm) from the chosen ones
      std::vector<double> gap(rest.size(), kInf);
      for (std::size_t i = 0; i < rest.size(); ++i)
        for (const KnownPoint* c : chosen) gap[i] = std::min(gap[i], (rest[i]->z - c->z).cwiseAbs().maxCoeff());
      while (chosen.size() < cap) {
        std::size_t far = 0;
        for (std::size_t i = 0; i < rest.size(); ++i)
          if (gap[i] > gap[far]) far = i;
        chosen.push_back(rest[far]);
        gap[far] = -1;  // taken
        for (std::size_t i = 0; i < rest.size(); ++i)
          if (gap[i] >= 0) gap[i] = std::min(gap[i], (rest[i]->z - rest[far]->z).cwiseAbs().maxCoeff());
      }
      pts = std::move(chosen);
    }
    const int m = static_cast<int>(pts.size());
    if (m < 2) break;
    Eigen::MatrixXd X(m, n_);
    for (int i = 0; i < m; ++i) X.row(i) = pts[i]->z.transpose();
    Acquisition acq;
    auto value = [&](const KnownPoint& p, std::size_t k) { return *fit_value(p, k); };
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

  return true;
}

std::size_t SaoRun::incumbent() const {
  // the incumbent of the acquisition: the lowest objective among the points that satisfy every
  // inequality (within the constraint tolerance) and every equality within its band (the phase's
  // information on the objective); without one, the point of lowest merit. Only points at the
  // current sample size compete (the ratio test compares the centre with new points at that size).
  const double tol = options_.constraint_tolerance;
  auto current = [&](const KnownPoint& p) { return p.ok && (!sampling_ || p.samples == samples_); };
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
    if (!current(p)) continue;
    bool feasible = true;
    for (std::size_t k = 0; k < m_ineq_; ++k) feasible = feasible && p.g[k] <= tol;
    for (std::size_t j = 0; j < m_eq_; ++j) feasible = feasible && std::fabs(p.h[j]) <= band[j];
    if (feasible && (!start || p.f < known_[*start].f)) start = i;
  }
  if (!start) {
    start = centre_;
    for (std::size_t i = 0; i < known_.size(); ++i)
      if (current(known_[i]) && merit(known_[i]) < merit(known_[*start])) start = i;
  }
  return *start;
}

bool SaoRun::restart_wanted() const {
  return global_ && sao_.global_phase.restart && options_.max_evaluations > 0 &&
         options_.max_evaluations - driver_.evaluations() >= n_ + 2;
}

std::optional<bool> SaoRun::restart() {
  const long before = driver_.evaluations();
  if (!global_infill(n_ + 1)) return std::nullopt;
  if (driver_.evaluations() == before) return false;  // every infill point was known already
  centre_ = incumbent();
  centre_z_ = known_[centre_].z;
  radius_ = sao_.initial_radius;
  return true;
}

}  // namespace abuopt::opt::detail
