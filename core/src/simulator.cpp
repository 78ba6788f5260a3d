// Event-driven simulation of one ABU startup (see simulator.hpp and docs/model.md).
//
// Integration runs in non-dimensional time tbar = omega_n t with SUNDIALS ARKODE (explicit
// ERKStep, a high-order table) in one-step mode. Each ball owns two root functions:
//   slipping ball:  g_a = sigma_i beta_i'             (slip -> stick candidate when it reaches 0)
//                   g_b = 1                            (unused)
//   stuck ball:     g_a = mu fn_i - fw_i + off_a       (stick -> slip forward)
//                   g_b = mu fn_i + fw_i + off_b       (stick -> slip backward)
// The offsets are zero unless a stick phase starts with a (numerically) negative margin: then the
// margin is shifted so that it starts positive and its later crossing is still seen. At every
// root the modes of all balls are chosen together (AbuModel::choose_modes) and the integrator is
// reset. After the profile ends with every ball stuck (ideal motor), the table motion is linear
// and time-invariant; if a bound on its transient proves that no stick margin can reach zero, the
// run is finished in closed form (closed_form_tail).
//
// The parts: sim_rhs.cpp (right-hand side and root functions), closed_form_tail.cpp,
// integrator_native.cpp and integrator_arkode.cpp (the back ends, integrator.hpp).
#include "abuopt/core/simulator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <memory>
#include <stdexcept>
#include <sstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/abu_model.hpp"
#include "integrator.hpp"
#include "sim_run_state.hpp"

namespace abuopt {

std::string to_string(FrictionMethod m) { return m == FrictionMethod::EventDriven ? "event_driven" : "switch_model"; }
std::string to_string(IntegratorBackend b) { return b == IntegratorBackend::ArkodeErk ? "arkode_erk" : "native"; }
std::string to_string(RunStatus s) {
  switch (s) {
    case RunStatus::Ok: return "ok";
    case RunStatus::SolverFailure: return "solver_failure";
    case RunStatus::ChatterLimit: return "chatter_limit";
    case RunStatus::StepLimit: return "step_limit";
  }
  return "unknown";
}

using namespace detail;

Simulator::Simulator(SimulationSetup setup) : setup_(std::move(setup)) {
  validate(setup_.abu);
  validate(setup_.profile);
  const auto& o = setup_.options;
  if (!(o.rtol > 0 && o.rtol < 1)) throw ConfigError("simulation.rtol", std::to_string(o.rtol), "must be in (0, 1)");
  if (!(o.atol > 0)) throw ConfigError("simulation.atol", std::to_string(o.atol), "must be > 0");
  if (o.end_time_s < 0) throw ConfigError("simulation.end_time_s", std::to_string(o.end_time_s), "must be >= 0 (0: twice the profile duration)");
  if (end_time_s() <= 0)
    throw ConfigError("simulation.end_time_s", std::to_string(o.end_time_s),
                      "must be > 0 when the profile has no segments");
}

Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;

double Simulator::end_time_s() const {
  return setup_.options.end_time_s > 0 ? setup_.options.end_time_s : 2.0 * setup_.profile.duration_s();
}

RunOutcome Simulator::run(const std::vector<double>& beta0, const RunOverrides& ov,
                          std::vector<TrajectoryPoint>* trajectory) const {
  const auto wall0 = std::chrono::steady_clock::now();
  if (beta0.size() != setup_.abu.balls.size())
    throw ConfigError("the ABU has " + std::to_string(setup_.abu.balls.size()) + " balls, but " +
                      std::to_string(beta0.size()) + " initial angles were given");
  AbuParameters p = setup_.abu;
  if (ov.friction_mu) p.friction_mu = *ov.friction_mu;
  if (ov.imbalance_mass_kg) p.imbalance_mass_kg = *ov.imbalance_mass_kg;

  RunState rs(p);
  rs.profile = &setup_.profile;
  rs.motor = setup_.motor;
  rs.opt = setup_.options;
  rs.mu = p.friction_mu;
  rs.omega_n = rs.nd.omega_n;
  rs.n = p.balls.size();
  rs.pi_motor = setup_.motor.kind == MotorKind::PI;
  rs.modes.assign(rs.n, BallMode::Stick);
  rs.forces.resize(rs.n);
  rs.off_a.assign(rs.n, 0);
  rs.off_b.assign(rs.n, 0);
  const StateLayout& lay = rs.lay();
  const std::size_t nabu = lay.size();
  const std::size_t nvar = nabu + (rs.pi_motor ? 2 : 0);
  const bool event_driven = rs.opt.method == FrictionMethod::EventDriven;

  std::vector<double> y(nvar, 0.0);
  // Angles relative to the imbalance; an imbalance at angle phi sees the balls at beta - phi.
  for (std::size_t i = 0; i < rs.n; ++i) y[lay.beta(i)] = wrap_angle(beta0[i] - ov.imbalance_angle_rad);

  const double w = rs.omega_n;
  const double t_end = end_time_s() * w;
  const double t_profile = setup_.profile.duration_s() * w;
  RunOutcome out;
  out.end_time_s = end_time_s();
  double peak_amp = 0;
  const double L_mm = p.ball_track_radius_m * 1e3;

  // Initial modes from what happens just after t = 0: at rest every force is zero, so decide at
  // a tiny time with the rest state (forces then scale alike and the relative test works).
  {
    const double first = setup_.profile.segments().empty() ? 1.0 : setup_.profile.segments()[0].duration_s;
    const double tiny = 1e-6 * first * w;
    std::vector<double> yprobe(y);
    if (rs.pi_motor) {
      // the reference has moved a little; the disc has not
      const double fr = rs.motor.realised_reference_hz(setup_.profile.frequency_hz(tiny / w));
      yprobe[lay.motor_delta()] = 0.25 * kTwoPi * fr / w * tiny;  // delta ~ integral of the reference speed
    }
    Speed sp = rs.pi_motor ? Speed{0, 0} : ideal_speed(rs, tiny);
    if (rs.pi_motor) {
      rs.modes.assign(rs.n, BallMode::Stick);
      sp.Wp = evaluate_forces(rs, tiny, yprobe.data()).Wp;
    }
    rs.model.choose_modes(yprobe.data(), sp.W, sp.Wp, rs.mu, 0.0, rs.modes.data(), rs.forces);
    rs.modes_changed(y.data());
  }

  std::unique_ptr<Integrator> integ_ptr = make_integrator(rs, nvar, event_driven);
  Integrator& integ = *integ_ptr;
  double t = 0;
  integ.reset(t, y);
  if (event_driven) set_root_offsets(rs, t, y.data());

  std::vector<double> breaks;
  for (double b : setup_.profile.breakpoints_s())
    if (b * w > 0 && b * w < t_end) breaks.push_back(b * w);
  breaks.push_back(t_end);
  std::size_t next_break = 0;
  integ.set_stop(breaks[0]);

  std::vector<int> rinfo(2 * rs.n);
  std::vector<char> fixed(rs.n, 0);
  std::deque<double> recent_events;
  double all_stuck_since = all_stuck(rs, y.data()) ? 0.0 : -1.0;
  double next_tail_check = t_profile;
  double next_traj = 0;
  const double traj_dt = rs.opt.trajectory_interval_s * w;
  std::vector<double> ytraj(nvar);
  auto record = [&](double tt, const std::vector<double>& yy) {
    TrajectoryPoint tp;
    tp.t_s = tt / w;
    tp.frequency_hz = rs.pi_motor ? yy[lay.motor_speed()] * w / kTwoPi : setup_.profile.frequency_hz(tp.t_s);
    tp.x_m = yy[StateLayout::x] * p.ball_track_radius_m;
    tp.y_m = yy[StateLayout::y] * p.ball_track_radius_m;
    for (std::size_t i = 0; i < rs.n; ++i) {
      tp.beta.push_back(wrap_angle(yy[lay.beta(i)]));
      tp.mode.push_back(static_cast<int>(static_cast<signed char>(rs.modes[i])));
    }
    trajectory->push_back(std::move(tp));
  };
  if (trajectory && traj_dt > 0) {
    record(0, y);
    next_traj = traj_dt;
  }

  while (t < t_end) {
    const Integrator::Result res = integ.step(t, y, rinfo);
    if (res == Integrator::Failure) {
      out.status = integ.too_much_work() ? RunStatus::StepLimit : RunStatus::SolverFailure;
      out.message = integ.failure() + " at t = " + std::to_string(t / w) + " s";
      break;
    }
    if (trajectory && traj_dt > 0) {
      while (next_traj <= t && next_traj <= t_end) {
        integ.dense(next_traj, ytraj);
        record(next_traj, ytraj);
        next_traj += traj_dt;
      }
    }
    peak_amp = std::max(peak_amp, std::hypot(y[StateLayout::x], y[StateLayout::y]) * L_mm);

    if (!event_driven) {
      // switch model: track the all-stuck period at step ends
      switch_modes(rs, t, y.data());
      if (all_stuck(rs, y.data())) {
        if (all_stuck_since < 0) all_stuck_since = t;
      } else {
        all_stuck_since = -1;
      }
    }

    bool reset_needed = false;
    if (res == Integrator::Root) {
      // A slipping ball whose speed reached zero may stick or reverse: a candidate. A stuck ball
      // whose friction margin reached zero leaves stick in the direction of the force needed to
      // hold it (the net force); the others are re-chosen consistently with that.
      const Speed sp0 = evaluate_forces(rs, t, y.data());
      for (std::size_t i = 0; i < rs.n; ++i) {
        fixed[i] = 0;
        if (rs.modes[i] != BallMode::Stick) {
          if (rinfo[2 * i] != 0) y[lay.beta_dot(i)] = 0.0;
        } else {
          y[lay.beta_dot(i)] = 0.0;
          if (rinfo[2 * i] != 0 || rinfo[2 * i + 1] != 0) {
            fixed[i] = 1;
            rs.modes[i] = rs.forces.fw[i] > 0 ? BallMode::SlipForward : BallMode::SlipBackward;
          }
        }
      }
      const Speed sp = rs.pi_motor ? sp0 : ideal_speed(rs, t);
      rs.model.choose_modes(y.data(), sp.W, sp.Wp, rs.mu, 0.0, rs.modes.data(), rs.forces, &fixed);
      rs.modes_changed(y.data());
      ++out.events;
      recent_events.push_back(t);
      while (!recent_events.empty() && (t - recent_events.front()) > rs.opt.chatter_window_s * w) recent_events.pop_front();
      if (static_cast<long>(recent_events.size()) > rs.opt.chatter_events) {
        out.status = RunStatus::ChatterLimit;
        out.message = "more than " + std::to_string(rs.opt.chatter_events) + " stick/slip events within " +
                      std::to_string(rs.opt.chatter_window_s) + " s at t = " + std::to_string(t / w) + " s";
        break;
      }
      if (out.events > rs.opt.max_events) {
        out.status = RunStatus::ChatterLimit;
        out.message = "more than " + std::to_string(rs.opt.max_events) + " stick/slip events";
        break;
      }
      if (all_stuck(rs, y.data())) {
        if (all_stuck_since < 0) all_stuck_since = t;
      } else {
        all_stuck_since = -1;
      }
      reset_needed = true;
    }
    if (next_break < breaks.size() && t >= breaks[next_break]) {
      ++next_break;
      if (next_break < breaks.size()) integ.set_stop(breaks[next_break]);
    }
    if (t >= t_end) break;

    if (event_driven && rs.opt.closed_form_tail && !rs.pi_motor && !(trajectory && traj_dt > 0) && t >= t_profile && t >= next_tail_check &&
        all_stuck_since >= 0) {
      if (closed_form_tail(rs, t, y, t_end, peak_amp)) {
        t = t_end;
        break;
      }
      next_tail_check = t + 0.5 * w;  // the transient decays; try again later
    }
    if (reset_needed) {
      integ.reset(t, y);
      set_root_offsets(rs, t, y.data());
    }
  }

  out.steps = integ.steps();
  out.rhs_evaluations = rs.rhs_evals;
  out.max_amplitude_mm = peak_amp;
  for (std::size_t i = 0; i < rs.n; ++i) out.beta_final.push_back(wrap_angle(y[lay.beta(i)]));
  double ix = 0, iy = 0;
  AbuModel::imbalance_vector(p, out.beta_final.data(), ix, iy);
  out.residual_imbalance_kgm = std::hypot(ix, iy);
  out.residual_imbalance_x_kgm = std::fabs(ix);
  out.settled = out.ok() && all_stuck(rs, y.data());
  out.settling_time_s = out.settled ? all_stuck_since / w : 0.0;
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return out;
}

}  // namespace abuopt
