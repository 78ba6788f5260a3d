#include "abuopt/core/equilibrium_residual.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>

namespace abuopt {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double wrap_angle(double a) {
  a = std::fmod(a, kTwoPi);
  return a < 0 ? a + kTwoPi : a;
}

ResidualStatistics statistics(std::vector<double> v) {
  ResidualStatistics s;
  s.count = v.size();
  if (v.empty()) {
    s.min = s.median = s.mean = s.max = kNaN;
    return s;
  }
  std::sort(v.begin(), v.end());
  s.min = v.front();
  s.max = v.back();
  const std::size_t h = v.size() / 2;
  s.median = v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  return s;
}

// |G(W)|, G = W^2 / (1 - W^2 + 2 i bbar W).
double gain(double W, double bbar) { return W * W / std::abs(std::complex<double>(1 - W * W, 2 * bbar * W)); }

double mass_length(const AbuParameters& p) { return p.total_mass_kg() * p.ball_track_radius_m; }

}  // namespace

std::pair<double, double> residual_vector_kgm(const AbuParameters& p, const std::vector<double>& beta) {
  if (beta.size() != p.balls.size())
    throw std::invalid_argument("residual_vector_kgm: " + std::to_string(beta.size()) + " angles given for " +
                                std::to_string(p.balls.size()) + " balls");
  double ux = p.imbalance_kgm(), uy = 0;
  for (std::size_t i = 0; i < beta.size(); ++i) {
    ux += p.balls[i].mass_kg * p.ball_track_radius_m * std::cos(beta[i]);
    uy += p.balls[i].mass_kg * p.ball_track_radius_m * std::sin(beta[i]);
  }
  return {ux, uy};
}

double inscribed_residual_kgm(const EquilibriumSet& set, double frequency_hz) {
  if (!(frequency_hz > 0) || !std::isfinite(frequency_hz))
    throw std::invalid_argument("inscribed_residual_kgm: frequency_hz = " + std::to_string(frequency_hz) +
                                ": must be a finite frequency > 0 Hz");
  const auto nd = NondimParameters::from(set.parameters());
  const double mu = set.mu();
  return mass_length(set.parameters()) * mu / ((1 + mu) * gain(set.speed_ratio(frequency_hz), nd.bbar));
}

double locked_residual_kgm(const EquilibriumSet& set) {
  const auto nd = NondimParameters::from(set.parameters());
  const double b = nd.bbar;
  // 1/|G|^2 = (v - 1)^2 + 4 b^2 v with v = 1/W^2: smallest at v = 1 - 2 b^2 (if > 0), 4 b^2 (1 - b^2);
  // otherwise |G| grows towards 1 as W -> infinity.
  const double max_gain = 2 * b * b < 1 ? 1.0 / (2 * b * std::sqrt(1 - b * b)) : 1.0;
  const double mu = set.mu();
  return mass_length(set.parameters()) * mu / ((1 + mu) * max_gain);
}

double pair_separation_floor_kgm(const AbuParameters& p, double separation_rad) {
  if (p.balls.size() != 2)
    throw std::invalid_argument("pair_separation_floor_kgm: needs exactly 2 balls, the ABU has " +
                                std::to_string(p.balls.size()));
  const double L = p.ball_track_radius_m;
  const double pair = L * std::abs(p.balls[0].mass_kg + p.balls[1].mass_kg * std::polar(1.0, separation_rad));
  return std::abs(p.imbalance_kgm() - pair);
}

std::vector<std::pair<double, double>> balancing_angles(const AbuParameters& p, const std::vector<double>& other_beta) {
  const std::size_t nb = p.balls.size();
  if (nb < 2 || other_beta.size() != nb - 2)
    throw std::invalid_argument("balancing_angles: needs >= 2 balls and the angles of balls 3..N");
  const double L = p.ball_track_radius_m;
  // m1 L e^{i b1} + m2 L e^{i b2} = T := -(m_I e + sum_{k >= 3} m_k L e^{i b_k}).
  std::complex<double> T(-p.imbalance_kgm(), 0);
  for (std::size_t k = 2; k < nb; ++k) T -= p.balls[k].mass_kg * L * std::polar(1.0, other_beta[k - 2]);
  const double a = p.balls[0].mass_kg * L, b = p.balls[1].mass_kg * L, t = std::abs(T);
  std::vector<std::pair<double, double>> out;
  if (t == 0 || t > a + b || t < std::abs(a - b)) return out;  // no solution (or a whole circle at t = 0)
  // Law of cosines: the angle between T and ball 1's vector.
  const double c = std::clamp((t * t + a * a - b * b) / (2 * a * t), -1.0, 1.0);
  const double phi = std::acos(c), arg_t = std::arg(T);
  for (double sgn : {+1.0, -1.0}) {
    const double b1 = arg_t + sgn * phi;
    const std::complex<double> rest = T - a * std::polar(1.0, b1);
    out.emplace_back(wrap_angle(b1), wrap_angle(std::arg(rest)));
    if (phi == 0) break;
  }
  return out;
}

EquilibriumResidual equilibrium_residual(const EquilibriumSet& set, double frequency_hz, std::size_t n,
                                         const std::vector<double>& other_beta) {
  const EquilibriumGrid g = set.grid(frequency_hz, n, other_beta);  // validates the arguments
  const AbuParameters& p = set.parameters();
  EquilibriumResidual r;
  r.frequency_hz = frequency_hz;
  r.speed_ratio = set.speed_ratio(frequency_hz);
  r.grid_n = n;
  r.coverage = g.coverage();
  r.inscribed_kgm = inscribed_residual_kgm(set, frequency_hz);

  const std::size_t nn = n * n;
  std::vector<double> mag(nn), x(nn), beta(p.balls.size());
  std::copy(other_beta.begin(), other_beta.end(), beta.begin() + 2);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      beta[0] = g.beta(i);
      beta[1] = g.beta(j);
      const auto u = residual_vector_kgm(p, beta);
      mag[g.index(i, j)] = std::hypot(u.first, u.second);
      x[g.index(i, j)] = std::abs(u.first);
    }

  // The connected part(s) of the set (4-neighbours on the torus) that hold a balancing point: seeded
  // from the in-set grid points of the cell around each balancing point.
  std::vector<char> part(nn, 0);
  std::vector<std::size_t> stack;
  const double h = kTwoPi / static_cast<double>(n);
  for (const auto& bal : balancing_angles(p, other_beta)) {
    const auto i0 = static_cast<std::size_t>(std::floor(bal.first / h)) % n;
    const auto j0 = static_cast<std::size_t>(std::floor(bal.second / h)) % n;
    for (std::size_t di = 0; di < 2; ++di)
      for (std::size_t dj = 0; dj < 2; ++dj) {
        const std::size_t k = g.index((i0 + di) % n, (j0 + dj) % n);
        if (g.in_set[k] && !part[k]) {
          part[k] = 1;
          stack.push_back(k);
        }
      }
  }
  while (!stack.empty()) {
    const std::size_t k = stack.back();
    stack.pop_back();
    const std::size_t i = k / n, j = k % n;
    const std::size_t nb[4] = {g.index((i + 1) % n, j), g.index((i + n - 1) % n, j), g.index(i, (j + 1) % n),
                               g.index(i, (j + n - 1) % n)};
    for (std::size_t m : nb)
      if (g.in_set[m] && !part[m]) {
        part[m] = 1;
        stack.push_back(m);
      }
  }

  std::vector<double> set_mag, set_x, part_mag, part_x, edge_mag, edge_x;
  for (std::size_t k = 0; k < nn; ++k) {
    if (!g.in_set[k]) continue;
    set_mag.push_back(mag[k]);
    set_x.push_back(x[k]);
    if (!part[k]) continue;
    part_mag.push_back(mag[k]);
    part_x.push_back(x[k]);
    const std::size_t i = k / n, j = k % n;
    const bool edge = !part[g.index((i + 1) % n, j)] || !part[g.index((i + n - 1) % n, j)] ||
                      !part[g.index(i, (j + 1) % n)] || !part[g.index(i, (j + n - 1) % n)];
    if (edge) {
      edge_mag.push_back(mag[k]);
      edge_x.push_back(x[k]);
    }
  }
  r.around_balance_fraction = static_cast<double>(part_mag.size()) / static_cast<double>(nn);
  r.in_set = {statistics(std::move(set_mag)), statistics(std::move(set_x))};
  r.around_balance = {statistics(std::move(part_mag)), statistics(std::move(part_x))};
  r.boundary = {statistics(std::move(edge_mag)), statistics(std::move(edge_x))};
  return r;
}

std::vector<EquilibriumResidual> equilibrium_residual_scan(const EquilibriumSet& set, double from_hz, double to_hz,
                                                           double step_hz, std::size_t n,
                                                           const std::vector<double>& other_beta) {
  if (!(from_hz > 0) || !(to_hz >= from_hz) || !std::isfinite(to_hz) || !(step_hz > 0))
    throw std::invalid_argument("equilibrium_residual_scan: needs 0 < from_hz <= to_hz and step_hz > 0");
  const auto count = static_cast<std::size_t>(std::floor((to_hz - from_hz) / step_hz + 1e-9)) + 1;
  std::vector<EquilibriumResidual> out;
  out.reserve(count);
  for (std::size_t k = 0; k < count; ++k)
    out.push_back(equilibrium_residual(set, from_hz + static_cast<double>(k) * step_hz, n, other_beta));
  return out;
}

}  // namespace abuopt
