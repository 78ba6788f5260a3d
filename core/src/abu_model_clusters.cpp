// AbuModel::evaluate_clusters: the reduced equations with rigid clusters of touching balls
// (hard ball-ball contact, docs/model.md section 11.4). O(N) like evaluate().
#include <cmath>

#include "abuopt/core/abu_model.hpp"

namespace abuopt {

void AbuModel::evaluate_clusters(const double* y, double W, double Wp, const BallMode* modes, const Clusters& cl,
                                 double mu, ModelForces& out) const {
  const std::size_t n = layout_.n_balls;
  const double x = y[StateLayout::x], yy = y[StateLayout::y], xd = y[StateLayout::x_dot], yd = y[StateLayout::y_dot];
  const double W2 = W * W;
  const double bb = nd_.bbar;
  constexpr double J = NondimParameters::Jbar;

  double hx = -2.0 * yd * W - x * W2 - nd_.mbar_I * nd_.ebar * W2 - Wp * yy + x + 2.0 * bb * (xd - yy * W);
  double hy = 2.0 * xd * W - yy * W2 + Wp * (x + nd_.mbar_I * nd_.ebar) + yy + 2.0 * bb * (yd + x * W);
  for (std::size_t i = 0; i < n; ++i) {
    const double bdi = y[layout_.beta_dot(i)];
    const double beta = y[layout_.beta(i)];
    out.sincos_at(i, beta);
    const double s = out.s[i], c = out.c[i], m = nd_.mbar[i], w = bdi + W;
    hx += -Wp * m * s - m * w * w * c;
    hy += Wp * m * c - m * w * w * s;
    out.hb[i] = 2.0 * xd * W * c + 2.0 * yd * W * s + x * W2 * s - yy * W2 * c +
                Wp * (x * c + yy * s + 1.0 - 2.0 * nd_.dbar[i] * J);
    out.hl[i] = 2.0 * xd * W * s - 2.0 * yd * W * c - x * W2 * c - yy * W2 * s - w * w +
                2.0 * J * bdi * (nd_.dbar[i] * W - 2.0 * bdi) + Wp * (x * s - yy * c);
  }
  // A slipping cluster g (sigma, members i): the sum of its ball rows times mbar_i has no contact
  // forces (they are internal) and gives beta_g'' = R_g + P_g xbar'' + Q_g ybar''.
  double A11 = 1, A12 = 0, A21 = 0, A22 = 1, R1 = 0, R2 = 0;
  for (const auto& g : cl.groups) {
    const BallMode mode = modes[g.front()];
    if (mode == BallMode::Stick) continue;
    const double ms = mu * static_cast<double>(static_cast<signed char>(mode));
    double Ss = 0, Sc = 0, SD = 0, P = 0, Q = 0, R = 0;
    for (std::size_t i : g) {
      const double m = nd_.mbar[i], s = out.s[i], c = out.c[i];
      Ss += m * s;
      Sc += m * c;
      SD += m * nd_.D[i];
      P += m * (s + ms * c);
      Q -= m * (c - ms * s);
      R += m * (-out.hb[i] - nd_.cbar[i] * y[layout_.beta_dot(i)] + ms * out.hl[i]);
    }
    P /= SD;
    Q /= SD;
    R /= SD;
    for (std::size_t i : g) out.r[i] = R;  // scratch: the cluster's acceleration terms
    out.betadd[g.front()] = P;  // (kept in betadd/fw until a, b are known)
    out.fw[g.front()] = Q;
    A11 -= Ss * P;
    A12 -= Ss * Q;
    A21 += Sc * P;
    A22 += Sc * Q;
    R1 += Ss * R;
    R2 -= Sc * R;
  }
  R1 -= hx;
  R2 -= hy;
  const double det = A11 * A22 - A12 * A21;
  const double a = (R1 * A22 - A12 * R2) / det;
  const double b = (A11 * R2 - R1 * A21) / det;
  out.xdd = a;
  out.ydd = b;
  for (std::size_t i = 0; i < n; ++i) out.fn[i] = -(out.c[i] * a + out.s[i] * b + out.hl[i]);
  for (const auto& g : cl.groups) {
    const BallMode mode = modes[g.front()];
    if (mode == BallMode::Stick) {
      // Needed friction with no contact force, then the margins of the blocks that can break
      // away: the balls from j to the front slipping forward, from the rear to j backward.
      double run = 0;
      for (std::size_t i : g) {
        out.betadd[i] = 0.0;
        out.contact[i] = 0.0;
        out.fw[i] = -(-out.s[i] * a + out.c[i] * b + out.hb[i] + nd_.cbar[i] * y[layout_.beta_dot(i)]);
        const double m = nd_.mbar[i];
        run += m * (mu * out.fn[i] + out.fw[i]);
        out.margin_bwd[i] = run;
      }
      run = 0;
      for (std::size_t k = g.size(); k-- > 0;) {
        const std::size_t i = g[k];
        const double m = nd_.mbar[i];
        run += m * (mu * out.fn[i] - out.fw[i]);
        out.margin_fwd[i] = run;
      }
      continue;
    }
    const double ms = mu * static_cast<double>(static_cast<signed char>(mode));
    const double acc = out.r[g.front()] + out.betadd[g.front()] * a + out.fw[g.front()] * b;
    // contact force after member l: lambda_l = -sum_{j <= l} mbar_j (ball row j)
    double lambda = 0;
    for (std::size_t k = 0; k < g.size(); ++k) {
      const std::size_t i = g[k];
      out.betadd[i] = acc;
      out.fw[i] = ms * out.fn[i];
      const double row = -out.s[i] * a + out.c[i] * b + nd_.D[i] * acc + out.hb[i] +
                         nd_.cbar[i] * y[layout_.beta_dot(i)] + out.fw[i];
      lambda -= nd_.mbar[i] * row;
      out.contact[i] = k + 1 < g.size() ? lambda : 0.0;
      out.margin_fwd[i] = out.margin_bwd[i] = 0.0;
    }
  }
}

}  // namespace abuopt
