#include "abuopt/core/equilibrium_set.hpp"

#include "abuopt/core/ball_contact.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>

namespace abuopt {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
// Hard contact: a pair closer than its least spacing by more than this overlaps; within it, it
// touches (docs/equilibrium_sets.md section 5).
constexpr double kTouchTolerance_rad = 1e-9;

void require_positive_frequency(double f, const char* what) {
  if (!(f > 0) || !std::isfinite(f))
    throw std::invalid_argument(std::string(what) + " = " + std::to_string(f) + ": must be a finite frequency > 0 Hz");
}

}  // namespace

double EquilibriumGrid::beta(std::size_t k) const { return kTwoPi * static_cast<double>(k) / static_cast<double>(n); }

double EquilibriumGrid::coverage() const {
  if (in_set.empty()) return 0;
  std::size_t c = 0;
  for (char v : in_set) c += v ? 1 : 0;
  return static_cast<double>(c) / static_cast<double>(in_set.size());
}

double EquilibriumGrid::min_amplitude_mm() const {
  return amplitude_mm.empty() ? 0 : *std::min_element(amplitude_mm.begin(), amplitude_mm.end());
}

double EquilibriumGrid::max_amplitude_mm() const {
  return amplitude_mm.empty() ? 0 : *std::max_element(amplitude_mm.begin(), amplitude_mm.end());
}

EquilibriumSet::EquilibriumSet(const AbuParameters& p, double mu, double tolerance)
    : params_(p), nd_(NondimParameters::from(p)), model_(nd_), mu_(mu < 0 ? p.friction_mu : mu), tol_(tolerance) {
  if (!(tolerance >= 0)) throw std::invalid_argument("EquilibriumSet: tolerance must be >= 0");
}

double EquilibriumSet::speed_ratio(double frequency_hz) const { return kTwoPi * frequency_hz / nd_.omega_n; }

std::pair<double, double> EquilibriumSet::steady_state(double frequency_hz, const std::vector<double>& beta) const {
  require_positive_frequency(frequency_hz, "frequency_hz");
  if (beta.size() != n_balls())
    throw std::invalid_argument("EquilibriumSet: " + std::to_string(beta.size()) + " angles given for " +
                                std::to_string(n_balls()) + " balls");
  const double W = speed_ratio(frequency_hz);
  // Same static balance as the simulator's closed_form_tail: x' = y' = x'' = y'' = 0 in the x/y rows.
  double Cx = nd_.mbar_I * nd_.ebar, Cy = 0;
  for (std::size_t i = 0; i < beta.size(); ++i) {
    Cx += nd_.mbar[i] * std::cos(beta[i]);
    Cy += nd_.mbar[i] * std::sin(beta[i]);
  }
  Cx *= W * W;
  Cy *= W * W;
  const double a = 1 - W * W, b = 2 * nd_.bbar * W;  // [a, -b; b, a]
  const double det = a * a + b * b;
  if (det == 0) return {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  return {(a * Cx + b * Cy) / det, (a * Cy - b * Cx) / det};
}

bool EquilibriumSet::evaluate_point(double W, const double* beta, std::vector<double>& state, ModelForces& f,
                                    double* margins_out, double& amp_mm, bool* overlapping, bool* touching) const {
  const std::size_t n = n_balls();
  const double W2 = W * W;
  double Cx = nd_.mbar_I * nd_.ebar, Cy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    Cx += nd_.mbar[i] * std::cos(beta[i]);
    Cy += nd_.mbar[i] * std::sin(beta[i]);
  }
  const double a = 1 - W2, b = 2 * nd_.bbar * W;
  const double det = a * a + b * b;
  if (det == 0) {
    amp_mm = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) margins_out[i] = -std::numeric_limits<double>::infinity();
    return false;
  }
  const double xs = W2 * (a * Cx + b * Cy) / det, ys = W2 * (a * Cy - b * Cx) / det;
  amp_mm = std::hypot(xs, ys) * nd_.length_m * 1e3;
  const StateLayout& lay = model_.layout();
  state.assign(lay.size(), 0.0);
  state[StateLayout::x] = xs;
  state[StateLayout::y] = ys;
  for (std::size_t i = 0; i < n; ++i) state[lay.beta(i)] = beta[i];
  static thread_local std::vector<BallMode> modes;
  modes.assign(n, BallMode::Stick);
  if (params_.ball_contact == BallContact::Hard && n >= 2) {
    // Section 5: overlapping is no configuration; touching balls are one stuck cluster whose
    // blocks must not break away (docs/model.md 11.4: the margins of its prefixes and suffixes).
    const std::vector<double> b(beta, beta + n);
    const ContactGeometry geo = ContactGeometry::from(params_, b);
    std::vector<double> unwrapped(n);
    for (std::size_t k = 0; k < n; ++k) unwrapped[k] = b[geo.order[k]] - std::floor(b[geo.order[k]] / kTwoPi) * kTwoPi;
    bool over = false, touch = false;
    std::vector<char> joined(n, 0);  // joined[k]: pair k (order[k] -> order[k + 1]) touches
    for (std::size_t k = 0; k < geo.pairs(); ++k) {
      double gap = (k + 1 < n ? unwrapped[k + 1] : unwrapped[0] + kTwoPi) - unwrapped[k] - geo.spacing[k];
      if (gap < -kTouchTolerance_rad) over = true;
      else if (gap <= kTouchTolerance_rad) joined[k] = 1, touch = true;
    }
    if (overlapping) *overlapping = over;
    if (touching) *touching = touch;
    if (over) {
      model_.evaluate(state.data(), W, 0.0, modes.data(), mu_, f);
      for (std::size_t i = 0; i < n; ++i) margins_out[i] = AbuModel::stick_margin(f, i, mu_);
      return false;
    }
    if (touch) {
      // Chains of touching balls from the rear to the front; start after a pair that is apart.
      std::size_t start = 0;
      while (start < n && joined[(start + n - 1) % n]) ++start;
      if (start == n) {  // every pair touching: impossible while sum of spacings < 2 pi
        for (std::size_t i = 0; i < n; ++i) margins_out[i] = -std::numeric_limits<double>::infinity();
        return false;
      }
      Clusters cl;
      for (std::size_t m = 0; m < n; ++m) {
        const std::size_t k = (start + m) % n;
        if (m == 0 || !joined[(k + n - 1) % n]) cl.groups.emplace_back();
        cl.groups.back().push_back(geo.order[k]);
      }
      model_.evaluate_clusters(state.data(), W, 0.0, modes.data(), cl, mu_, f);
      bool in = true;
      for (std::size_t i = 0; i < n; ++i) {
        // Per ball, in units of mu fn - |fw|: the weakest block it belongs to (for a single ball
        // min(mu fn + fw, mu fn - fw) = mu fn - |fw|, the margin without contact).
        margins_out[i] = std::min(f.margin_fwd[i], f.margin_bwd[i]) / nd_.mbar[i];
        if (!(f.fn[i] > 0) || margins_out[i] < -tol_ * f.fn[i]) in = false;
      }
      return in;
    }
  }
  model_.evaluate(state.data(), W, 0.0, modes.data(), mu_, f);
  bool in = true;
  for (std::size_t i = 0; i < n; ++i) {
    const double m = AbuModel::stick_margin(f, i, mu_);
    margins_out[i] = m;
    if (!(f.fn[i] > 0) || m < -tol_ * f.fn[i]) in = false;
  }
  return in;
}

EquilibriumPoint EquilibriumSet::point(double frequency_hz, const std::vector<double>& beta) const {
  const auto z = steady_state(frequency_hz, beta);  // validates the arguments
  const std::size_t n = n_balls();
  EquilibriumPoint p;
  p.xbar = z.first;
  p.ybar = z.second;
  p.margins.assign(n, 0.0);
  std::vector<double> state;
  ModelForces f(n);
  p.in_set = evaluate_point(speed_ratio(frequency_hz), beta.data(), state, f, p.margins.data(), p.amplitude_mm,
                            &p.overlapping, &p.touching);
  if (std::isfinite(p.amplitude_mm)) {
    p.fn = f.fn;
    p.fw = f.fw;
  } else {
    p.fn.assign(n, std::numeric_limits<double>::quiet_NaN());
    p.fw.assign(n, std::numeric_limits<double>::quiet_NaN());
  }
  p.min_margin = p.margins.empty() ? 0 : *std::min_element(p.margins.begin(), p.margins.end());
  return p;
}

EquilibriumGrid EquilibriumSet::grid(double frequency_hz, std::size_t n, const std::vector<double>& other_beta) const {
  require_positive_frequency(frequency_hz, "frequency_hz");
  const std::size_t nb = n_balls();
  if (nb < 2) throw std::invalid_argument("EquilibriumSet::grid: needs at least 2 balls, the ABU has " + std::to_string(nb));
  if (n < 2) throw std::invalid_argument("EquilibriumSet::grid: n = " + std::to_string(n) + ": must be >= 2");
  if (other_beta.size() != nb - 2)
    throw std::invalid_argument("EquilibriumSet::grid: " + std::to_string(other_beta.size()) +
                                " further angles given, the ABU has " + std::to_string(nb - 2) + " balls beyond the first two");
  EquilibriumGrid g;
  g.frequency_hz = frequency_hz;
  g.mu = mu_;
  g.n = n;
  g.n_balls = nb;
  g.other_beta = other_beta;
  g.amplitude_mm.assign(n * n, 0.0);
  g.in_set.assign(n * n, 0);
  g.margins.assign(n * n * nb, 0.0);
  if (params_.ball_contact == BallContact::Hard) g.excluded.assign(n * n, 0);
  const double W = speed_ratio(frequency_hz);
  std::vector<double> beta(nb), state;
  std::copy(other_beta.begin(), other_beta.end(), beta.begin() + 2);
  ModelForces f(nb);
  for (std::size_t i = 0; i < n; ++i) {
    beta[0] = g.beta(i);
    for (std::size_t j = 0; j < n; ++j) {
      beta[1] = g.beta(j);
      const std::size_t k = g.index(i, j);
      bool over = false;
      g.in_set[k] = evaluate_point(W, beta.data(), state, f, &g.margins[k * nb], g.amplitude_mm[k], &over) ? 1 : 0;
      if (!g.excluded.empty()) g.excluded[k] = over ? 1 : 0;
    }
  }
  return g;
}

double EquilibriumSet::coverage(double frequency_hz, std::size_t n, const std::vector<double>& other_beta) const {
  require_positive_frequency(frequency_hz, "frequency_hz");
  const std::size_t nb = n_balls();
  if (nb < 2) throw std::invalid_argument("EquilibriumSet::coverage: needs at least 2 balls, the ABU has " + std::to_string(nb));
  if (n < 2) throw std::invalid_argument("EquilibriumSet::coverage: n = " + std::to_string(n) + ": must be >= 2");
  if (other_beta.size() != nb - 2)
    throw std::invalid_argument("EquilibriumSet::coverage: " + std::to_string(other_beta.size()) +
                                " further angles given, the ABU has " + std::to_string(nb - 2) + " balls beyond the first two");
  const double W = speed_ratio(frequency_hz);
  std::vector<double> beta(nb), state, margins(nb);
  std::copy(other_beta.begin(), other_beta.end(), beta.begin() + 2);
  ModelForces f(nb);
  std::size_t count = 0;
  double amp = 0;
  for (std::size_t i = 0; i < n; ++i) {
    beta[0] = kTwoPi * static_cast<double>(i) / static_cast<double>(n);
    for (std::size_t j = 0; j < n; ++j) {
      beta[1] = kTwoPi * static_cast<double>(j) / static_cast<double>(n);
      if (evaluate_point(W, beta.data(), state, f, margins.data(), amp)) ++count;
    }
  }
  return static_cast<double>(count) / static_cast<double>(n * n);
}

EquilibriumScan EquilibriumSet::scan(double from_hz, double to_hz, double step_hz, std::size_t n,
                                     const std::vector<double>& other_beta) const {
  require_positive_frequency(from_hz, "from_hz");
  if (!(to_hz >= from_hz) || !std::isfinite(to_hz)) throw std::invalid_argument("EquilibriumSet::scan: to_hz must be >= from_hz");
  if (!(step_hz > 0)) throw std::invalid_argument("EquilibriumSet::scan: step_hz must be > 0");
  EquilibriumScan s;
  s.mu = mu_;
  s.grid_n = n;
  s.natural_frequency_hz = natural_frequency_hz();
  const auto count = static_cast<std::size_t>(std::floor((to_hz - from_hz) / step_hz + 1e-9)) + 1;
  for (std::size_t k = 0; k < count; ++k) {
    const double f = from_hz + static_cast<double>(k) * step_hz;
    const double c = coverage(f, n, other_beta);
    s.frequency_hz.push_back(f);
    s.coverage.push_back(c);
    if (c < 1) {
      if (!s.band_hz) s.band_hz = std::make_pair(f, f);
      s.band_hz->second = f;
    }
  }
  return s;
}

double EquilibriumSet::ContactLine::coverage(int side) const {
  const std::vector<char>& v = in_set[side == 0 ? 0 : 1];
  if (v.empty()) return 0;
  std::size_t c = 0;
  for (char x : v) c += x ? 1 : 0;
  return static_cast<double>(c) / static_cast<double>(v.size());
}

EquilibriumSet::ContactLine EquilibriumSet::contact_line(double frequency_hz, std::size_t n) const {
  require_positive_frequency(frequency_hz, "frequency_hz");
  if (params_.ball_contact != BallContact::Hard || n_balls() != 2)
    throw std::invalid_argument("EquilibriumSet::contact_line: needs hard ball contact and two balls");
  if (n < 1) throw std::invalid_argument("EquilibriumSet::contact_line: n must be >= 1");
  ContactLine line;
  line.spacing_rad = contact_spacing(params_, 0, 1);
  line.n = n;
  const double W = speed_ratio(frequency_hz);
  std::vector<double> beta(2), state, margins(2);
  ModelForces f(2);
  double amp = 0;
  for (int side = 0; side < 2; ++side) {
    line.in_set[side].assign(n, 0);
    for (std::size_t k = 0; k < n; ++k) {
      beta[0] = kTwoPi * static_cast<double>(k) / static_cast<double>(n);
      beta[1] = beta[0] + (side == 0 ? line.spacing_rad : -line.spacing_rad);
      bool over = false, touch = false;
      const bool in = evaluate_point(W, beta.data(), state, f, margins.data(), amp, &over, &touch);
      line.in_set[side][k] = in && touch && !over ? 1 : 0;
    }
  }
  return line;
}

double EquilibriumSet::full_coverage_margin(double frequency_hz) const {
  require_positive_frequency(frequency_hz, "frequency_hz");
  const double W = speed_ratio(frequency_hz);
  const std::complex<double> G = W * W / std::complex<double>(1 - W * W, 2 * nd_.bbar * W);
  double msum = 0;
  for (double m : nd_.mbar) msum += m;
  const double c0 = nd_.mbar_I * nd_.ebar;
  const double s = std::sqrt(1 + mu_ * mu_);
  double worst = std::numeric_limits<double>::infinity();
  for (double m : nd_.mbar) {
    const double R = c0 + msum - m;
    const double g = mu_ * (1 + m * G.real()) - m * std::abs(G.imag()) - s * std::abs(G) * R;
    worst = std::min(worst, g);
  }
  return worst;
}

std::optional<std::pair<double, double>> EquilibriumSet::exact_band_hz(double from_hz, double to_hz,
                                                                        std::size_t samples) const {
  require_positive_frequency(from_hz, "from_hz");
  if (!(to_hz > from_hz)) throw std::invalid_argument("EquilibriumSet::exact_band_hz: to_hz must be > from_hz");
  samples = std::max<std::size_t>(samples, 2);
  auto f_at = [&](std::size_t k) {
    return from_hz + (to_hz - from_hz) * static_cast<double>(k) / static_cast<double>(samples - 1);
  };
  std::optional<std::size_t> first, last;
  for (std::size_t k = 0; k < samples; ++k) {
    if (full_coverage_margin(f_at(k)) < 0) {
      if (!first) first = k;
      last = k;
    }
  }
  if (!first) return std::nullopt;
  // Bisect between a covering sample (g >= 0) and a failing one (g < 0).
  auto edge = [&](double good, double bad) {
    for (int it = 0; it < 200 && std::abs(bad - good) > 1e-9; ++it) {
      const double mid = 0.5 * (good + bad);
      (full_coverage_margin(mid) < 0 ? bad : good) = mid;
    }
    return bad;
  };
  const double lo = *first == 0 ? from_hz : edge(f_at(*first - 1), f_at(*first));
  const double hi = *last == samples - 1 ? to_hz : edge(f_at(*last + 1), f_at(*last));
  return std::make_pair(lo, hi);
}

}  // namespace abuopt
