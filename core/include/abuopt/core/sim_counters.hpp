#pragma once
// Per-thread counters of the simulator's internal work, for benchmarks and profiling (bench/,
// docs/performance.md): which kinds of events the runs meet and where their right-hand sides go.
// Every run on the calling thread adds to them; reset with `abuopt::sim_counters() = {};`.
// Not part of a run's outcome: they cost one increment per event or step.
namespace abuopt {

struct SimCounters {
  // Root functions that crossed zero at an event (an event can have several).
  long stick_to_slip = 0;  // a stuck ball's (or stuck cluster's) friction margin
  long slip_stop = 0;      // a slipping ball's (or cluster's) speed reached zero
  long gap_closed = 0;     // hard contact: the gap of a neighbour pair closed
  long contact_open = 0;   // hard contact: the contact force inside a slipping cluster reached zero
  // Runge-Kutta stepper (native back end): right-hand sides by purpose.
  long resets = 0;            // restarts (after events, stop times and exact all-stuck phases)
  long rhs_accepted = 0;      // stages of accepted steps and the derivative at their ends
  long rhs_rejected = 0;      // stages of rejected step attempts
  long rhs_root = 0;          // the state at a root (and the polished roots' iterations)
  long rhs_after_reset = 0;   // of rhs_accepted + rhs_rejected: the first two steps after a restart
  long root_evaluations = 0;  // evaluations of the root functions (each costs about one RHS)
  long polishes = 0;          // roots refined on the Runge-Kutta solution (hard contact)
  long polish_steps = 0;      // the Runge-Kutta steps those refinements took
  long dips = 0;              // hard contact: gaps (or stops, 11.11) that crossed and back inside one step
  // hard contact: the largest overlap (negative gap) projected away at an event [rad] (11.5: at
  // most ~1e-12 when every event is located; docs/model.md 11.10 - 11.11)
  double max_gap_correction = 0;
  // Hard contact: choices of clusters and modes at events (sim_contact_modes.cpp), the flips of
  // the pivoting, and the choices where pivoting failed and every joint option was enumerated.
  long mode_choices = 0;
  long mode_pivots = 0;
  long mode_fallbacks = 0;
  // ContactChoiceMethod::Compare only: choices where the enumeration chose otherwise, and where
  // the enumeration found a consistent option.
  long mode_differs = 0;
  long mode_enum_consistent = 0;
};

SimCounters& sim_counters();

}  // namespace abuopt
