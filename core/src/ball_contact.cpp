#include "abuopt/core/ball_contact.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace abuopt {

namespace {
constexpr double kTwoPi = 2.0 * M_PI;
double wrap(double a) {
  double r = std::fmod(a, kTwoPi);
  if (r < 0) r += kTwoPi;
  if (r >= kTwoPi) r = 0;
  return r;
}
}  // namespace

double contact_spacing(const AbuParameters& p, std::size_t i, std::size_t j) {
  const double s = (p.balls[i].diameter_m + p.balls[j].diameter_m) / (4.0 * p.ball_track_radius_m);
  return 2.0 * std::asin(std::min(1.0, s));
}

ContactGeometry ContactGeometry::from(const AbuParameters& p, const std::vector<double>& beta) {
  if (beta.size() != p.balls.size()) throw std::invalid_argument("ContactGeometry::from: one angle per ball");
  ContactGeometry g;
  const std::size_t n = beta.size();
  g.order.resize(n);
  std::iota(g.order.begin(), g.order.end(), std::size_t{0});
  std::vector<double> w(n);
  for (std::size_t i = 0; i < n; ++i) w[i] = wrap(beta[i]);
  std::stable_sort(g.order.begin(), g.order.end(), [&](std::size_t a, std::size_t b) { return w[a] < w[b]; });
  for (std::size_t k = 0; k < g.pairs(); ++k) g.spacing.push_back(contact_spacing(p, g.order[k], g.order[(k + 1) % n]));
  return g;
}

double ContactGeometry::gap(const double* beta, std::size_t k) const {
  const std::size_t n = order.size();
  const std::size_t a = order[k], b = order[(k + 1) % n];
  return beta[b] - beta[a] + (k + 1 == n ? kTwoPi : 0.0) - spacing[k];
}

double min_contact_clearance(const AbuParameters& p, const std::vector<double>& beta) {
  if (beta.size() < 2) return std::numeric_limits<double>::infinity();
  const ContactGeometry g = ContactGeometry::from(p, beta);
  std::vector<double> w(beta.size());
  for (std::size_t i = 0; i < beta.size(); ++i) w[i] = wrap(beta[i]);
  double m = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < g.pairs(); ++k) m = std::min(m, g.gap(w.data(), k));
  return m;
}

std::vector<double> map_onto_contact_feasible_set(const AbuParameters& p, const std::vector<double>& beta) {
  const std::size_t n = beta.size();
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = wrap(beta[i]);
  if (n < 2) return out;
  // walk from ball 0 in increasing angle: raw angles relative to ball 0 in [0, 2 pi)
  std::vector<std::size_t> idx(n);
  std::iota(idx.begin(), idx.end(), std::size_t{0});
  std::vector<double> rel(n);
  for (std::size_t i = 0; i < n; ++i) rel[i] = wrap(out[i] - out[0]);
  rel[0] = 0;
  std::stable_sort(idx.begin() + 1, idx.end(), [&](std::size_t a, std::size_t b) { return rel[a] < rel[b]; });
  double need = 0;
  for (std::size_t k = 0; k < n; ++k) need += contact_spacing(p, idx[k], idx[(k + 1) % n]);
  const double scale = (kTwoPi - need) / kTwoPi;
  double pos = 0;
  for (std::size_t k = 1; k < n; ++k) {
    pos += contact_spacing(p, idx[k - 1], idx[k]) + (rel[idx[k]] - rel[idx[k - 1]]) * scale;
    out[idx[k]] = wrap(out[0] + pos);
  }
  return out;
}

std::vector<double> mass_matrix(const NondimParameters& nd, const double* beta) {
  const std::size_t n = nd.mbar.size(), m = 2 + n;
  std::vector<double> M(m * m, 0.0);
  M[0] = M[m + 1] = 1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double s = std::sin(beta[i]), c = std::cos(beta[i]), mb = nd.mbar[i];
    const std::size_t k = 2 + i;
    M[0 * m + k] = M[k * m + 0] = -mb * s;
    M[1 * m + k] = M[k * m + 1] = mb * c;
    M[k * m + k] = mb * nd.D[i];
  }
  return M;
}

double kinetic_energy(const NondimParameters& nd, const double* beta, const std::vector<double>& qdot) {
  const std::size_t m = qdot.size();
  const std::vector<double> M = mass_matrix(nd, beta);
  double T = 0;
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t b = 0; b < m; ++b) T += 0.5 * qdot[a] * M[a * m + b] * qdot[b];
  return T;
}

double apply_impact(const NondimParameters& nd, const double* beta, std::vector<double>& qdot,
                    const std::vector<int>& group_of, const std::vector<char>& held, std::size_t rear,
                    std::size_t front, double e) {
  const std::size_t n = nd.mbar.size();
  if (qdot.size() != 2 + n || group_of.size() != n || held.size() != n || rear >= n || front >= n)
    throw std::invalid_argument("apply_impact: sizes do not match the model");
  // Reduced velocities u = (x', y', v_g for each free group): T maps u to qdot. Held balls do not
  // move in the impact; the two colliding groups are never held.
  std::vector<int> col(n, -1);
  std::vector<int> gid_col;  // group id -> column
  int next = 2;
  std::vector<std::pair<int, int>> seen;
  for (std::size_t i = 0; i < n; ++i) {
    const bool colliding = group_of[i] == group_of[rear] || group_of[i] == group_of[front];
    if (held[i] && !colliding) continue;
    int c = -1;
    for (const auto& s : seen)
      if (s.first == group_of[i]) c = s.second;
    if (c < 0) {
      c = next++;
      seen.push_back({group_of[i], c});
    }
    col[i] = c;
  }
  const int r = next;
  Eigen::MatrixXd Mr = Eigen::MatrixXd::Zero(r, r);
  Mr(0, 0) = Mr(1, 1) = 1.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (col[i] < 0) continue;
    const double s = std::sin(beta[i]), c = std::cos(beta[i]), mb = nd.mbar[i];
    Mr(0, col[i]) += -mb * s;
    Mr(col[i], 0) += -mb * s;
    Mr(1, col[i]) += mb * c;
    Mr(col[i], 1) += mb * c;
    Mr(col[i], col[i]) += mb * nd.D[i];
  }
  Eigen::VectorXd G = Eigen::VectorXd::Zero(r);
  G(col[front]) += 1.0;
  G(col[rear]) -= 1.0;
  if (col[front] == col[rear]) return 0.0;  // same rigid group: no relative motion
  const Eigen::VectorXd MinvG = Mr.ldlt().solve(G);
  const double w = G.dot(MinvG);  // 1 / effective mass of the gap
  const double vrel = qdot[2 + front] - qdot[2 + rear];
  if (!(vrel < 0) || !(w > 0)) return 0.0;  // not approaching
  const double P = -(1.0 + e) * vrel / w;
  qdot[0] += MinvG(0) * P;
  qdot[1] += MinvG(1) * P;
  for (std::size_t i = 0; i < n; ++i)
    if (col[i] >= 0) qdot[2 + i] += MinvG(col[i]) * P;
  return P;
}

}  // namespace abuopt
