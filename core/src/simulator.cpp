// Event-driven simulation of one ABU startup (see simulator.hpp and docs/model.md).
//
// Integration runs in non-dimensional time tbar = omega_n t, one step at a time, with the native
// explicit Runge-Kutta stepper (default; ARKODE's Fehlberg 7(8) table) or SUNDIALS ARKODE's
// ERKStep (the reference). Each ball owns two root functions:
//   slipping ball:  g_a = sigma_i beta_i'             (slip -> stick candidate when it reaches 0)
//                   g_b = 1                            (unused)
//   stuck ball:     g_a = mu fn_i - fw_i + off_a       (stick -> slip forward)
//                   g_b = mu fn_i + fw_i + off_b       (stick -> slip backward)
// The offsets are zero unless a stick phase starts with a (numerically) negative margin: then the
// margin is shifted so that it starts positive and its later crossing is still seen. At every
// root the modes of all balls are chosen together (AbuModel::choose_modes) and the integrator is
// reset. After the profile ends with every ball stuck (ideal motor), the table motion is linear
// and time-invariant; if a bound on its transient proves that no stick margin can reach zero, the
// run is finished in closed form (closed_form_tail). Under the PI drive the same with table and
// motor linearised about their equilibrium and a reserve for the neglected terms
// (closed_form_tail_pi, docs/model.md 6.1). While every ball is stuck (ideal motor), the
// default stuck integrator propagates the table exactly instead of stepping
// (stuck_propagator.hpp, docs/stuck_propagator.md); the stepper restarts at the next event.
//
// The parts: sim_rhs.cpp (right-hand side and root functions), closed_form_tail.cpp,
// integrator_native.cpp and integrator_arkode.cpp (the back ends, integrator.hpp),
// stuck_propagator.cpp (the exact all-stuck phases).
#include "abuopt/core/simulator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <memory>
#include <optional>
#include <stdexcept>
#include <sstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/abu_model.hpp"
#include "abuopt/core/sim_counters.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "integrator.hpp"
#include "sim_run_state.hpp"
#include "run_forcing_table.hpp"
#include "abuopt/common/stop.hpp"
#include "stuck_propagator.hpp"

namespace abuopt {

std::string to_string(FrictionMethod m) { return m == FrictionMethod::EventDriven ? "event_driven" : "switch_model"; }
std::string to_string(IntegratorBackend b) { return b == IntegratorBackend::ArkodeErk ? "arkode_erk" : "native"; }
std::string to_string(StuckIntegrator s) { return s == StuckIntegrator::Exact ? "exact" : "rk"; }
std::string to_string(RunStatus s) {
  switch (s) {
    case RunStatus::Ok: return "ok";
    case RunStatus::SolverFailure: return "solver_failure";
    case RunStatus::ChatterLimit: return "chatter_limit";
    case RunStatus::StepLimit: return "step_limit";
    case RunStatus::EventLimit: return "event_limit";
  }
  return "unknown";
}

using namespace detail;

Simulator::Simulator(SimulationSetup setup) : setup_(std::move(setup)) {
  validate(setup_.abu);
  validate(setup_.profile);
  validate(setup_.motor);
  validate(setup_.options);  // the reader's rules, from the one field list (simulation_config.hpp)
  const auto& o = setup_.options;
  if (end_time_s() <= 0)
    throw ConfigError("simulation.end_time_s", std::to_string(o.end_time_s),
                      "must be > 0 when the profile has no segments");
  // The exact stuck-phase propagator: its forcing integrals depend only on the profile and the
  // table, so they are computed once (by the first run that needs them) and shared by every run.
  if (o.stuck_integrator == StuckIntegrator::Exact && o.method == FrictionMethod::EventDriven &&
      setup_.motor.kind == MotorKind::Ideal)
    forcing_ = std::make_shared<SimulatorForcing>(setup_.profile, NondimParameters::from(setup_.abu), end_time_s());
  if (setup_.motor.kind == MotorKind::PI && setup_.motor.feedforward.enabled)
    reference_ = std::make_shared<const StartupProfile>(feedforward_setpoint(setup_.profile, setup_.motor, end_time_s()));
  // The integrator's stop times, once for every run (not per run: the feed-forward setpoint has ~100
  // segments a second): the reference's breakpoints and the quantised reference's steps. The exact
  // setpoint keeps its joins as stops (C1 there, but without them a mismatch run failed with a too
  // small step: FeedForward.TheDriveFollowsTheProfile).
  const StartupProfile& ref = reference_ ? *reference_ : setup_.profile;
  stop_times_s_ = ref.breakpoints_s();
  if (reference_ && setup_.motor.quantize_setpoint_1hz) {
    // whole-Hz feed-forward: the held reference changes only at its steps, not at the joins
    stop_times_s_ = setup_.profile.breakpoints_s();
    stop_times_s_.push_back(reference_->duration_s());
  }
  if (setup_.motor.kind == MotorKind::PI && setup_.motor.quantize_setpoint_1hz) {
    const std::vector<double> steps = setup_.motor.reference_step_times_s(ref);
    stop_times_s_.insert(stop_times_s_.end(), steps.begin(), steps.end());
  }
  std::sort(stop_times_s_.begin(), stop_times_s_.end());
  stop_times_s_.erase(std::unique(stop_times_s_.begin(), stop_times_s_.end()), stop_times_s_.end());
}

Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;

double Simulator::end_time_s() const {
  return setup_.options.end_time_s > 0 ? setup_.options.end_time_s : 2.0 * setup_.profile.duration_s();
}

namespace {

// One run from its initial angles to the end time, in three phases: mode initialisation (the
// constructor), stepping with event handling (execute, handle_event), finishing (finish).
class Run {
 public:
  Run(const SimulationSetup& setup, double end_time_s, const std::vector<double>& beta0, const RunOverrides& ov,
      std::vector<TrajectoryPoint>* trajectory, SimulatorForcing* forcing, const StartupProfile& reference,
      const std::vector<double>& stop_times_s)
      : setup_(setup), ref_(reference), p_(with_overrides(setup.abu, ov)), rs_(p_), lay_(rs_.lay()), trajectory_(trajectory) {
    rs_.profile = &ref_;  // the ideal motor's speed, or the PI drive's setpoint
    rs_.motor = setup_.motor;
    rs_.opt = setup_.options;
    rs_.mu = p_.friction_mu;
    rs_.omega_n = rs_.nd.omega_n;
    rs_.n = p_.balls.size();
    rs_.pi_motor = setup_.motor.kind == MotorKind::PI;
    rs_.modes.assign(rs_.n, BallMode::Stick);
    rs_.forces.resize(rs_.n);
    rs_.off_a.assign(rs_.n, 0);
    rs_.off_b.assign(rs_.n, 0);
    nvar_ = lay_.size() + (rs_.pi_motor ? 2 : 0);
    event_driven_ = rs_.opt.method == FrictionMethod::EventDriven;
    w_ = rs_.omega_n;
    t_end_ = end_time_s * w_;
    t_profile_ = ref_.duration_s() * w_;
    out_.end_time_s = end_time_s;
    stops_.reserve(stop_times_s.size());
    for (double s : stop_times_s) stops_.push_back(s * w_);
    L_mm_ = p_.ball_track_radius_m * 1e3;
    traj_dt_ = rs_.opt.trajectory_interval_s * w_;
    if (rs_.pi_motor && rs_.motor.quantize_setpoint_1hz) {
      // The quantised reference is piecewise constant: its step times are among the stop times,
      // and it is held per interval (docs/model.md).
      rs_.ref_held = true;
      hold_reference_after(0.0);
    }

    y_.assign(nvar_, 0.0);
    // Angles relative to the imbalance; an imbalance at angle phi sees the balls at beta - phi.
    for (std::size_t i = 0; i < rs_.n; ++i) y_[lay_.beta(i)] = wrap_angle(beta0[i] - ov.imbalance_angle_rad);
    rs_.contact = p_.ball_contact == BallContact::Hard && rs_.n >= 2;
    if (rs_.contact) {
      // overlapping starts are mapped onto the feasible set (designs do this already)
      std::vector<double> b(beta0);
      if (min_contact_clearance(p_, b) < -1e-12) {
        b = map_onto_contact_feasible_set(p_, b);
        for (std::size_t i = 0; i < rs_.n; ++i) y_[lay_.beta(i)] = wrap_angle(b[i] - ov.imbalance_angle_rad);
      }
      contact_setup(rs_, y_.data());
    }
    choose_initial_modes();
    // The exact stuck-phase propagator (ideal motor, event-driven, no trajectory): the Simulator's
    // table when this run has its omega_n and bbar, else (an uncertain stiffness or imbalance
    // mass) a view of the shared profile samples formed for this run (run_forcing_table.hpp).
    const bool exact = rs_.opt.stuck_integrator == StuckIntegrator::Exact && !rs_.pi_motor && event_driven_ &&
                       !(trajectory_ && traj_dt_ > 0);
    const StuckForcingTable* stuck_table = exact && forcing ? forcing->nominal(rs_.nd) : nullptr;
    if (stuck_table) {
      stuck_.emplace(*stuck_table, rs_, rs_.contact ? roots_contact : roots_plain);
    } else if (exact && forcing && StuckForcingTable::supports(rs_.nd)) {
      run_table_.emplace(forcing->samples(RunForcingTable::damped_frequency(rs_.nd)), rs_.nd);
      stuck_run_.emplace(*run_table_, rs_, rs_.contact ? roots_contact : roots_plain);
    }
  }

  RunOutcome execute();

 private:
  static AbuParameters with_overrides(AbuParameters p, const RunOverrides& ov) {
    if (ov.friction_mu) p.friction_mu = *ov.friction_mu;
    if (ov.imbalance_mass_kg) p.imbalance_mass_kg = *ov.imbalance_mass_kg;
    if (ov.stiffness_N_per_m) p.stiffness_N_per_m = *ov.stiffness_N_per_m;
    if (ov.ball_restitution) p.ball_restitution = *ov.ball_restitution;
    return p;
  }
  void choose_initial_modes();
  bool handle_event(double t);  // false: a guard ended the run (status set)
  void count_event_kinds() const;  // into sim_counters(), from rinfo_ and the modes before the event
  bool count_event(double t);
  void track_all_stuck(double t) {
    if (all_stuck(rs_, y_.data())) {
      if (all_stuck_since_ < 0) all_stuck_since_ = t;
    } else {
      all_stuck_since_ = -1;
    }
  }
  // Quantised reference: hold the value of the interval that starts at tbar (the value at the
  // interval's middle, away from the jumps), and re-choose the modes at a jump.
  void hold_reference_after(double tbar);
  void reference_step(double t);
  void record(double tt, const std::vector<double>& yy);
  RunOutcome finish(const Integrator& integ);

  const SimulationSetup& setup_;
  const StartupProfile& ref_;  // setup_.profile, or its feed-forward setpoint (PI drive)
  AbuParameters p_;  // with the run's overrides applied
  RunState rs_;
  const StateLayout& lay_;
  std::vector<TrajectoryPoint>* trajectory_;
  std::size_t nvar_ = 0;
  bool event_driven_ = true;
  double w_ = 0, t_end_ = 0, t_profile_ = 0, L_mm_ = 0, traj_dt_ = 0;
  std::vector<double> y_;
  RunOutcome out_;
  double peak_amp_ = 0;
  double all_stuck_since_ = -1;
  std::vector<int> rinfo_;
  std::vector<char> fixed_;
  std::deque<double> recent_events_;
  std::vector<double> stops_;  // the Simulator's stop times (tbar), sorted, distinct
  std::optional<StuckPropagator> stuck_;
  std::optional<RunForcingTable> run_table_;
  std::optional<RunStuckPropagator> stuck_run_;
  bool exact_stuck() const { return stuck_ || stuck_run_; }
  StuckPropagatorResult::Result advance_stuck(double& t, std::vector<double>& y, double stop) {
    return stuck_ ? stuck_->advance(t, y, stop, rinfo_, peak_amp_) : stuck_run_->advance(t, y, stop, rinfo_, peak_amp_);
  }
};

void Run::hold_reference_after(double tbar) {
  // next stop after tbar: a reference step or a profile breakpoint (or the profile's end)
  double next = std::max(t_end_, t_profile_) + 1.0;
  const auto it = std::upper_bound(stops_.begin(), stops_.end(), tbar);
  if (it != stops_.end()) next = std::min(next, *it);
  const double mid = 0.5 * (tbar + next) / w_;
  rs_.ref_hold_hz = rs_.motor.realised_reference_hz(ref_.frequency_hz(mid));
}

// At a stop time with the quantised reference: the motor's W' (and with it every stuck ball's
// friction margin) may jump. Re-choose the modes with the new reference, as at a root; the caller
// resets the integrator and the root offsets.
void Run::reference_step(double t) {
  const double old_ref = rs_.ref_hold_hz;
  hold_reference_after(t);
  if (rs_.ref_hold_hz == old_ref || !event_driven_) return;  // the switch model re-chooses per call
  const std::vector<BallMode> before = rs_.modes;
  for (std::size_t i = 0; i < rs_.n; ++i)
    if (rs_.modes[i] == BallMode::Stick) y_[lay_.beta_dot(i)] = 0.0;
  const Speed sp = evaluate_forces(rs_, t, y_.data());
  if (rs_.contact)
    choose_contact_modes(rs_, choice_speed(rs_, t, sp), y_, std::vector<char>(rs_.n, 0));
  else
    rs_.model.choose_modes(y_.data(), sp.W, sp.Wp, rs_.mu, 0.0, rs_.modes.data(), rs_.forces);
  rs_.modes_changed(y_.data());
  if (rs_.modes != before) ++out_.events;
  track_all_stuck(t);
}

// Initial modes from what happens just after t = 0: at rest every force is zero, so decide at a
// tiny time with the rest state (forces then scale alike and the relative test works).
void Run::choose_initial_modes() {
  const double w = w_;
  const double first = ref_.segments().empty() ? 1.0 : ref_.segments()[0].duration_s;
  const double tiny = 1e-6 * first * w;
  std::vector<double> yprobe(y_);
  if (rs_.pi_motor) {
    // the reference has moved a little; the disc has not
    const double fr = reference_hz(rs_, tiny);
    yprobe[lay_.motor_delta()] = 0.25 * kTwoPi * fr / w * tiny;  // delta ~ integral of the reference speed
  }
  Speed sp = rs_.pi_motor ? Speed{0, 0} : ideal_speed(rs_, tiny);
  if (rs_.pi_motor) {
    rs_.modes.assign(rs_.n, BallMode::Stick);
    sp.Wp = evaluate_forces(rs_, tiny, yprobe.data()).Wp;
  }
  if (rs_.contact)
    choose_contact_modes(rs_, choice_speed(rs_, tiny, sp), yprobe, std::vector<char>(rs_.n, 0));
  else
    rs_.model.choose_modes(yprobe.data(), sp.W, sp.Wp, rs_.mu, 0.0, rs_.modes.data(), rs_.forces);
  rs_.modes_changed(y_.data());
}

void Run::record(double tt, const std::vector<double>& yy) {
  TrajectoryPoint tp;
  tp.t_s = tt / w_;
  tp.frequency_hz = rs_.pi_motor ? yy[lay_.motor_speed()] * w_ / kTwoPi : setup_.profile.frequency_hz(tp.t_s);
  tp.x_m = yy[StateLayout::x] * p_.ball_track_radius_m;
  tp.y_m = yy[StateLayout::y] * p_.ball_track_radius_m;
  for (std::size_t i = 0; i < rs_.n; ++i) {
    tp.beta.push_back(wrap_angle(yy[lay_.beta(i)]));
    tp.mode.push_back(static_cast<int>(static_cast<signed char>(rs_.modes[i])));
  }
  trajectory_->push_back(std::move(tp));
}

// A root of the stick/slip functions at t: re-choose the modes, count the event, apply the guards.
void Run::count_event_kinds() const {
  SimCounters& c = sim_counters();
  for (std::size_t i = 0; i < rs_.n; ++i) {
    const bool stuck = rs_.modes[i] == BallMode::Stick;
    if (stuck) {
      c.stick_to_slip += (rinfo_[2 * i] != 0) + (rinfo_[2 * i + 1] != 0);
    } else if (rinfo_[2 * i] != 0) {
      // with contact, the first function of a slipping cluster's inner ball is its contact force
      const bool inner = rs_.contact && rs_.cs.clusters.groups[static_cast<std::size_t>(rs_.cs.group_of[i])].back() != i;
      ++(inner ? c.contact_open : c.slip_stop);
    }
  }
  for (std::size_t k = 2 * rs_.n; k < rinfo_.size(); ++k) c.gap_closed += rinfo_[k] != 0;
}

bool Run::handle_event(double t) {
  count_event_kinds();
  // A slipping ball whose speed reached zero may stick or reverse: a candidate. A stuck ball
  // whose friction margin reached zero leaves stick in the direction of the force needed to
  // hold it (the net force); the others are re-chosen consistently with that.
  std::vector<double>& y = y_;
  if (rs_.contact) {
    out_.impacts += handle_contact_event(rs_, t, y, rinfo_);
    rs_.modes_changed(y.data());
    return count_event(t);
  }
  const Speed sp0 = evaluate_forces(rs_, t, y.data());
  for (std::size_t i = 0; i < rs_.n; ++i) {
    fixed_[i] = 0;
    if (rs_.modes[i] != BallMode::Stick) {
      if (rinfo_[2 * i] != 0) y[lay_.beta_dot(i)] = 0.0;
    } else {
      y[lay_.beta_dot(i)] = 0.0;
      if (rinfo_[2 * i] != 0 || rinfo_[2 * i + 1] != 0) {
        fixed_[i] = 1;
        rs_.modes[i] = rs_.forces.fw[i] > 0 ? BallMode::SlipForward : BallMode::SlipBackward;
      }
    }
  }
  const Speed sp = rs_.pi_motor ? sp0 : ideal_speed(rs_, t);
  rs_.model.choose_modes(y.data(), sp.W, sp.Wp, rs_.mu, 0.0, rs_.modes.data(), rs_.forces, &fixed_);
  rs_.modes_changed(y.data());
  return count_event(t);
}

// Counts an event and applies the guards (chatter, event budget); tracks the all-stuck period.
bool Run::count_event(double t) {
  ++out_.events;
  recent_events_.push_back(t);
  while (!recent_events_.empty() && (t - recent_events_.front()) > rs_.opt.chatter_window_s * w_)
    recent_events_.pop_front();
  if (static_cast<long>(recent_events_.size()) > rs_.opt.chatter_events) {
    out_.status = RunStatus::ChatterLimit;
    out_.message = "more than " + std::to_string(rs_.opt.chatter_events) + " stick/slip events within " +
                   std::to_string(rs_.opt.chatter_window_s) + " s at t = " + std::to_string(t / w_) + " s";
    return false;
  }
  if (out_.events > rs_.opt.max_events) {
    out_.status = RunStatus::EventLimit;
    out_.message = "more than " + std::to_string(rs_.opt.max_events) + " events in all (simulation.max_events)";
    return false;
  }
  track_all_stuck(t);
  return true;
}

RunOutcome Run::execute() {
  // root functions: the event-driven model's, or the switch model's gap closings with contact
  std::unique_ptr<Integrator> integ_ptr = make_integrator(rs_, nvar_, event_driven_ || rs_.contact);
  Integrator& integ = *integ_ptr;
  std::vector<double>& y = y_;
  double t = 0;
  // with contact the offsets go first: reset() evaluates the root functions (a gap shifted after
  // that would start negative and its crossing would never be seen)
  if (rs_.contact) set_root_offsets(rs_, t, y.data());
  integ.reset(t, y);
  if (event_driven_) set_root_offsets(rs_, t, y.data());

  std::vector<double> breaks;
  for (double b : stops_)
    if (b > 0 && b < t_end_) breaks.push_back(b);
  breaks.push_back(t_end_);
  std::size_t next_break = 0;
  integ.set_stop(breaks[0]);

  rinfo_.assign(rs_.nroots(), 0);
  fixed_.assign(rs_.n, 0);
  all_stuck_since_ = all_stuck(rs_, y.data()) ? 0.0 : -1.0;
  double next_tail_check = t_profile_;
  double next_traj = 0;
  const bool tracing = trajectory_ && traj_dt_ > 0;
  std::vector<double> ytraj(nvar_);
  if (tracing) {
    record(0, y);
    next_traj = traj_dt_;
  }

  const bool tail_enabled = event_driven_ && rs_.opt.closed_form_tail && !tracing;
  bool integ_stale = false;  // the exact propagator moved (t, y): the stepper restarts from there
  unsigned long passes = 0;
  while (t < t_end_) {
    // the stop request (SIGINT / SIGTERM, common/stop.hpp): a run can take seconds (chatter, a
    // long end time), so it ends here too, not only between runs; the batch runner then reports
    // the interruption and no outcome of this run is kept
    if ((++passes & 255u) == 0 && stop_requested()) throw Interrupted("interrupted by " + stop_signal_name());
    Integrator::Result res = Integrator::Ok;
    if (exact_stuck() && rs_.frozen) {
      // every ball stuck: the exact propagator, to the next stop time (a breakpoint, the end, or
      // the next attempt of the closed-form tail) or the next stick -> slip root
      double stop = next_break < breaks.size() ? breaks[next_break] : t_end_;
      if (tail_enabled && t >= t_profile_ && next_tail_check > t) stop = std::min(stop, next_tail_check);
      const StuckPropagator::Result r = advance_stuck(t, y, stop);
      if (r == StuckPropagator::NotFinite) {
        out_.status = RunStatus::SolverFailure;
        out_.message = "state not finite (exact stuck-phase propagator) at t = " + std::to_string(t / w_) + " s";
        break;
      }
      if (r == StuckPropagator::Root) res = Integrator::Root;
      integ_stale = true;
    } else {
      if (integ_stale) {
        integ.reset(t, y);
        integ_stale = false;
      }
      res = integ.step(t, y, rinfo_);
      if (res == Integrator::Failure) {
        out_.status = integ.too_much_work() ? RunStatus::StepLimit : RunStatus::SolverFailure;
        out_.message = integ.failure() + " at t = " + std::to_string(t / w_) + " s";
        break;
      }
      if (tracing) {
        while (next_traj <= t && next_traj <= t_end_) {
          integ.dense(next_traj, ytraj);
          record(next_traj, ytraj);
          next_traj += traj_dt_;
        }
      }
      peak_amp_ = std::max(peak_amp_, std::hypot(y[StateLayout::x], y[StateLayout::y]) * L_mm_);

      if (!event_driven_) {
        // switch model: track the all-stuck period at step ends
        switch_modes(rs_, t, y.data());
        track_all_stuck(t);
      }
    }

    bool reset_needed = false;
    if (res == Integrator::Root) {
      if (!handle_event(t)) break;
      reset_needed = true;
    }
    if (next_break < breaks.size() && t >= breaks[next_break]) {
      ++next_break;
      if (next_break < breaks.size()) integ.set_stop(breaks[next_break]);
      if (rs_.ref_held && t < t_end_) {
        reference_step(t);
        reset_needed = true;
      }
    }
    if (t >= t_end_) break;

    if (tail_enabled && t >= t_profile_ && t >= next_tail_check && all_stuck_since_ >= 0) {
      const bool done = rs_.pi_motor
                            ? closed_form_tail_pi(rs_, t, y, t_end_, peak_amp_, rs_.contact ? roots_contact : roots_plain)
                            : closed_form_tail(rs_, t, y, t_end_, peak_amp_);
      if (done) {
        t = t_end_;
        break;
      }
      next_tail_check = t + 0.5 * w_;  // the transient decays; try again later
    }
    if (reset_needed) {
      if (rs_.contact) set_root_offsets(rs_, t, y.data());
      integ.reset(t, y);
      integ_stale = false;
      set_root_offsets(rs_, t, y.data());
    }
  }
  return finish(integ);
}

RunOutcome Run::finish(const Integrator& integ) {
  out_.steps = integ.steps() + (stuck_ ? stuck_->intervals() : 0) + (stuck_run_ ? stuck_run_->intervals() : 0);
  out_.rhs_evaluations = rs_.rhs_evals;
  out_.max_amplitude_mm = peak_amp_;
  for (std::size_t i = 0; i < rs_.n; ++i) out_.beta_final.push_back(wrap_angle(y_[lay_.beta(i)]));
  double ix = 0, iy = 0;
  AbuModel::imbalance_vector(p_, out_.beta_final.data(), ix, iy);
  out_.residual_imbalance_kgm = std::hypot(ix, iy);
  out_.residual_imbalance_x_kgm = std::fabs(ix);
  out_.settled = out_.ok() && all_stuck(rs_, y_.data());
  out_.settling_time_s = out_.settled ? all_stuck_since_ / w_ : 0.0;
  if (rs_.contact) out_.min_contact_clearance_rad = min_contact_clearance(p_, out_.beta_final);
  return out_;
}

}  // namespace

RunOutcome Simulator::run(const std::vector<double>& beta0, const RunOverrides& ov,
                          std::vector<TrajectoryPoint>* trajectory) const {
  const auto wall0 = std::chrono::steady_clock::now();
  if (beta0.size() != setup_.abu.balls.size())  // API misuse: the caller sizes beta0 from ball_count()
    throw std::invalid_argument("Simulator::run: the ABU has " + std::to_string(setup_.abu.balls.size()) +
                                " balls, but " + std::to_string(beta0.size()) + " initial angles were given");
  if ((ov.stiffness_N_per_m && !(*ov.stiffness_N_per_m > 0 && std::isfinite(*ov.stiffness_N_per_m))) ||
      (ov.imbalance_mass_kg && !(*ov.imbalance_mass_kg >= 0 && std::isfinite(*ov.imbalance_mass_kg))) ||
      (ov.ball_restitution && !(*ov.ball_restitution >= 0 && *ov.ball_restitution <= 1)))
    // the abu section's rules: stiffness > 0, imbalance mass >= 0 (a balanced rotor is a valid ABU)
    throw std::invalid_argument("Simulator::run: an override is out of range (stiffness > 0, imbalance mass >= 0, "
                                "restitution in [0, 1])");
  Run run(setup_, end_time_s(), beta0, ov, trajectory, forcing_.get(), reference_ ? *reference_ : setup_.profile,
          stop_times_s_);
  RunOutcome out = run.execute();
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return out;
}

}  // namespace abuopt
