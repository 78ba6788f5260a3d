// Right-hand side and root functions of the event-driven simulator (see simulator.cpp for the
// root functions' meaning, docs/model.md for the equations).
#include <algorithm>
#include <cmath>

#include "sim_run_state.hpp"

namespace abuopt::detail {

// Evaluates forces for the current modes into rs.forces and returns the speed used. For the PI
// motor, W comes from the state and W' from the motor equation, whose friction feedback is
// resolved by a short fixed-point iteration (the coupling m_i L^2 / J is ~1e-3: two passes
// converge to rounding).
Speed evaluate_forces(RunState& rs, double tbar, const double* y) {
  if (!rs.pi_motor) {
    const Speed sp = ideal_speed(rs, tbar);
    rs.eval(y, sp.W, sp.Wp);
    return sp;
  }
  // PI motor: states delta = theta_ref - theta [rad] and W (StateLayout::motor_delta/motor_speed).
  const double W = y[rs.lay().motor_speed()];
  const double delta = y[rs.lay().motor_delta()];
  const double f_ref = reference_hz(rs, tbar);
  const double Omega = W * rs.omega_n;
  const double Omega_ref = kTwoPi * f_ref;
  const double wm = rs.motor.omega_m_rad_s;
  // Bearing torque T_b opposes rotation; regularised below 0.1 rad/s so the drive can start.
  const double load = -rs.motor.bearing_torque_Nm * std::clamp(Omega / 0.1, -1.0, 1.0);
  const double accel0 = 2.0 * rs.motor.xi * wm * (Omega_ref - Omega) + wm * wm * delta + load / rs.motor.inertia_kgm2;
  const double w2 = rs.omega_n * rs.omega_n;
  double Wp = accel0 / w2;
  rs.eval(y, W, Wp);
  if (rs.motor.friction_feedback) {
    const double L = rs.params.ball_track_radius_m;
    for (int pass = 0; pass < 2; ++pass) {
      double torque = 0;  // reaction of the balls' friction (and viscous damping) on the disc
      for (std::size_t i = 0; i < rs.n; ++i)
        torque += (rs.forces.fw[i] + rs.nd.cbar[i] * y[rs.lay().beta_dot(i)]) * rs.params.balls[i].mass_kg * w2 * L * L;
      Wp = (accel0 + torque / rs.motor.inertia_kgm2) / w2;
      rs.eval(y, W, Wp);
    }
  }
  return {W, Wp};
}

// Switch model (Leine): a ball with |beta'| below the band is a stick candidate; modes are chosen
// at every right-hand-side call. A stuck ball's angle is frozen (the report reset beta' = 0 every
// step to the same effect).
// With hard contact (docs/model.md 8.1) the same rule per cluster: the joint choice of clusters
// and modes of an event (choose_contact_modes) with clusters at |speed| <= band counting as at
// rest, on a copy of the state (the choice equalises the speeds of touching balls and zeroes
// those of stuck ones; the right-hand side keeps the state as it is, as without contact). The
// clusters it chooses persist like the modes: a cut made here is the switch model's separation.
void switch_modes(RunState& rs, double tbar, const double* y) {
  // The PI motor's W' depends on the modes through the friction feedback: the W' of the current
  // modes is used to choose the new ones.
  const Speed sp = rs.pi_motor ? evaluate_forces(rs, tbar, y) : ideal_speed(rs, tbar);
  if (rs.contact) {
    switch_contact_modes(rs, {sp.W, sp.Wp}, y);
    return;
  }
  rs.model.choose_modes(y, sp.W, sp.Wp, rs.mu, rs.opt.switch_band, rs.modes.data(), rs.forces);
}

void rhs_plain(double tbar, const double* y, double* yd, void* user) {
  auto& rs = *static_cast<RunState*>(user);
  ++rs.rhs_evals;
  if (rs.frozen) {
    const Speed sp = ideal_speed(rs, tbar);
    const double W = sp.W, Wp = sp.Wp, W2 = W * W, bb = rs.nd.bbar;
    const double x = y[StateLayout::x], yy = y[StateLayout::y], xd = y[StateLayout::x_dot], ydd = y[StateLayout::y_dot];
    const double hx = -2.0 * ydd * W - x * W2 - rs.nd.mbar_I * rs.nd.ebar * W2 - Wp * (yy + rs.frozen_ss) -
                      W2 * rs.frozen_sc + x + 2.0 * bb * (xd - yy * W);
    const double hy = 2.0 * xd * W - yy * W2 + Wp * (x + rs.nd.mbar_I * rs.nd.ebar + rs.frozen_sc) -
                      W2 * rs.frozen_ss + yy + 2.0 * bb * (ydd + x * W);
    yd[StateLayout::x] = xd;
    yd[StateLayout::y] = ydd;
    yd[StateLayout::x_dot] = -hx;
    yd[StateLayout::y_dot] = -hy;
    std::fill(yd + StateLayout::table_size, yd + rs.lay().size(), 0.0);
    return;
  }
  if (rs.opt.method == FrictionMethod::SwitchModel) switch_modes(rs, tbar, y);
  const Speed sp = evaluate_forces(rs, tbar, y);
  const std::size_t n = rs.n;
  const StateLayout& lay = rs.lay();
  yd[StateLayout::x] = y[StateLayout::x_dot];
  yd[StateLayout::y] = y[StateLayout::y_dot];
  yd[StateLayout::x_dot] = rs.forces.xdd;
  yd[StateLayout::y_dot] = rs.forces.ydd;
  for (std::size_t i = 0; i < n; ++i) {
    const bool frozen = rs.modes[i] == BallMode::Stick;
    yd[lay.beta(i)] = frozen ? 0.0 : y[lay.beta_dot(i)];
    yd[lay.beta_dot(i)] = rs.forces.betadd[i];
  }
  if (rs.contact && switch_model(rs)) {
    // The balls of a cluster move as one: their angles at the cluster's mean speed (the speeds
    // of balls joined by the switch choice agree only to 1e-9; events make them equal exactly).
    for (const auto& g : rs.cs.clusters.groups) {
      if (g.size() < 2 || rs.modes[g.front()] == BallMode::Stick) continue;
      double v = 0;
      for (std::size_t i : g) v += y[lay.beta_dot(i)];
      v /= static_cast<double>(g.size());
      for (std::size_t i : g) yd[lay.beta(i)] = v;
    }
  }
  if (rs.pi_motor) {
    const double W_ref = kTwoPi * reference_hz(rs, tbar) / rs.omega_n;
    yd[lay.motor_delta()] = (W_ref - y[lay.motor_speed()]);  // d delta / dtbar = (Omega_ref - Omega)/omega_n
    yd[lay.motor_speed()] = sp.Wp;
  }
}

void roots_plain(double tbar, const double* y, double* g, void* user) {
  auto& rs = *static_cast<RunState*>(user);
  bool need_forces = false;
  for (std::size_t i = 0; i < rs.n; ++i) need_forces |= rs.modes[i] == BallMode::Stick;
  if (need_forces) evaluate_forces(rs, tbar, y);
  for (std::size_t i = 0; i < rs.n; ++i) {
    if (rs.modes[i] == BallMode::Stick) {
      const double lim = rs.mu * rs.forces.fn[i];
      g[2 * i] = lim - rs.forces.fw[i] + rs.off_a[i];
      g[2 * i + 1] = lim + rs.forces.fw[i] + rs.off_b[i];
    } else {
      g[2 * i] = static_cast<double>(static_cast<signed char>(rs.modes[i])) * y[rs.lay().beta_dot(i)];
      g[2 * i + 1] = 1.0;
    }
  }
}

// Shifts the stick margins that start negative (by rounding) so their crossing is still seen.
void set_root_offsets(RunState& rs, double tbar, const double* y) {
  if (rs.contact) {
    set_contact_root_offsets(rs, tbar, y);
    return;
  }
  evaluate_forces(rs, tbar, y);
  for (std::size_t i = 0; i < rs.n; ++i) {
    rs.off_a[i] = rs.off_b[i] = 0;
    if (rs.modes[i] != BallMode::Stick) continue;
    const double lim = rs.mu * rs.forces.fn[i];
    const double scale = 1e-10 * (std::fabs(lim) + std::fabs(rs.forces.fw[i]));
    const double ga = lim - rs.forces.fw[i], gb = lim + rs.forces.fw[i];
    if (ga < scale) rs.off_a[i] = scale - ga;
    if (gb < scale) rs.off_b[i] = scale - gb;
  }
}

bool all_stuck(const RunState& rs, const double* y) {
  for (std::size_t i = 0; i < rs.n; ++i) {
    if (rs.modes[i] != BallMode::Stick) return false;
    if (rs.opt.method == FrictionMethod::SwitchModel && std::fabs(y[rs.lay().beta_dot(i)]) > rs.opt.switch_band) return false;
  }
  return true;
}

}  // namespace abuopt::detail
