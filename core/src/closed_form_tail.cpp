// The closed-form tail of a run (see docs/model.md section 6).
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <utility>

#include "sim_run_state.hpp"

namespace abuopt::detail {

namespace {

// The table's static balance at speed W with every ball stuck at the angles in y: the steady
// offset (x_s, y_s) of section 6, (1-W^2) x - 2 bbar W y = W^2 U_x, 2 bbar W x + (1-W^2) y = W^2 U_y.
std::array<double, 2> static_balance(const RunState& rs, const std::vector<double>& y, double W) {
  const double bb = rs.nd.bbar;
  double Cx = rs.nd.mbar_I * rs.nd.ebar, Cy = 0;
  for (std::size_t i = 0; i < rs.n; ++i) {
    Cx += rs.nd.mbar[i] * std::cos(y[rs.lay().beta(i)]);
    Cy += rs.nd.mbar[i] * std::sin(y[rs.lay().beta(i)]);
  }
  Cx *= W * W;
  Cy *= W * W;
  const double a11 = 1 - W * W, a12 = -2 * bb * W, a21 = 2 * bb * W, a22 = 1 - W * W;
  const double det = a11 * a22 - a12 * a21;
  return {(Cx * a22 - a12 * Cy) / det, (a11 * Cy - Cx * a21) / det};
}

// The amplitude peak of a tail e(t) = V exp(Lambda t) c about the steady offset zs (the table's x
// and y are the first two components): sampled at a twentieth of the fastest period over 20 of the
// slowest time constants, when the bound |zs| + sum_k |v_k (x, y)| |c_k| can exceed the peak so far.
template <class Vm, class Lm, class Cm, class XyAt>
void sample_tail_peak(const Vm& V, const Lm& lam, const Cm& c, double zs_norm, double span_max, double L_mm,
                      XyAt xy_at, double& peak_amp) {
  double transient = 0;
  for (int k = 0; k < lam.size(); ++k) transient += std::hypot(std::abs(V(0, k)), std::abs(V(1, k))) * std::abs(c[k]);
  if ((zs_norm + transient) * L_mm <= peak_amp) return;
  double slowest = 0, fastest = 0;
  for (int k = 0; k < lam.size(); ++k) {
    slowest = std::max(slowest, -1.0 / lam[k].real());
    fastest = std::max(fastest, std::abs(lam[k].imag()));
  }
  const double span = std::min(span_max, 20.0 * slowest);
  const double dt = fastest > 0 ? std::min(0.05 / fastest * kTwoPi, span / 16) : span / 16;
  for (double s = 0; s <= span; s += std::max(dt, 1e-9)) {
    const auto [x, y] = xy_at(s);
    peak_amp = std::max(peak_amp, std::hypot(x, y) * L_mm);
  }
}

}  // namespace

// Closed-form tail: profile over (W constant, W' = 0), every ball stuck, ideal motor. The table
// state z = (x, y, x', y') obeys z' = A z + f; with e = z - z_s, e(t) = V exp(Lambda t) V^-1 e0.
// Every stick margin is affine in z: g(t) = g(z_s) + l^T e(t), |l^T e(t)| <= sum_k |l^T v_k||c_k|.
// If g(z_s) exceeds that bound for every margin, no ball can slip again. Returns true and sets
// the final state (and the amplitude peak of the tail) when proven.
bool closed_form_tail(RunState& rs, double tbar, std::vector<double>& y, double tbar_end, double& peak_amp) {
  const double W = ideal_speed(rs, tbar).W;
  const double bb = rs.nd.bbar;
  if (!(bb > 0)) return false;
  Eigen::Matrix4d A;
  A << 0, 0, 1, 0, 0, 0, 0, 1, W * W - 1, 2 * bb * W, -2 * bb, 2 * W, -2 * bb * W, W * W - 1, -2 * W, -2 * bb;
  // Steady state from the forces with zero table velocity: solve the 2x2 static balance.
  const auto [xs, ys_] = static_balance(rs, y, W);
  Eigen::Vector4d zs(xs, ys_, 0, 0);
  // z is the table part of the state: StateLayout::x, y, x_dot, y_dot are its first four entries.
  static_assert(StateLayout::x == 0 && StateLayout::y == 1 && StateLayout::x_dot == 2 && StateLayout::y_dot == 3);
  Eigen::Vector4d e0(y[0] - zs[0], y[1] - zs[1], y[2], y[3]);

  Eigen::EigenSolver<Eigen::Matrix4d> es(A);
  const Eigen::Matrix4cd V = es.eigenvectors();
  const Eigen::Vector4cd lam = es.eigenvalues();
  for (int k = 0; k < 4; ++k)
    if (!(lam[k].real() < 0)) return false;
  const Eigen::Vector4cd c = V.partialPivLu().solve(e0.cast<std::complex<double>>());

  // Margins at z_s and their gradients (affine: differences are exact up to rounding).
  std::vector<double> ys(y);
  for (int k = 0; k < 4; ++k) ys[k] = zs[k];
  const std::size_t n = rs.n;
  std::vector<double> ga(n), gb(n);
  auto margins = [&](const std::vector<double>& state, std::vector<double>& oa, std::vector<double>& ob) {
    rs.model.evaluate(state.data(), W, 0.0, rs.modes.data(), rs.mu, rs.forces);
    for (std::size_t i = 0; i < n; ++i) {
      const double lim = rs.mu * rs.forces.fn[i];
      oa[i] = lim - rs.forces.fw[i];
      ob[i] = lim + rs.forces.fw[i];
    }
  };
  margins(ys, ga, gb);
  std::vector<Eigen::Vector4d> la(n), lb(n);
  std::vector<double> pa(n), pb(n);
  for (int k = 0; k < 4; ++k) {
    std::vector<double> yp(ys);
    const double h = 1e-3;
    yp[k] += h;
    margins(yp, pa, pb);
    for (std::size_t i = 0; i < n; ++i) {
      la[i][k] = (pa[i] - ga[i]) / h;
      lb[i][k] = (pb[i] - gb[i]) / h;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    double bound_a = 0, bound_b = 0;
    for (int k = 0; k < 4; ++k) {
      const std::complex<double> va = la[i].cast<std::complex<double>>().dot(V.col(k));
      const std::complex<double> vb = lb[i].cast<std::complex<double>>().dot(V.col(k));
      bound_a += std::abs(va) * std::abs(c[k]);
      bound_b += std::abs(vb) * std::abs(c[k]);
    }
    // margin of safety for rounding in the affine reconstruction
    const double slack = 1e-9 * (std::fabs(ga[i]) + std::fabs(gb[i]));
    if (!(ga[i] - bound_a > slack && gb[i] - bound_b > slack)) return false;
  }

  // Proven: no slip until the end. Amplitude peak of the tail, then the final table state.
  auto state_at = [&](double dt) {
    Eigen::Vector4cd ex;
    for (int k = 0; k < 4; ++k) ex[k] = c[k] * std::exp(lam[k] * dt);
    return Eigen::Vector4d(zs + (V * ex).real());
  };
  sample_tail_peak(V, lam, c, std::hypot(zs[0], zs[1]), tbar_end - tbar, rs.params.ball_track_radius_m * 1e3,
                   [&](double s) {
                     const Eigen::Vector4d z = state_at(s);
                     return std::pair<double, double>(z[0], z[1]);
                   },
                   peak_amp);
  const Eigen::Vector4d zend = state_at(tbar_end - tbar);
  for (int k = 0; k < 4; ++k) y[k] = zend[k];
  return true;
}

// Closed-form tail under the PI drive (docs/model.md 6.1). Profile over: the reference W_ref is
// constant. Every ball stuck: the balls' angles are constants and the state that still moves is
// q = (x, y, x', y', delta, W). Its equilibrium q_s (z_s of the ideal tail at W_ref, delta_s from
// W' = 0, polished by one Newton step on the full right-hand side) and the linearisation
// q' = A (q - q_s) are taken from the simulator's own right-hand side and root functions by central
// differences (the right-hand side is a low-degree polynomial in q, and the differences' truncation
// error lies far below the residual tolerance). The bound on every root function is that of the ideal
// tail with A 6 x 6. The neglected terms are second order in the deviation; they are kept small
// relative to the first-order ones by two conditions: |W - W_ref| <= 1e-3 W_ref now and along the
// whole linear tail (its bound sum_k |V(W, k)| |c_k|: the drive's oscillation crosses W_ref while it
// has not settled), and the bound may use at most half of every margin (the other half is the
// reserve for them). Not a proof: checked against integration (tests/core/closed_form_tail_pi_test.cpp).
bool closed_form_tail_pi(RunState& rs, double tbar, std::vector<double>& y, double tbar_end, double& peak_amp,
                         void (*roots)(double, const double*, double*, void*)) {
  if (!rs.pi_motor) return false;
  const StateLayout& lay = rs.lay();
  const std::size_t id = lay.motor_delta(), iw = lay.motor_speed();
  const double W_ref = kTwoPi * reference_hz(rs, tbar) / rs.omega_n;
  const double bb = rs.nd.bbar;
  if (!(bb > 0) || !(W_ref * rs.omega_n > 1.0)) return false;  // the bearing torque's regularisation: far away
  if (!(std::fabs(y[iw] - W_ref) <= 1e-3 * W_ref)) return false;
  for (std::size_t i = 0; i < rs.n; ++i)
    if (rs.modes[i] != BallMode::Stick || y[lay.beta_dot(i)] != 0.0) return false;
  const std::array<std::size_t, 6> idx = {0, 1, 2, 3, id, iw};

  // The equilibrium: the table's static balance at W_ref (as the ideal tail), delta from W' = 0.
  std::vector<double> ys(y);
  double wp_scale = 0;
  {
    const auto [xs, ys_] = static_balance(rs, y, W_ref);
    ys[0] = xs;
    ys[1] = ys_;
    ys[2] = ys[3] = 0;
    ys[iw] = W_ref;
    ys[id] = 0;
    rs.eval(ys.data(), W_ref, 0.0);
    double torque = 0;
    if (rs.motor.friction_feedback) {
      const double L = rs.params.ball_track_radius_m, w2 = rs.omega_n * rs.omega_n;
      for (std::size_t i = 0; i < rs.n; ++i) torque += rs.forces.fw[i] * rs.params.balls[i].mass_kg * w2 * L * L;
    }
    const double load = -rs.motor.bearing_torque_Nm * std::clamp(W_ref * rs.omega_n / 0.1, -1.0, 1.0);
    const double wm = rs.motor.omega_m_rad_s;
    ys[id] = -(load + torque) / (rs.motor.inertia_kgm2 * wm * wm);
    // the size of the W' row's terms (nondimensional), for its residual's tolerance
    wp_scale = (std::fabs(load) + std::fabs(torque)) / rs.motor.inertia_kgm2 / (rs.omega_n * rs.omega_n);
  }
  const std::size_t nv = lay.size() + 2;
  std::vector<double> f(nv), fp(nv), fm(nv), q(ys);
  auto rhs6 = [&](const std::vector<double>& state, Eigen::Matrix<double, 6, 1>& out) {
    rhs_plain(tbar, state.data(), f.data(), &rs);
    for (int k = 0; k < 6; ++k) out[k] = f[idx[k]];
  };
  auto steps = [&](const std::vector<double>& at) {
    std::array<double, 6> h{};
    // the table's step: relative to the largest of the offset, the imbalance and the deviation (an
    // ABU balanced almost exactly has a tiny offset but terms of the imbalance's size)
    const double zn = std::max({std::hypot(at[0], at[1]), rs.nd.mbar_I * rs.nd.ebar, std::hypot(y[0] - at[0], y[1] - at[1]),
                                1e-12});
    for (int k = 0; k < 4; ++k) h[k] = 1e-4 * zn;
    h[4] = 1e-6 * std::max(1.0, std::fabs(at[id]));
    h[5] = 1e-6 * std::max(1.0, std::fabs(at[iw]));
    return h;
  };
  auto jacobian = [&](const std::vector<double>& at, Eigen::Matrix<double, 6, 6>& A) {
    const auto h = steps(at);
    Eigen::Matrix<double, 6, 1> up, dn;
    for (int k = 0; k < 6; ++k) {
      q = at;
      q[idx[k]] += h[k];
      rhs6(q, up);
      q = at;
      q[idx[k]] -= h[k];
      rhs6(q, dn);
      A.col(k) = (up - dn) / (2 * h[k]);
    }
  };
  // One Newton step on the full right-hand side (the fixed point of the friction feedback and the
  // regularisations are in it), then the residual must be at rounding level.
  Eigen::Matrix<double, 6, 6> A;
  Eigen::Matrix<double, 6, 1> r;
  jacobian(ys, A);
  rhs6(ys, r);
  const Eigen::Matrix<double, 6, 1> dq = A.partialPivLu().solve(r);
  for (int k = 0; k < 6; ++k) ys[idx[k]] -= dq[k];
  jacobian(ys, A);
  rhs6(ys, r);
  const double scale = W_ref * W_ref * (std::hypot(ys[0], ys[1]) + rs.nd.mbar_I * rs.nd.ebar);
  if (!(r.template head<4>().norm() <= 1e-9 * scale && std::fabs(r[4]) <= 1e-9 * W_ref &&
        std::fabs(r[5]) <= 1e-9 * std::max(wp_scale, 1e-6 * W_ref * W_ref)))
    return false;

  Eigen::EigenSolver<Eigen::Matrix<double, 6, 6>> es(A);
  if (es.info() != Eigen::Success) return false;
  const Eigen::Matrix<std::complex<double>, 6, 6> V = es.eigenvectors();
  const Eigen::Matrix<std::complex<double>, 6, 1> lam = es.eigenvalues();
  for (int k = 0; k < 6; ++k)
    if (!(lam[k].real() < 0)) return false;
  Eigen::Matrix<double, 6, 1> e0;
  for (int k = 0; k < 6; ++k) e0[k] = y[idx[k]] - ys[idx[k]];
  const Eigen::Matrix<std::complex<double>, 6, 1> c = V.partialPivLu().solve(e0.cast<std::complex<double>>());
  if (!c.allFinite()) return false;
  double speed_bound = 0;  // |W(t) - W_ref| <= this along the linear tail
  for (int k = 0; k < 6; ++k) speed_bound += std::abs(V(5, k)) * std::abs(c[k]);
  if (!(speed_bound <= 1e-3 * W_ref)) return false;

  // The root functions at q_s and their gradients.
  const std::size_t nr = rs.nroots();
  std::vector<double> gs(nr), gu(nr), gd(nr);
  roots(tbar, ys.data(), gs.data(), &rs);
  Eigen::MatrixXd G(static_cast<Eigen::Index>(nr), 6);
  const auto h = steps(ys);
  for (int k = 0; k < 6; ++k) {
    q = ys;
    q[idx[k]] += h[k];
    roots(tbar, q.data(), gu.data(), &rs);
    q = ys;
    q[idx[k]] -= h[k];
    roots(tbar, q.data(), gd.data(), &rs);
    for (std::size_t j = 0; j < nr; ++j) G(static_cast<Eigen::Index>(j), k) = (gu[j] - gd[j]) / (2 * h[k]);
  }
  for (std::size_t j = 0; j < nr; ++j) {
    double bound = 0;
    for (int k = 0; k < 6; ++k)
      bound += std::abs(G.row(static_cast<Eigen::Index>(j)).cast<std::complex<double>>().dot(V.col(k))) * std::abs(c[k]);
    if (!(gs[j] > 0 && bound <= 0.5 * gs[j])) return false;
  }

  // Accepted: the amplitude peak of the tail (sampled as the ideal tail does), the final state.
  auto state_at = [&](double dt) {
    Eigen::Matrix<std::complex<double>, 6, 1> ex;
    for (int k = 0; k < 6; ++k) ex[k] = c[k] * std::exp(lam[k] * dt);
    Eigen::Matrix<double, 6, 1> out = (V * ex).real();
    for (int k = 0; k < 6; ++k) out[k] += ys[idx[k]];
    return out;
  };
  sample_tail_peak(V, lam, c, std::hypot(ys[0], ys[1]), tbar_end - tbar, rs.params.ball_track_radius_m * 1e3,
                   [&](double s) {
                     const auto z = state_at(s);
                     return std::pair<double, double>(z[0], z[1]);
                   },
                   peak_amp);
  const auto qend = state_at(tbar_end - tbar);
  for (int k = 0; k < 6; ++k) y[idx[k]] = qend[k];
  return true;
}

}  // namespace abuopt::detail
