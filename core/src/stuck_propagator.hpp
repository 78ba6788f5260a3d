#pragma once
// Exact propagation of the table while every ball is stuck (ideal motor, event-driven; derivation
// in docs/stuck_propagator.md). With beta_i' = beta_i'' = 0 the table rows are linear in
// z = xbar + i ybar; in the fixed frame Z = z e^{i phi} they are time-invariant with a known force:
//
//   Z'' + 2 bbar Z' + Z = C g(tbar),   g = (W^2 - i W') e^{i phi} = -(e^{i phi})'',
//   C = mbar_I ebar + sum_i mbar_i e^{i beta_i}   (constant while the balls stick).
//
// In modal coordinates (Z = a_1 + a_2, Z' = lambda_1 a_1 + lambda_2 a_2, lambda = -bbar +- i wd)
//   a_k(t + h) = e^{lambda_k h} a_k(t) + C P_k(t, h),
//   P_k(t, h) = rho_k int_0^h e^{lambda_k (h - s)} g(t + s) ds,  rho_1 = -rho_2 = 1/(lambda_1 - lambda_2).
// P_k depends on the profile and the table only, not on the balls: StuckForcingTable computes it
// once per Simulator on a grid (Gauss-Legendre quadrature; closed form at constant speed), shared
// by every run. A run then costs two complex multiply-adds per grid interval plus the stick
// margins at the grid points, which are the checks for stick -> slip events; a sign change is
// located by Illinois on the exact solution between grid points (P_k over a partial interval by
// the same quadrature). The grid spacing is half a period of the fastest oscillation of the
// margins (W + wd in the disc frame), so event checks are at least as dense as the 7(8) steps.
#include <complex>
#include <memory>
#include <vector>

#include "abuopt/core/abu_model.hpp"
#include "abuopt/core/profile.hpp"
#include "erk_stepper.hpp"
#include "sim_run_state.hpp"

namespace abuopt::detail {

using cplx = std::complex<double>;

// The forcing integrals of one profile and table (read-only after construction, shared by runs).
class StuckForcingTable {
 public:
  // t_end_bar: the end time of the runs (non-dimensional). Throws std::invalid_argument when the
  // table is not a damped oscillator with two distinct modes (bbar <= 0 or bbar == 1): the caller
  // then keeps the Runge-Kutta path.
  StuckForcingTable(const StartupProfile& profile, const NondimParameters& nd, double t_end_bar);
  static bool supports(const NondimParameters& nd);
  // The table of (profile, omega_n, bbar, t_end_bar) from a process-wide cache of the last
  // kSharedTables built, or a new one (then cached). A Monte Carlo evaluation builds one
  // Simulator, and so one table (~18M instructions for the final profile, about two runs);
  // studies evaluate the same profile and table again and again (other friction, imbalance
  // angles or seeds; repeated design points), which then share it. Thread-safe; the table is
  // built outside the lock.
  static std::shared_ptr<const StuckForcingTable> shared(const StartupProfile& profile, const NondimParameters& nd,
                                                         double t_end_bar);
  static constexpr std::size_t kSharedTables = 4;
  // The table applies to a run whose non-dimensional constants of the table rows are these.
  bool matches(const NondimParameters& nd) const { return nd.omega_n == omega_n_ && nd.bbar == bbar_; }

  std::size_t intervals() const { return t_.size() - 1 + tail_n_; }
  double t(std::size_t j) const;
  // Interval j with t_j <= tbar < t_{j+1} (the last one for tbar >= its end).
  std::size_t interval(double tbar) const;
  const cplx& lambda(int k) const { return lam_[k]; }
  const cplx& rho(int k) const { return rho_[k]; }
  // Grid values: e^{lambda_k (t_{j+1} - t_j)}, P_k over interval j, e^{-i phi(t_j)}, W(t_j).
  // The profile's segments are stored (at most kMaxStoredIntervals intervals, ~100 B each); the
  // constant-speed span after the profile is not: its values are computed from its closed form
  // when asked, so the table's memory does not grow with the end time.
  cplx decay(int k, std::size_t j) const;
  cplx forcing(int k, std::size_t j) const;
  cplx unrotate(std::size_t j) const;
  double speed(std::size_t j) const;
  double speed_rate(std::size_t j) const;
  // Above this many stored intervals (a very long profile) the constructor throws
  // std::invalid_argument and the simulator keeps the Runge-Kutta path (bounded memory).
  static constexpr std::size_t kMaxStoredIntervals = std::size_t{1} << 19;

  // W, W' and e^{i phi} at any tbar (from the profile).
  void sample(double tbar, double& W, double& Wp, cplx& eiphi) const;
  // P_k(t0, h) for any 0 <= h (Gauss-Legendre; exact enough for h up to a grid interval).
  void partial(double t0, double h, cplx P[2]) const;

 private:
  bool same(const StartupProfile& profile, const NondimParameters& nd, double t_end_bar) const;

  StartupProfile profile_;  // a copy: the Simulator that owns the table may move
  double t_end_bar_ = 0;
  double omega_n_ = 0, bbar_ = 0;
  cplx lam_[2], rho_[2];
  std::vector<double> gl_x_, gl_w_;  // Gauss-Legendre nodes on [0, 1] and weights (sum 1)
  std::vector<double> t_, W_, Wp_;
  std::vector<cplx> E_, P_, rot_;
  // The constant-speed tail [tail_a_, t_end_bar_]: tail_n_ intervals of tail_h_ (the last one
  // ends at t_end_bar_), speed tail_W_, e^{i phi(tail_a_)} = tail_e0_, per-interval E and P / e^{i phi}.
  std::size_t tail_n_ = 0;
  double tail_a_ = 0, tail_h_ = 0, tail_W_ = 0;
  cplx tail_e0_, tail_E_[2], tail_Fc_[2];
  cplx tail_last_E_[2], tail_last_P_[2], tail_end_rot_;
  double tail_end_W_ = 0, tail_end_Wp_ = 0;
};

// Gauss-Legendre nodes on [0, 1] and their weights (sum 1), m nodes.
void gauss_legendre(int m, std::vector<double>& x, std::vector<double>& w);

struct StuckPropagatorResult {
  enum Result { Stop, Root, NotFinite };
};

// One run's use of the table: from a state with every ball stuck, advance to a stop time or to the
// earliest root of the stick functions (the integrator's root functions, offsets included).
// Table: StuckForcingTable (the Simulator's, shared: runs with its omega_n and bbar) or
// RunForcingTable (run_forcing_table.hpp: a run with its own, e.g. an uncertain stiffness).
template <class Table>
class StuckPropagatorT : public StuckPropagatorResult {
 public:
  StuckPropagatorT(const Table& tab, RunState& rs, RootFn g);
  // On Root: t and y are at the root (on the far side of the crossing, as the stepper's roots),
  // roots[k] != 0 marks the functions that crossed. NotFinite: the state is not finite (NaN or
  // inf, e.g. from a non-finite angle); t and y are where it was found. The peak table amplitude [mm] over the grid
  // points passed is folded into peak_amp_mm.
  Result advance(double& t, std::vector<double>& y, double tstop, std::vector<int>& roots, double& peak_amp_mm);
  long intervals() const { return intervals_; }

 private:
  void to_modal(double t, const double* y);
  void state_at(double t0, const cplx a0[2], double t, double* y) const;  // rotating-frame table state
  void from_modal(const cplx a[2], double W, const cplx& rot, double* y) const;
  void margins(double W, double Wp, const double* y, double* g);
  double locate(std::size_t k, double ta, double ga, double tb, double gb, const cplx a0[2], double t0);

  const Table& tab_;
  RunState& rs_;
  RootFn g_;
  cplx C_;
  std::vector<cplx> e_;  // e^{i beta_i} of the stuck balls
  cplx a_[2];
  std::vector<double> ywork_, g0_, g1_, gtmp_;
  long intervals_ = 0;
  double L_mm_ = 0;
};

using StuckPropagator = StuckPropagatorT<StuckForcingTable>;
class RunForcingTable;
using RunStuckPropagator = StuckPropagatorT<RunForcingTable>;

}  // namespace abuopt::detail
