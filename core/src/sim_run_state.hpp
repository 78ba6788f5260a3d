#pragma once
// Internal to the simulator: the state of one run (the integrators' user data) and the functions
// the integrators call: right-hand side and root functions (sim_rhs.cpp), the closed-form tail
// (closed_form_tail.cpp). See simulator.cpp for the event logic and docs/model.md for the maths.
#include <cmath>
#include <vector>

#include "abuopt/core/abu_model.hpp"
#include "abuopt/core/ball_contact.hpp"
#include "abuopt/core/simulator.hpp"

namespace abuopt::detail {

constexpr double kTwoPi = 2.0 * M_PI;

inline double wrap_angle(double a) {
  double r = std::fmod(a, kTwoPi);
  if (r < 0) r += kTwoPi;
  if (r >= kTwoPi) r = 0;
  return r;
}

// Hard ball-ball contact of one run (docs/model.md section 11; sim_contact.cpp).
struct ContactState {
  ContactGeometry geo;        // cyclic order and least spacings (fixed for the run)
  std::vector<char> closed;   // per neighbour pair: the two balls move as one cluster
  Clusters clusters;          // built from `closed`
  std::vector<int> group_of;  // ball -> cluster index
  std::vector<double> off_gap, off_lambda;  // root offsets (see set_root_offsets)
  double restitution = 0;
  double v_stop = 0;          // relative approach speed below which an impact is plastic
  long impacts = 0;
  double max_correction = 0;  // largest position correction of a negative gap at an event [rad]
};

// Everything one run needs; ARKODE's user data.
struct RunState {
  AbuParameters params;  // with the run's overrides applied
  NondimParameters nd;
  AbuModel model;
  const StartupProfile* profile = nullptr;
  MotorModel motor;
  SimulationOptions opt;
  double mu = 0;
  double omega_n = 0;
  std::size_t n = 0;
  std::size_t nstate = 0;  // ABU states (+2 motor states for the PI model)
  bool pi_motor = false;
  std::vector<BallMode> modes;
  ModelForces forces;
  std::vector<double> off_a, off_b;
  long rhs_evals = 0;
  // Fast path while every ball is stuck (event-driven, ideal motor): beta' = beta'' = 0, so the
  // table rows reduce to x'' = -h_x, y'' = -h_y with the ball sums sum mbar_i (c_i, s_i) fixed.
  // The full evaluation is still used for the root functions (they need fn, fw).
  bool frozen = false;
  double frozen_sc = 0, frozen_ss = 0;
  // PI motor with a quantised setpoint: the reference is piecewise constant and is held at the
  // value of the current interval between its step times, which are stop times of the
  // integration (simulator.cpp), so no step straddles a jump of the right-hand side.
  bool ref_held = false;
  double ref_hold_hz = 0;
  bool contact = false;  // hard ball-ball contact (two or more balls)
  ContactState cs;
  // switch model with contact: the choice of each right-hand-side call works on a copy of the
  // state (scratch, kept to avoid allocations) and with no forced clusters
  std::vector<double> switch_y;
  std::vector<char> switch_forced, switch_closed;

  const StateLayout& lay() const { return model.layout(); }
  // Root functions: two per ball; with contact one more per neighbour pair (the gaps).
  std::size_t nroots() const { return 2 * n + (contact ? cs.geo.pairs() : 0); }
  // The model's forces for the current modes (and clusters, with contact).
  void eval(const double* y, double W, double Wp) {
    if (contact)
      model.evaluate_clusters(y, W, Wp, modes.data(), cs.clusters, mu, forces);
    else
      model.evaluate(y, W, Wp, modes.data(), mu, forces);
  }

  explicit RunState(const AbuParameters& p) : params(p), nd(NondimParameters::from(p)), model(nd) {}

  // Call whenever the modes change (event-driven only).
  void modes_changed(const double* y) {
    frozen = !pi_motor && opt.method == FrictionMethod::EventDriven;
    frozen_sc = frozen_ss = 0;
    for (std::size_t i = 0; i < n && frozen; ++i) {
      frozen = modes[i] == BallMode::Stick;
      frozen_sc += nd.mbar[i] * std::cos(y[lay().beta(i)]);
      frozen_ss += nd.mbar[i] * std::sin(y[lay().beta(i)]);
    }
  }
};

struct Speed {
  double W = 0, Wp = 0;
};

// The table speed a mode choice judges its trials with. With the PI drive and its friction
// feedback, W' depends on the balls' friction and so on the modes being chosen: each trial then
// takes W' from the motor equation at tbar with its own modes (evaluate_forces; docs/model.md
// 11.12). Otherwise W and W' are those given; the switch model, which re-chooses at every
// right-hand-side call, always takes them as given.
struct ChoiceSpeed {
  double W = 0, Wp = 0;
  bool wp_from_modes = false;
  double tbar = 0;
};
inline ChoiceSpeed choice_speed(const RunState& rs, double tbar, const Speed& sp) {
  return {sp.W, sp.Wp, rs.pi_motor && rs.motor.friction_feedback, tbar};
}

inline Speed ideal_speed(const RunState& rs, double tbar) {
  const ProfileSample s = rs.profile->sample(tbar / rs.omega_n);
  return {kTwoPi * s.frequency_hz / rs.omega_n, kTwoPi * s.rate_hz_per_s / (rs.omega_n * rs.omega_n)};
}

// The reference frequency [Hz] the PI motor follows at tbar.
inline double reference_hz(const RunState& rs, double tbar) {
  if (rs.ref_held) return rs.ref_hold_hz;
  return rs.motor.realised_reference_hz(rs.profile->frequency_hz(tbar / rs.omega_n));
}

// Evaluates forces for the current modes into rs.forces and returns the speed used (sim_rhs.cpp).
Speed evaluate_forces(RunState& rs, double tbar, const double* y);
// Switch model: chooses the modes (with contact: and the clusters) at every right-hand-side call.
void switch_modes(RunState& rs, double tbar, const double* y);
// True for the switch model (simulation.method: switch_model).
inline bool switch_model(const RunState& rs) { return rs.opt.method == FrictionMethod::SwitchModel; }
// Right-hand side and root functions with the native stepper's signatures.
void rhs_plain(double tbar, const double* y, double* yd, void* user);
void roots_plain(double tbar, const double* y, double* g, void* user);
// Shifts the stick margins that start negative (by rounding) so their crossing is still seen.
void set_root_offsets(RunState& rs, double tbar, const double* y);
bool all_stuck(const RunState& rs, const double* y);

// Hard contact (sim_contact.cpp): setup at the start of a run, root functions, root offsets, and
// the event step (impacts, then one consistent choice of clusters and modes).
void contact_setup(RunState& rs, const double* y);
void roots_contact(double tbar, const double* y, double* g, void* user);
// The rates of the contact root functions where known: d gap_k / dtbar for open pairs, 0 for the
// rest (the stepper's dip check, erk_stepper.hpp).
void root_rates_contact(double tbar, const double* y, double* gd, void* user);
// The slipping clusters' stop functions' rates from the right-hand side dydt, 0 for the rest (the
// dip check only, docs/model.md 11.11).
void stop_rates_contact(double tbar, const double* y, const double* dydt, double* gd, void* user);
void set_contact_root_offsets(RunState& rs, double tbar, const double* y);
// Chooses clusters and modes at an instant: balls at zero relative speed and zero gap may form or
// leave clusters, clusters at zero speed may stick or slip. forced[i] != 0: the cluster of ball i
// was stuck and one of its margins crossed zero (it must not stay stuck whole), forward
// (kForcedForward: a block slips forward) and/or backward (kForcedBackward).
constexpr char kForcedForward = 1, kForcedBackward = 2;
// Method: Auto pivots (docs/model.md 11.8) and enumerates every joint option when pivoting finds
// no consistent choice; Pivot and Enumerate (the reference) only for tests; Compare is Auto that
// also enumerates on a copy and counts the choices that differ (sim_counters().mode_differs).
enum class ContactChoiceMethod { Auto, Pivot, Enumerate, Compare };
struct ContactChoiceResult {
  bool consistent = false;  // the choice meets every condition of 11.5
  int pivots = 0;           // flips of the active set
  bool enumerated = false;  // Auto: pivoting failed and the enumeration chose
};
// The method of the simulator's runs on this thread (Auto; tests and benchmarks compare it with
// Enumerate, the choice before pivoting).
ContactChoiceMethod& run_contact_choice();
// band: clusters with |speed| <= band count as at rest (may stick); 0 for the event-driven
// model, simulation.switch_band for the switch model (docs/model.md 8.1).
ContactChoiceResult choose_contact_modes(RunState& rs, const ChoiceSpeed& sp, std::vector<double>& y,
                                         const std::vector<char>& forced,
                                         ContactChoiceMethod method = run_contact_choice(), double band = 0.0);
// Switch model with contact (docs/model.md 8.1): the clusters and modes of one right-hand-side
// call, chosen on a copy of y with clusters at |speed| <= switch_band at rest; a contact it cuts
// gets its gap's root offset (the gap starts at zero).
void switch_contact_modes(RunState& rs, const ChoiceSpeed& sp, const double* y);
// Applies the roots found at an event: impacts for closing gaps, zero speed for clusters that
// stopped; then choose_contact_modes. Returns the number of impacts.
int handle_contact_event(RunState& rs, double tbar, std::vector<double>& y, const std::vector<int>& rinfo);
// After the profile, with every ball stuck and an ideal motor: finishes the run in closed form
// when a bound proves no ball can slip again (closed_form_tail.cpp).
bool closed_form_tail(RunState& rs, double tbar, std::vector<double>& y, double tbar_end, double& peak_amp);
// The same under the PI drive: the linearisation of table and motor about their equilibrium at the
// constant reference, the run's own root functions `roots` bounded with a reserve of half of every
// margin for the neglected second-order terms (closed_form_tail.cpp, docs/model.md 6.1).
bool closed_form_tail_pi(RunState& rs, double tbar, std::vector<double>& y, double tbar_end, double& peak_amp,
                         void (*roots)(double, const double*, double*, void*));

}  // namespace abuopt::detail
