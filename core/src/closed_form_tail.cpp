// The closed-form tail of a run (see docs/model.md section 6).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>

#include "sim_run_state.hpp"

namespace abuopt::detail {

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
  double Cx = rs.nd.mbar_I * rs.nd.ebar, Cy = 0;
  for (std::size_t i = 0; i < rs.n; ++i) {
    Cx += rs.nd.mbar[i] * std::cos(y[rs.lay().beta(i)]);
    Cy += rs.nd.mbar[i] * std::sin(y[rs.lay().beta(i)]);
  }
  Cx *= W * W;
  Cy *= W * W;
  const double a11 = 1 - W * W, a12 = -2 * bb * W, a21 = 2 * bb * W, a22 = 1 - W * W;
  const double det = a11 * a22 - a12 * a21;
  Eigen::Vector4d zs((Cx * a22 - a12 * Cy) / det, (a11 * Cy - Cx * a21) / det, 0, 0);
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
  double transient = 0;
  for (int k = 0; k < 4; ++k) transient += std::hypot(std::abs(V(0, k)), std::abs(V(1, k))) * std::abs(c[k]);
  const double L_mm = rs.params.ball_track_radius_m * 1e3;
  if ((std::hypot(zs[0], zs[1]) + transient) * L_mm > peak_amp) {
    double slowest = 0, fastest = 0;
    for (int k = 0; k < 4; ++k) {
      slowest = std::max(slowest, -1.0 / lam[k].real());
      fastest = std::max(fastest, std::abs(lam[k].imag()));
    }
    const double span = std::min(tbar_end - tbar, 20.0 * slowest);
    const double dt = fastest > 0 ? std::min(0.05 / fastest * kTwoPi, span / 16) : span / 16;
    for (double s = 0; s <= span; s += std::max(dt, 1e-9)) {
      const Eigen::Vector4d z = state_at(s);
      peak_amp = std::max(peak_amp, std::hypot(z[0], z[1]) * L_mm);
    }
  }
  const Eigen::Vector4d zend = state_at(tbar_end - tbar);
  for (int k = 0; k < 4; ++k) y[k] = zend[k];
  return true;
}

}  // namespace abuopt::detail
