// SAO: noise detected from the data (docs/sao.md, "Noise detected from the data"). A replicate-free
// probe: with common random numbers (or any deterministic noise) evaluating a point again gives
// the same value, so the noise is read from second differences on a short segment instead.
// Also the stop on noise that uses the level found (docs/sao.md, "Stop when the rest is noise").
#include <algorithm>
#include <cmath>
#include <random>

#include "sao_run.hpp"

namespace abuopt::opt::detail {

namespace {

// The probe's longer step as a fraction of the radius (d = 0.1 r; the shorter one is d / 4).
constexpr double kProbeStep = 0.1;
// Noise counts when kProbeRatio times the merit's noise level reaches the predicted reduction.
constexpr double kProbeRatio = 20.0;
// A noise level below this fraction of max(1, |y|) is rounding error of a smooth response.
constexpr double kRounding = 1e-9;

}  // namespace

// Second differences D(d) = y(c + 2 d v) - 2 y(c + d v) + y(c) of every response, at d = 0.1 r
// and at d / 4 (four evaluations; v a seeded sign vector kept inside the box). On a smooth response
// D(d) = y''_v d^2 + O(d^3): at most 1/100 of the curvature term over the region, and D(d / 4) is
// 1/16 of D(d). On a response with independent noise of standard deviation sigma,
// Var D = (1 + 4 + 1) sigma^2 at both steps: |D| / sqrt(6) estimates sigma, and the two are alike
// (|D(d/4)| >= |D(d)| / 4 with probability 1 - (2/pi) atan(1/4) = 0.84). A response is noisy at
// this scale when |D(d/4)| >= |D(d)| / 4; its noise level is then (|D(d)| + |D(d/4)|) / (2 sqrt 6),
// else 0. The merit's noise is combined from them as the ratio test does (merit_noise); noise is
// declared when kProbeRatio * sigma_merit >= the predicted reduction that failed.
std::optional<bool> SaoRun::probe_noise(double predicted, bool phase1) {
  const KnownPoint c = known_[centre_];  // a copy: evaluate() may grow known_
  if (!c.ok) return false;
  last_probe_radius_ = radius_;
  std::mt19937_64 rng(options_.seed * 6364136223846793005ULL + static_cast<std::uint64_t>(iterations));
  const double d = kProbeStep * radius_;
  Eigen::VectorXd v(n_);
  for (int i = 0; i < n_; ++i) {
    v[i] = (rng() & 1U) ? 1.0 : -1.0;
    if (c.z[i] + 2 * d * v[i] > 1.0 || c.z[i] + 2 * d * v[i] < 0.0) v[i] = -v[i];  // stay in the box
  }
  std::vector<KnownPoint> probe;  // at d/4, d/2, d, 2d
  std::vector<std::size_t> added;  // the probe's new points
  auto smooth = [&] {              // no noise: the probe's points leave the fits
    for (const std::size_t i : added) known_[i].probe_only = true;
    return false;
  };
  for (const double t : {0.25, 0.5, 1.0, 2.0}) {
    const std::size_t before = known_.size();
    const auto idx = evaluate((c.z + t * d * v).cwiseMax(0.0).cwiseMin(1.0));
    if (!idx) return std::nullopt;
    if (known_.size() > before) added.push_back(*idx);
    if (!known_[*idx].ok) return smooth();
    probe.push_back(known_[*idx]);
  }
  const std::size_t responses = 1 + m_ineq_ + m_eq_;
  std::vector<double> noise(responses, 0.0);
  auto value = [&](const KnownPoint& p, std::size_t k) {
    return k == 0 ? p.f : k <= m_ineq_ ? p.g[k - 1] : p.h[k - 1 - m_ineq_];
  };
  for (std::size_t k = 0; k < responses; ++k) {
    const double y0 = value(c, k);
    const double small = std::fabs(value(probe[1], k) - 2 * value(probe[0], k) + y0);
    const double large = std::fabs(value(probe[3], k) - 2 * value(probe[2], k) + y0);
    const double level = (small + large) / (2 * std::sqrt(6.0));
    // rounding, not noise: a response linear along v has D ~ 1e-16 |y| at both steps
    const bool above_rounding = level > kRounding * std::max(1.0, std::fabs(y0));
    if (above_rounding && small >= large / 4) noise[k] = level;
  }
  const double sigma = detail::merit_noise(noise, c.g, m_ineq_, m_eq_, mu_, phase1);
  if (kProbeRatio * sigma >= predicted) {
    probed_noise_ = noise;
    probed_samples_ = samples_;
    return true;
  }
  return smooth();
}

// The best feasible objective (every inequality within the constraint tolerance, every equality
// within it, at the current sample size) is recorded at the start of each trust-region iteration.
// The stall: the best has improved by less than k sigma_f (k = noise_stop) since the evaluation
// count e0 of the first record within k sigma_f of it, and now - e0 >= W (noise_stop_window or
// 10 (n + 1)). sigma_f is the standard deviation of one evaluation of the objective (the confirmed
// residual noise of the fits, or the probe's), so a gain below 2 sigma_f is within the noise of a
// difference of two noisy values (sqrt 2 sigma_f) and of the selection bias of a minimum over
// many. A first stall ends the trust region (a restart follows when the global phase allows one:
// measured, a trust region stuck on a noisy constraint found the optimum after a restart); a
// stall that a restart begun after e0 has shared for W evaluations ends the run. The trace starts
// after the global phase: its evaluations are not a trust region's progress. Only on a stochastic
// problem (Problem::stochastic()) or once the probe has found noise.
SaoRun::NoiseStall SaoRun::noise_stall() {
  if (!(sao_.noise_stop > 0)) return NoiseStall::None;
  const double tol = options_.constraint_tolerance;
  double best = kInf;
  for (const KnownPoint& p : known_) {
    if (!p.ok || (sampling_ && p.samples != samples_) || !(p.f < best)) continue;
    bool feasible = true;
    for (double g : p.g) feasible = feasible && g <= tol;
    for (double h : p.h) feasible = feasible && std::fabs(h) <= tol;
    if (feasible) best = p.f;
  }
  const long now = driver_.evaluations();
  best_trace_.emplace_back(now, best);
  // only where noise is known to exist: a stochastic problem, or one whose noise the probe found
  // (on a smooth problem a residual that does not shrink with the region can be lack of fit:
  // measured on hs071, a "noise" of 0.63 ended a run at 17.87)
  if (!(stochastic_ || noisy_) || !(noise_f_ > 0) || !std::isfinite(best)) return NoiseStall::None;
  const double band = sao_.noise_stop * noise_f_;
  long since = now;  // e0: the first record within the band of the best
  for (const auto& [evaluations, value] : best_trace_)
    if (value - best < band) {
      since = evaluations;
      break;
    }
  const long window = noise_window();
  if (now - since < window) return NoiseStall::None;
  if (last_restart_evaluations_ >= since)
    return now - last_restart_evaluations_ >= window ? NoiseStall::Stop : NoiseStall::None;
  return NoiseStall::Restart;
}

}  // namespace abuopt::opt::detail
