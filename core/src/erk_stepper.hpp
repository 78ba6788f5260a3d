#pragma once
// A lean explicit Runge-Kutta stepper with an embedded error estimate, dense output and root
// location, for small ODE systems whose right-hand side costs less than a SUNDIALS step's
// bookkeeping (our ABU right-hand side takes ~50 ns; ARKODE's per-step overhead was ~5 us).
// The Butcher tables are SUNDIALS ARKODE's (loaded by name), so both backends integrate with the
// same coefficients; only the bookkeeping differs.
//
// Root functions follow SUNDIALS' convention: a root of g_k is a sign change over a step; a g_k
// that is exactly zero at the start of a step is ignored for that step. Root times are found on
// the step's cubic Hermite interpolant (Illinois), then the state at the root is computed by a
// fresh Runge-Kutta step from the step's start, so the state at an event has the method's
// accuracy, not the interpolant's.
#include <cstddef>
#include <string>
#include <vector>

#include "abuopt/core/sim_counters.hpp"

namespace abuopt::detail {

struct ButcherTable {
  int stages = 0, order = 0, embedded_order = 0;
  std::vector<double> A;  // stages x stages, row-major
  std::vector<double> b, c, d;
  // Loads an ARKODE explicit table by name (e.g. "ARKODE_FEHLBERG_13_7_8"); throws
  // std::invalid_argument for an unknown name.
  static ButcherTable from_arkode(const std::string& name);
};

using RhsFn = void (*)(double t, const double* y, double* dydt, void* user);
using RootFn = void (*)(double t, const double* y, double* g, void* user);
// Rates of root functions computed from the state and its derivative dydt = f(t, y) (e.g. a
// function that is a state component: its rate is that component of f).
using RateFn = void (*)(double t, const double* y, const double* dydt, double* gd, void* user);

// A located event's gap error allowed, as a fraction of the absolute state tolerance atol
// (docs/model.md 11.9): the time tolerance of a gap's root is atol * kEventGapTol / |its rate|.
constexpr double kEventGapTol = 1e-3;

class ErkStepper {
 public:
    // NotFinite: the state, its derivative or the step size is not finite (NaN or inf): the run
  // cannot continue (a step from such a state would otherwise shrink or repeat forever).
  enum Status { Ok = 0, Root = 1, StopReached = 2, StepTooSmall = -1, TooManySteps = -2, NotFinite = -3 };

  ErkStepper(ButcherTable table, std::size_t n, RhsFn f, RootFn g, std::size_t nroots, void* user, double rtol,
             double atol, long max_steps);

  // Restarts at (t, y); keeps the current step size as the first guess.
  void reset(double t, const double* y);
  void set_stop_time(double t) { tstop_ = t; }
  // Polished roots: each crossing found on the interpolant is refined on the Runge-Kutta solution
  // itself (Illinois, one fresh step from the step's start per iteration), so root times get the
  // method's accuracy instead of the interpolant's, and the earliest crossing wins. Off by
  // default (the no-contact model keeps its published numbers); on for hard ball contact.
  void set_polish_roots(bool on) { polish_ = on; }
  // Rates dg_k/dt of the root functions where known (0 for the others). A function that moves
  // towards zero at a step's start and away from it at the end may dip through zero and back
  // inside the step (two crossings: no sign change at the ends). With rates, the stepper finds the
  // extremum of such a function on the step's cubic Hermite interpolant, which is exact for
  // functions linear in the state (ball-ball gaps), and if the extremum is across zero on the
  // Runge-Kutta solution, the crossing before it is a root like any other.
  void set_root_rates(RootFn gd) { gd_ = gd; }
  // Rates from the right-hand side, for the dip check only (docs/model.md 11.11): at the step's
  // ends f is known (the step's start and its FSAL end), so they cost no extra evaluation. These
  // functions are not polished by Newton (their rate at an inner time would need f there); a dip
  // found with them is refined like a function without rate. gd_ and dr_ fill disjoint entries
  // (0 for the functions they do not know).
  void set_dip_rates(RateFn dr) { dr_ = dr; }
  // Takes one accepted step (never past the stop time). On Root, t()/y() are at the earliest
  // root and roots_found()[k] != 0 marks the functions that crossed there.
  Status step();
  double t() const { return t_; }
  const std::vector<double>& y() const { return y_; }
  const std::vector<int>& roots_found() const { return found_; }
  // Cubic Hermite interpolation on the last accepted step [t_prev, t].
  void dense(double t, double* out) const;
  long steps() const { return steps_; }
  long rhs_calls() const { return nf_; }

 private:
  // One RK step of size h from (t0, y0, f0): high-order result into yout, error norm returned.
  double attempt(double t0, const double* y0, const double* f0, double h, double* yout);
  // Root of g_k in [ta, tb] (g_k(ta) = ga, g_k(tb) = gb of opposite signs) on RK steps from tprev.
  // With rates (gd_): functions that dip through zero and back inside the step get the bracket
  // [tprev, their extremum] (bt_, bg_).
  void find_dips();
  // hint: the root on the interpolant (the first trial point). Functions with a known rate (gd_)
  // by Newton's method to a derived time tolerance, the others by refine_crossing to 2 ulp.
  double polish(std::size_t k, double ta, double ga, double tb, double gb, double hint);
  bool polish_ = false;
  // The Runge-Kutta state at tc by one step from the step's start, into ycache_ (reused when tc
  // is the last time asked for in this step). Returns tc.
  double state_at(double tc);
  std::vector<double> ycache_, gdtmp_;
  double tcache_ = 0;
  bool cache_valid_ = false;
  double initial_step() ;

  ButcherTable tab_;
  // Nonzero entries only (Fehlberg 7(8) has 41 of 78 in A, 5 of 13 in b, 3 of 13 in b - d).
  struct Term {
    int stage;
    double coef;
  };
  std::vector<std::vector<Term>> a_terms_;  // per stage
  std::vector<Term> b_terms_, e_terms_;     // solution weights, error weights (b - d)
  std::size_t n_, nroots_;
  RhsFn f_;
  RootFn g_;
  void* user_;
  double rtol_, atol_;
  long max_steps_;
  double t_ = 0, h_ = 0, tstop_ = 1e300, tprev_ = 0;
  std::vector<double> y_, f0_, yprev_, fprev_, ynew_, k_, tmp_, err_;
  std::vector<double> g0_, g1_, gtmp_, groot_, hint_;
  RootFn gd_ = nullptr;
  std::vector<double> gd0_, gd1_;  // root function rates at the step's ends (with gd_)
  RateFn dr_ = nullptr;
  std::vector<double> dr0_, dr1_;  // rates from f at the step's ends (with dr_)
  std::vector<double> bt_, bg_;    // per function: the end of its bracket [tprev, bt] and g there
  std::vector<std::size_t> order_;
  std::vector<int> found_;
  long steps_ = 0, nf_ = 0;
  SimCounters& ctr_;    // this thread's counters (sim_counters.hpp)
  int since_reset_ = 0;  // accepted steps since the last reset
};

}  // namespace abuopt::detail
