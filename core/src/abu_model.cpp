#include "abuopt/core/abu_model.hpp"

#include <cmath>

namespace abuopt {

NondimParameters NondimParameters::from(const AbuParameters& p) {
  NondimParameters nd;
  const double M = p.total_mass_kg();
  nd.omega_n = std::sqrt(p.stiffness_N_per_m / M);
  nd.length_m = p.ball_track_radius_m;
  nd.bbar = p.damping_Ns_per_m / (2.0 * M * nd.omega_n);
  nd.mbar_I = p.imbalance_mass_kg / M;
  nd.ebar = p.eccentricity_m / p.ball_track_radius_m;
  nd.mu = p.friction_mu;
  for (const auto& b : p.balls) {
    nd.mbar.push_back(b.mass_kg / M);
    nd.dbar.push_back(b.diameter_m / p.ball_track_radius_m);
    nd.cbar.push_back(p.ball_damping_Nms / (b.mass_kg * nd.omega_n * p.ball_track_radius_m * p.ball_track_radius_m));
    nd.D.push_back(1.0 + 4.0 * Jbar);
  }
  return nd;
}

void AbuModel::evaluate(const double* y, double W, double Wp, const BallMode* modes, double mu,
                        ModelForces& out) const {
  const std::size_t n = layout_.n_balls;
  const double x = y[StateLayout::x], yy = y[StateLayout::y], xd = y[StateLayout::x_dot], yd = y[StateLayout::y_dot];
  const double W2 = W * W;
  const double bb = nd_.bbar;
  constexpr double J = NondimParameters::Jbar;

  double hx = -2.0 * yd * W - x * W2 - nd_.mbar_I * nd_.ebar * W2 - Wp * yy + x + 2.0 * bb * (xd - yy * W);
  double hy = 2.0 * xd * W - yy * W2 + Wp * (x + nd_.mbar_I * nd_.ebar) + yy + 2.0 * bb * (yd + x * W);

  // Eliminating the ball accelerations beta_i'' = r_i + p_i a + q_i b (a = xbar'', b = ybar'')
  // leaves  [1 - sum m s p, -sum m s q; sum m c p, 1 + sum m c q] [a; b]
  //           = [-h_x + sum m s r; -h_y - sum m c r].
  double A11 = 1, A12 = 0, A21 = 0, A22 = 1, R1 = 0, R2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double bdi = y[layout_.beta_dot(i)];
    const double beta = y[layout_.beta(i)];
    out.sincos_at(i, beta);
    const double s = out.s[i], c = out.c[i];
    const double m = nd_.mbar[i];
    const double w = bdi + W;
    hx += -Wp * m * s - m * w * w * c;
    hy += Wp * m * c - m * w * w * s;
    const double hb = 2.0 * xd * W * c + 2.0 * yd * W * s + x * W2 * s - yy * W2 * c +
                      Wp * (x * c + yy * s + 1.0 - 2.0 * nd_.dbar[i] * J);
    const double hl = 2.0 * xd * W * s - 2.0 * yd * W * c - x * W2 * c - yy * W2 * s - w * w +
                      2.0 * J * bdi * (nd_.dbar[i] * W - 2.0 * bdi) + Wp * (x * s - yy * c);
    out.hb[i] = hb;
    out.hl[i] = hl;
    if (modes[i] != BallMode::Stick) {
      const double ms = mu * static_cast<double>(static_cast<signed char>(modes[i]));
      const double D = nd_.D[i];
      const double p = (s + ms * c) / D;
      const double q = -(c - ms * s) / D;
      const double r = (-hb - nd_.cbar[i] * bdi + ms * hl) / D;
      out.r[i] = r;
      A11 -= m * s * p;
      A12 -= m * s * q;
      A21 += m * c * p;
      A22 += m * c * q;
      R1 += m * s * r;
      R2 -= m * c * r;
    }
  }
  R1 -= hx;
  R2 -= hy;
  const double det = A11 * A22 - A12 * A21;
  const double a = (R1 * A22 - A12 * R2) / det;
  const double b = (A11 * R2 - R1 * A21) / det;
  out.xdd = a;
  out.ydd = b;
  for (std::size_t i = 0; i < n; ++i) {
    const double s = out.s[i], c = out.c[i];
    const double fn = -(c * a + s * b + out.hl[i]);
    out.fn[i] = fn;
    if (modes[i] == BallMode::Stick) {
      out.betadd[i] = 0.0;
      out.fw[i] = -(-s * a + c * b + out.hb[i] + nd_.cbar[i] * y[layout_.beta_dot(i)]);
    } else {
      const double ms = mu * static_cast<double>(static_cast<signed char>(modes[i]));
      out.betadd[i] = out.r[i] + ((s + ms * c) * a - (c - ms * s) * b) / nd_.D[i];
      out.fw[i] = ms * fn;
    }
  }
}

bool AbuModel::choose_modes(const double* y, double W, double Wp, double mu, double vtol, BallMode* modes,
                            ModelForces& forces, const std::vector<char>* fixed) const {
  const std::size_t n = layout_.n_balls;
  std::vector<std::size_t> free_balls;  // balls at (numerically) zero relative speed
  for (std::size_t i = 0; i < n; ++i) {
    const double v = y[layout_.beta_dot(i)];
    if (fixed && (*fixed)[i]) continue;
    if (std::fabs(v) <= vtol) {
      free_balls.push_back(i);
    } else {
      modes[i] = v > 0 ? BallMode::SlipForward : BallMode::SlipBackward;
    }
  }
  const std::size_t k = free_balls.size();
  auto consistent = [&](const ModelForces& f) {
    for (std::size_t j : free_balls) {
      if (modes[j] == BallMode::Stick) {
        const double lim = mu * f.fn[j];
        const double tol = 1e-9 * (std::fabs(lim) + std::fabs(f.fw[j])) + 1e-300;
        if (std::fabs(f.fw[j]) > lim + tol) return false;
      } else {
        const double sg = static_cast<double>(static_cast<signed char>(modes[j]));
        if (!(sg * f.betadd[j] > 0)) return false;
      }
    }
    return true;
  };
  if (k == 0) {
    evaluate(y, W, Wp, modes, mu, forces);
    return true;
  }
  if (k <= 6) {
    // Enumerate the 3^k assignments, those with more stuck balls first.
    std::size_t total = 1;
    for (std::size_t j = 0; j < k; ++j) total *= 3;
    for (std::size_t sticks = k + 1; sticks-- > 0;) {
      for (std::size_t code = 0; code < total; ++code) {
        std::size_t c = code, nst = 0;
        for (std::size_t j = 0; j < k; ++j) {
          const std::size_t d = c % 3;
          c /= 3;
          nst += (d == 0);
        }
        if (nst != sticks) continue;
        c = code;
        for (std::size_t j = 0; j < k; ++j) {
          const std::size_t d = c % 3;
          c /= 3;
          modes[free_balls[j]] = d == 0 ? BallMode::Stick : (d == 1 ? BallMode::SlipForward : BallMode::SlipBackward);
        }
        evaluate(y, W, Wp, modes, mu, forces);
        if (consistent(forces)) return true;
      }
    }
  }
  // Greedy fallback: all free balls stuck, release the most violated one at a time in the
  // direction of its needed friction.
  for (std::size_t j : free_balls) modes[j] = BallMode::Stick;
  for (std::size_t round = 0; round <= k; ++round) {
    evaluate(y, W, Wp, modes, mu, forces);
    double worst = 0;
    std::size_t worst_j = n;
    for (std::size_t j : free_balls) {
      if (modes[j] != BallMode::Stick) continue;
      const double viol = std::fabs(forces.fw[j]) - mu * forces.fn[j];
      if (viol > worst) {
        worst = viol;
        worst_j = j;
      }
    }
    if (worst_j == n) return consistent(forces);
    modes[worst_j] = forces.fw[worst_j] > 0 ? BallMode::SlipForward : BallMode::SlipBackward;
  }
  evaluate(y, W, Wp, modes, mu, forces);
  return false;
}

void AbuModel::imbalance_vector(const AbuParameters& p, const double* beta, double& ix, double& iy) {
  ix = p.imbalance_mass_kg * p.eccentricity_m;
  iy = 0;
  for (std::size_t i = 0; i < p.balls.size(); ++i) {
    ix += p.balls[i].mass_kg * p.ball_track_radius_m * std::cos(beta[i]);
    iy += p.balls[i].mass_kg * p.ball_track_radius_m * std::sin(beta[i]);
  }
}

}  // namespace abuopt
