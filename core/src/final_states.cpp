#include "abuopt/core/final_states.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/abu_model.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"

namespace abuopt {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kZ95 = 1.959963984540054;

void check_angles(const AbuParameters& p, const std::vector<double>& beta, const char* who) {
  if (beta.size() != p.balls.size())
    throw std::invalid_argument(std::string(who) + ": " + std::to_string(beta.size()) + " angles given for " +
                                std::to_string(p.balls.size()) + " balls");
}

double mass_length(const AbuParameters& p) { return p.total_mass_kg() * p.ball_track_radius_m; }

double bbar_of(const AbuParameters& p) { return NondimParameters::from(p).bbar; }

// The speed ratio W of the largest |G| (resonance of the damped table), and that |G|.
std::pair<double, double> gain_peak(const AbuParameters& p) {
  const double b = bbar_of(p);
  if (2 * b * b >= 1) return {kInf, 1.0};  // |G| grows towards 1 as W -> infinity
  return {1.0 / std::sqrt(1 - 2 * b * b), 1.0 / (2 * b * std::sqrt(1 - b * b))};
}

// The speed [Hz] on the falling (below = true: rising) side of |G| where |G| = target, by bisection.
double gain_level_hz(const AbuParameters& p, double target, bool below) {
  const double w_peak = gain_peak(p).first;
  if (!std::isfinite(w_peak)) return below ? 0.0 : kInf;
  const double f_peak = w_peak * p.natural_frequency_hz();
  double lo = below ? 0.0 : f_peak, hi = f_peak;
  if (!below) {
    hi = 2 * f_peak;
    while (std::abs(steady_gain(p, hi)) > target && hi < 1e12) hi *= 2;
    if (std::abs(steady_gain(p, hi)) > target) return kInf;  // |G| stays above target (heavy damping)
  }
  for (int k = 0; k < 200 && hi - lo > 1e-12 * hi; ++k) {
    const double mid = 0.5 * (lo + hi);
    const bool above_target = std::abs(steady_gain(p, mid)) > target;
    if (below == above_target)
      hi = mid;
    else
      lo = mid;
  }
  return 0.5 * (lo + hi);
}

std::vector<double> sorted(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v;
}

double mean_of(const std::vector<double>& v) {
  if (v.empty()) return kNaN;
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

Interval mean_interval(const std::vector<double>& v) {
  if (v.size() < 2) return {kNaN, kNaN};
  const double m = mean_of(v);
  double ss = 0;
  for (double x : v) ss += (x - m) * (x - m);
  const double h = kZ95 * std::sqrt(ss / static_cast<double>(v.size() - 1)) / std::sqrt(static_cast<double>(v.size()));
  return {m - h, m + h};
}

// Ranks floor(n/2 - z sqrt(n)/2) .. ceil(n/2 + z sqrt(n)/2) of the sorted sample.
Interval median_interval(const std::vector<double>& s) {
  const double n = static_cast<double>(s.size());
  if (s.size() < 2) return {kNaN, kNaN};
  const auto lo = static_cast<long>(std::floor(n / 2 - kZ95 * std::sqrt(n) / 2));
  const auto hi = static_cast<long>(std::ceil(n / 2 + kZ95 * std::sqrt(n) / 2));
  return {s[static_cast<std::size_t>(std::max(0L, lo))],
          s[static_cast<std::size_t>(std::min(static_cast<long>(s.size()) - 1, hi))]};
}

FinalStateGroup group_of(const std::vector<const FinalStateRecord*>& g, std::size_t total) {
  FinalStateGroup out;
  out.count = g.size();
  out.share = total ? static_cast<double>(g.size()) / static_cast<double>(total) : kNaN;
  const auto w = wilson_interval(g.size(), total);
  out.share_ci = {w.first, w.second};
  std::vector<double> depth, lock, settle_g, hz;
  std::size_t held = 0, locked = 0;
  for (const auto* r : g) {
    depth.push_back(r->depth);
    lock.push_back(r->lock_gauge);
    settle_g.push_back(r->gauge_settle);
    hz.push_back(r->settle_hz);
    held += r->floor_depth > 0 ? 1 : 0;
    locked += r->lock_gauge <= 1 ? 1 : 0;
  }
  out.depth_mean = mean_of(depth);
  out.depth_mean_ci = mean_interval(depth);
  const auto ds = sorted(depth), hs = sorted(hz);
  out.depth_median = ds.empty() ? kNaN : quantile_type7(ds, 0.5);
  out.depth_median_ci = median_interval(ds);
  out.lock_gauge_mean = mean_of(lock);
  out.gauge_settle_mean = mean_of(settle_g);
  out.settle_hz_p10 = hs.empty() ? kNaN : quantile_type7(hs, 0.1);
  out.settle_hz_median = hs.empty() ? kNaN : quantile_type7(hs, 0.5);
  out.settle_hz_p90 = hs.empty() ? kNaN : quantile_type7(hs, 0.9);
  out.held_share = g.empty() ? kNaN : static_cast<double>(held) / static_cast<double>(g.size());
  out.locked_share = g.empty() ? kNaN : static_cast<double>(locked) / static_cast<double>(g.size());
  return out;
}

}  // namespace

std::complex<double> residual_complex_kgm(const AbuParameters& p, const std::vector<double>& beta) {
  check_angles(p, beta, "residual_complex_kgm");
  std::complex<double> u(p.imbalance_kgm(), 0);
  for (std::size_t i = 0; i < beta.size(); ++i) u += p.balls[i].mass_kg * p.ball_track_radius_m * std::polar(1.0, beta[i]);
  return u;
}

std::complex<double> steady_gain(const AbuParameters& p, double frequency_hz) {
  const double w = frequency_hz / p.natural_frequency_hz();
  return w * w / std::complex<double>(1 - w * w, 2 * bbar_of(p) * w);
}

double inscribed_radius_kgm(const AbuParameters& p, double frequency_hz) {
  const double mu = p.friction_mu;
  return mass_length(p) * mu / ((1 + mu) * std::abs(steady_gain(p, frequency_hz)));
}

double lock_radius_kgm(const AbuParameters& p) {
  const double mu = p.friction_mu;
  return mass_length(p) * mu / ((1 + mu) * gain_peak(p).second);
}

double equilibrium_gauge(const AbuParameters& p, double frequency_hz, const std::vector<double>& beta) {
  const std::complex<double> z = steady_gain(p, frequency_hz) * residual_complex_kgm(p, beta) / mass_length(p);
  const double mu = p.friction_mu;
  double g = 0;
  for (double b : beta) {
    const std::complex<double> w = z * std::polar(1.0, -b);
    const double cone = mu * (1 + w.real()), need = std::abs(w.imag());
    if (1 + w.real() <= 0) return kInf;  // the ball lifts off the track: never stuck
    g = std::max(g, need == 0 ? 0.0 : (cone > 0 ? need / cone : kInf));
  }
  return g;
}

std::pair<double, double> lock_band_hz(const AbuParameters& p) {
  const double target = gain_peak(p).second / kLockBandRatio;
  return {gain_level_hz(p, target, true), gain_level_hz(p, target, false)};
}

double lock_gauge(const AbuParameters& p, const std::vector<double>& beta) {
  const auto [from, to] = lock_band_hz(p);
  const double hi = std::isfinite(to) ? to : 100 * p.natural_frequency_hz();
  const double lo = std::max(from, 1e-9 * hi);
  double g = 0;
  for (std::size_t k = 0; k < kLockBandSamples; ++k) {
    const double f = lo + (hi - lo) * static_cast<double>(k) / static_cast<double>(kLockBandSamples - 1);
    g = std::max(g, equilibrium_gauge(p, f, beta));
  }
  // the resonance itself, which the samples may straddle
  const double w_peak = gain_peak(p).first;
  if (std::isfinite(w_peak)) g = std::max(g, equilibrium_gauge(p, w_peak * p.natural_frequency_hz(), beta));
  return g;
}

double band_edge_hz(const AbuParameters& p, double ratio) {
  if (!(ratio > 1)) throw std::invalid_argument("band_edge_hz: ratio must be > 1");
  return gain_level_hz(p, gain_peak(p).second / ratio, true);
}

std::vector<std::vector<std::size_t>> ball_clusters(const AbuParameters& p, const std::vector<double>& beta,
                                                    double tol_rad) {
  check_angles(p, beta, "ball_clusters");
  const std::size_t n = beta.size();
  auto wrap = [](double a) {
    a = std::fmod(a, kTwoPi);
    return a < 0 ? a + kTwoPi : a;
  };
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return wrap(beta[a]) < wrap(beta[b]); });
  if (n <= 1) return {order};
  const double L = p.ball_track_radius_m;
  std::vector<char> close(n);  // close[k]: order[k] and order[k + 1] (cyclically) touch or nearly
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = order[k], j = order[(k + 1) % n];
    const double gap = wrap(beta[j] - beta[i]);
    const double contact = 2 * std::asin(std::min(1.0, (p.balls[i].diameter_m + p.balls[j].diameter_m) / (4 * L)));
    close[k] = std::abs(gap - contact) <= tol_rad;
  }
  const auto open = std::find(close.begin(), close.end(), char(0));
  if (open == close.end()) return {order};
  const std::size_t start = static_cast<std::size_t>(open - close.begin()) + 1;  // a chain starts after an open link
  std::vector<std::vector<std::size_t>> out;
  std::vector<std::size_t> cur;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t q = (start + k) % n;
    cur.push_back(order[q]);
    if (!close[q]) {
      out.push_back(cur);
      cur.clear();
    }
  }
  return out;
}

double cluster_floor_kgm(const AbuParameters& p, const std::vector<double>& beta, double tol_rad) {
  std::vector<double> a{p.imbalance_kgm()};
  for (const auto& c : ball_clusters(p, beta, tol_rad)) {
    std::complex<double> v;
    for (std::size_t i : c) v += p.balls[i].mass_kg * p.ball_track_radius_m * std::polar(1.0, beta[i]);
    a.push_back(std::abs(v));
  }
  const double longest = *std::max_element(a.begin(), a.end());
  return std::max(0.0, 2 * longest - std::accumulate(a.begin(), a.end(), 0.0));
}

LockSetStatistics lock_set_statistics(const AbuParameters& p, std::size_t n, const std::vector<double>& other_beta,
                                      double alpha_rad_s2) {
  if (p.balls.size() < 2 || other_beta.size() != p.balls.size() - 2 || n == 0)
    throw std::invalid_argument("lock_set_statistics: needs >= 2 balls, the angles of balls 3..N and n > 0");
  LockSetStatistics out;
  out.grid = n;
  const double omega_n = 2 * M_PI * p.natural_frequency_hz();
  out.reach = alpha_rad_s2 > 0 ? alpha_rad_s2 / (p.friction_mu * omega_n * omega_n) : 0.0;
  const double rl = lock_radius_kgm(p);
  std::vector<double> beta(p.balls.size());
  std::copy(other_beta.begin(), other_beta.end(), beta.begin() + 2);
  std::size_t locked = 0, unreached = 0;
  double depth = 0, gauge = 0, depth_unreached = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      beta[0] = kTwoPi * (static_cast<double>(i) + 0.5) / static_cast<double>(n);
      beta[1] = kTwoPi * (static_cast<double>(j) + 0.5) / static_cast<double>(n);
      const double g = lock_gauge(p, beta);
      if (!(g <= 1)) continue;
      const double d = std::abs(residual_complex_kgm(p, beta)) / rl;
      ++locked;
      depth += d;
      gauge += g;
      if (g <= 1 - out.reach) {
        ++unreached;
        depth_unreached += d;
      }
    }
  const double total = static_cast<double>(n) * static_cast<double>(n);
  out.share = static_cast<double>(locked) / total;
  out.depth_mean = locked ? depth / static_cast<double>(locked) : kNaN;
  out.lock_gauge_mean = locked ? gauge / static_cast<double>(locked) : kNaN;
  out.unreached_share = static_cast<double>(unreached) / total;
  out.unreached_depth_mean = unreached ? depth_unreached / static_cast<double>(unreached) : kNaN;
  return out;
}

std::optional<double> first_passage_s(const StartupProfile& profile, double level_hz) {
  double f0 = profile.start_frequency_hz();
  if (f0 >= level_hz) return 0.0;
  const auto& segs = profile.segments();
  const auto& breaks = profile.breakpoints_s();
  for (std::size_t k = 0; k < segs.size(); ++k) {
    const double f1 = segs[k].end_frequency_hz;
    if (f1 == level_hz) return breaks[k + 1];
    if (f0 < level_hz && level_hz < f1) return profile.crossing_time_s(k, level_hz);
    f0 = f1;
  }
  return std::nullopt;
}

FinalStateAnalysis analyse_final_states(const AbuParameters& nominal, const StartupProfile& profile,
                                        const std::vector<FinalStateInput>& runs, EarlySplit split,
                                        std::optional<double> edge_hz) {
  FinalStateAnalysis out;
  out.split = split;
  out.r_lock_kgm = lock_radius_kgm(nominal);
  out.edge_hz = edge_hz ? *edge_hz : band_edge_hz(nominal);
  if (split == EarlySplit::passage) out.edge_time_s = first_passage_s(profile, out.edge_hz);
  for (const auto& r : runs) {
    if (r.beta_final.size() != nominal.balls.size())
      throw ConfigError("runs", "run " + std::to_string(r.index) + ": " + std::to_string(r.beta_final.size()) + " angles",
                        "must give one final angle per ball of the config (" + std::to_string(nominal.balls.size()) + ")");
    if (!r.settled) {
      ++out.not_settled;
      continue;
    }
    AbuParameters p = nominal;
    if (r.friction_mu) p.friction_mu = *r.friction_mu;
    if (r.imbalance_mass_kg) p.imbalance_mass_kg = *r.imbalance_mass_kg;
    if (r.stiffness_N_per_m) p.stiffness_N_per_m = *r.stiffness_N_per_m;
    FinalStateRecord rec;
    rec.index = r.index;
    rec.settling_time_s = r.settling_time_s;
    rec.settle_hz = profile.frequency_hz(r.settling_time_s);
    rec.r_lock_kgm = lock_radius_kgm(p);
    rec.depth = std::abs(residual_complex_kgm(p, r.beta_final)) / rec.r_lock_kgm;
    rec.gauge_settle = equilibrium_gauge(p, rec.settle_hz, r.beta_final);
    rec.lock_gauge = lock_gauge(p, r.beta_final);
    rec.floor_depth = cluster_floor_kgm(p, r.beta_final) / rec.r_lock_kgm;
    for (const auto& c : ball_clusters(p, r.beta_final)) rec.largest_cluster = std::max(rec.largest_cluster, c.size());
    if (split == EarlySplit::passage) {
      const std::optional<double> t_edge = edge_hz ? out.edge_time_s : first_passage_s(profile, band_edge_hz(p));
      rec.early = !t_edge || r.settling_time_s < *t_edge;
    } else {
      rec.early = rec.settle_hz < p.natural_frequency_hz() &&
                  inscribed_radius_kgm(p, rec.settle_hz) > kEarlyEdgeRatio * rec.r_lock_kgm;
    }
    out.records.push_back(rec);
  }
  out.settled = out.records.size();
  std::vector<const FinalStateRecord*> early, late;
  std::vector<double> depth;
  for (const auto& rec : out.records) {
    (rec.early ? early : late).push_back(&rec);
    depth.push_back(rec.depth);
  }
  out.early = group_of(early, out.settled);
  out.late = group_of(late, out.settled);
  out.depth_mean = mean_of(depth);
  out.depth_mean_ci = mean_interval(depth);
  return out;
}

}  // namespace abuopt
