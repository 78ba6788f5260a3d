#include "erk_stepper.hpp"

#include "root_refine.hpp"

#include <arkode/arkode_butcher.h>
#include <arkode/arkode_butcher_erk.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace abuopt::detail {

ButcherTable ButcherTable::from_arkode(const std::string& name) {
  ARKodeButcherTable B = ARKodeButcherTable_LoadERKByName(name.c_str());
  if (!B) throw std::invalid_argument("unknown ARKODE explicit table '" + name + "'");
  if (!B->d) {
    ARKodeButcherTable_Free(B);
    throw std::invalid_argument("ARKODE table '" + name + "' has no embedding (no error estimate)");
  }
  ButcherTable t;
  t.stages = B->stages;
  t.order = B->q;
  t.embedded_order = B->p;
  t.A.assign(static_cast<std::size_t>(t.stages * t.stages), 0.0);
  for (int i = 0; i < t.stages; ++i)
    for (int j = 0; j < t.stages; ++j) t.A[static_cast<std::size_t>(i * t.stages + j)] = B->A[i][j];
  t.b.assign(B->b, B->b + t.stages);
  t.c.assign(B->c, B->c + t.stages);
  t.d.assign(B->d, B->d + t.stages);
  ARKodeButcherTable_Free(B);
  return t;
}

ErkStepper::ErkStepper(ButcherTable table, std::size_t n, RhsFn f, RootFn g, std::size_t nroots, void* user,
                       double rtol, double atol, long max_steps)
    : tab_(std::move(table)), n_(n), nroots_(nroots), f_(f), g_(g), user_(user), rtol_(rtol), atol_(atol),
      max_steps_(max_steps), ctr_(sim_counters()) {
  const std::size_t s = static_cast<std::size_t>(tab_.stages);
  a_terms_.resize(s);
  for (int i = 0; i < tab_.stages; ++i)
    for (int j = 0; j < i; ++j) {
      const double a = tab_.A[static_cast<std::size_t>(i * tab_.stages + j)];
      if (a != 0.0) a_terms_[static_cast<std::size_t>(i)].push_back({j, a});
    }
  for (int j = 0; j < tab_.stages; ++j) {
    const double b = tab_.b[static_cast<std::size_t>(j)], e = b - tab_.d[static_cast<std::size_t>(j)];
    if (b != 0.0) b_terms_.push_back({j, b});
    if (e != 0.0) e_terms_.push_back({j, e});
  }
  y_.resize(n);
  f0_.resize(n);
  yprev_.resize(n);
  fprev_.resize(n);
  ynew_.resize(n);
  k_.resize(s * n);
  tmp_.resize(n);
  err_.resize(n);
  g0_.resize(nroots);
  g1_.resize(nroots);
  groot_.resize(nroots);
  hint_.resize(nroots);
  gd0_.assign(nroots, 0.0);
  gd1_.assign(nroots, 0.0);
  dr0_.assign(nroots, 0.0);
  dr1_.assign(nroots, 0.0);
  bt_.resize(nroots);
  bg_.resize(nroots);
  gtmp_.resize(nroots);
  gdtmp_.assign(nroots, 0.0);
  ycache_.resize(n);
  found_.assign(nroots, 0);
}

void ErkStepper::reset(double t, const double* y) {
  t_ = t;
  std::copy(y, y + n_, y_.begin());
  f_(t_, y_.data(), f0_.data(), user_);
  ++nf_;
  ++ctr_.resets;
  since_reset_ = 0;
  cache_valid_ = false;
  if (g_ && nroots_) {
    g_(t_, y_.data(), g0_.data(), user_);
    ++ctr_.root_evaluations;
    if (gd_) gd_(t_, y_.data(), gd0_.data(), user_);
    if (dr_) dr_(t_, y_.data(), f0_.data(), dr0_.data(), user_);
  }
  if (h_ <= 0) h_ = initial_step();
  tprev_ = t_;
  yprev_ = y_;
  fprev_ = f0_;
}

double ErkStepper::initial_step() {
  // Hairer-Norsett-Wanner's starting step heuristic (first-order part only).
  double d0 = 0, d1 = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    const double sc = atol_ + rtol_ * std::fabs(y_[i]);
    d0 += (y_[i] / sc) * (y_[i] / sc);
    d1 += (f0_[i] / sc) * (f0_[i] / sc);
  }
  d0 = std::sqrt(d0 / n_);
  d1 = std::sqrt(d1 / n_);
  double h = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
  return std::min(h, 1.0);
}

double ErkStepper::attempt(double t0, const double* y0, const double* f0, double h, double* yout) {
  const int s = tab_.stages;
  std::copy(f0, f0 + n_, k_.begin());  // c_0 = 0 for every explicit table
  for (int i = 1; i < s; ++i) {
    std::copy(y0, y0 + n_, tmp_.begin());
    for (const Term& a : a_terms_[static_cast<std::size_t>(i)]) {
      const double ha = h * a.coef;
      const double* k = &k_[static_cast<std::size_t>(a.stage) * n_];
      for (std::size_t m = 0; m < n_; ++m) tmp_[m] += ha * k[m];
    }
    f_(t0 + tab_.c[static_cast<std::size_t>(i)] * h, tmp_.data(), &k_[static_cast<std::size_t>(i) * n_], user_);
    ++nf_;
  }
  std::copy(y0, y0 + n_, yout);
  std::fill(err_.begin(), err_.end(), 0.0);
  for (const Term& b : b_terms_) {
    const double hb = h * b.coef;
    const double* k = &k_[static_cast<std::size_t>(b.stage) * n_];
    for (std::size_t m = 0; m < n_; ++m) yout[m] += hb * k[m];
  }
  for (const Term& e : e_terms_) {
    const double he = h * e.coef;
    const double* k = &k_[static_cast<std::size_t>(e.stage) * n_];
    for (std::size_t m = 0; m < n_; ++m) err_[m] += he * k[m];
  }
  double norm = 0;
  for (std::size_t m = 0; m < n_; ++m) {
    const double sc = atol_ + rtol_ * std::max(std::fabs(y0[m]), std::fabs(yout[m]));
    norm += (err_[m] / sc) * (err_[m] / sc);
  }
  return std::sqrt(norm / static_cast<double>(n_));
}

namespace {
bool all_finite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}
}  // namespace

ErkStepper::Status ErkStepper::step() {
  const int q = std::min(tab_.order, tab_.embedded_order);
  const double expo = 1.0 / (q + 1);
  if (t_ >= tstop_) return StopReached;
  if (steps_ >= max_steps_) return TooManySteps;
  if (!std::isfinite(h_) || !std::isfinite(t_) || !all_finite(y_) || !all_finite(f0_)) return NotFinite;
  for (;;) {
    double h = std::min(h_, tstop_ - t_);
    const bool to_stop = h >= tstop_ - t_;
    if (h < 1e-14 * std::max(1.0, std::fabs(t_))) return StepTooSmall;
    const long nf_before = nf_;
    const double err = attempt(t_, y_.data(), f0_.data(), h, ynew_.data());
    const double fac = err > 0 ? 0.9 * std::pow(err, -expo) : 5.0;
    const bool accept = err <= 1.0 && std::isfinite(err);
    const long used = nf_ - nf_before + (accept ? 1 : 0);
    (accept ? ctr_.rhs_accepted : ctr_.rhs_rejected) += used;
    if (since_reset_ < 2) ctr_.rhs_after_reset += used;
    if (accept) {
      ++since_reset_;
      // accept
      tprev_ = t_;
      cache_valid_ = false;
      yprev_.swap(y_);
      fprev_.swap(f0_);
      t_ = to_stop ? tstop_ : t_ + h;
      y_.swap(ynew_);
      f_(t_, y_.data(), f0_.data(), user_);
      ++nf_;
      ++steps_;
      if (!to_stop || h == h_) h_ = h * std::clamp(fac, 0.2, 5.0);
      break;
    }
    // a non-finite error estimate (a stage left the domain: NaN or overflow) cuts the step hard
    h_ = h * (std::isfinite(err) ? std::clamp(std::isfinite(fac) ? fac : 0.1, 0.1, 0.9) : 0.1);
  }
  if (!g_ || nroots_ == 0) return t_ >= tstop_ ? StopReached : Ok;

  // Root detection over [tprev, t].
  g_(t_, y_.data(), g1_.data(), user_);
  ++ctr_.root_evaluations;
  for (std::size_t k = 0; k < nroots_; ++k) {
    bt_[k] = t_;
    bg_[k] = g1_[k];
  }
  if (gd_ || dr_) find_dips();
  double troot = t_ + 1.0;
  int first = -1;
  for (std::size_t k = 0; k < nroots_; ++k) {
    const double a = g0_[k], b = bg_[k];
    if (a == 0.0 || !((a < 0) != (b < 0) || b == 0.0)) continue;
    // Illinois on the Hermite interpolant.
    auto g = [&](double tc) {
      dense(tc, tmp_.data());
      g_(tc, tmp_.data(), gtmp_.data(), user_);
      ++ctr_.root_evaluations;
      return gtmp_[k];
    };
    const double tol = 1e-14 * std::max(1.0, std::fabs(t_));
    const double tk = illinois_crossing(g, tprev_, a, bt_[k], b, [tol](double) { return tol; }, 60, false);  // far side
    hint_[k] = tk;
    if (tk < troot) {
      troot = tk;
      first = static_cast<int>(k);
    }
  }
  if (first < 0) {
    g0_.swap(g1_);
    gd0_.swap(gd1_);
    dr0_.swap(dr1_);
    return t_ >= tstop_ ? StopReached : Ok;
  }
  if (polish_) {
    // The crossed functions refined on the RK solution, the earliest wins. In the order of their
    // interpolated roots: once one is polished (troot), a later function needs polishing only if
    // it has crossed by troot already (its sign at the state at troot), on [tprev, troot].
    order_.clear();
    for (std::size_t k = 0; k < nroots_; ++k) {
      const double a = g0_[k], b = bg_[k];
      if (a != 0.0 && ((a < 0) != (b < 0) || b == 0.0)) order_.push_back(k);
    }
    std::sort(order_.begin(), order_.end(), [&](std::size_t i, std::size_t j) { return hint_[i] < hint_[j]; });
    troot = t_;
    first = -1;
    for (std::size_t k : order_) {
      double tb = bt_[k], gb = bg_[k];
      if (first >= 0) {
        gb = groot_[k];
        // not crossed by troot: its root is later; exactly zero there: a root at troot (found_)
        if (gb == 0.0 || (g0_[k] < 0) == (gb < 0)) continue;
        tb = std::min(tb, troot);
      }
      const double tk = polish(k, tprev_, g0_[k], tb, gb, hint_[k]);
      if (first < 0 || tk < troot) {
        troot = tk;
        first = static_cast<int>(k);
        if (order_.size() > 1) {  // the signs at troot, for the functions still to come
          state_at(troot);
          g_(troot, ycache_.data(), groot_.data(), user_);
          ++ctr_.root_evaluations;
        }
      }
    }
  }
  // Recompute the state at the root with a fresh RK step from the step's start.
  const double hroot = troot - tprev_;
  if (hroot > 0) {
    state_at(troot);
    y_ = ycache_;
  } else {
    y_ = yprev_;
  }
  t_ = troot;
  f_(t_, y_.data(), f0_.data(), user_);  // keeps dense() consistent on [tprev, troot]
  ++nf_;
  ++ctr_.rhs_root;
  g_(t_, y_.data(), g1_.data(), user_);
  ++ctr_.root_evaluations;
  std::fill(found_.begin(), found_.end(), 0);
  found_[static_cast<std::size_t>(first)] = 1;
  for (std::size_t k = 0; k < nroots_; ++k) {
    const double a = g0_[k], b = g1_[k];
    if (a != 0.0 && ((a < 0) != (b < 0) || b == 0.0)) found_[k] = 1;
  }
  return Root;  // the caller resets the stepper at the root
}

void ErkStepper::find_dips() {
  if (gd_) gd_(t_, y_.data(), gd1_.data(), user_);
  if (dr_) dr_(t_, y_.data(), f0_.data(), dr1_.data(), user_);  // f at the step's end (FSAL)
  const double h = t_ - tprev_;
  for (std::size_t k = 0; k < nroots_; ++k) {
    const double g0 = g0_[k], g1 = g1_[k];
    if (g1 == 0.0) continue;
    // the rate known for k: a gap's (gd_) or one from f (dr_); the two fill disjoint entries
    const double r0 = gd0_[k] + dr0_[k], r1 = gd1_[k] + dr1_[k];
    // A function exactly 0 at the start (a cluster released from rest, its stop function; docs/
    // model.md 11.12) that leaves zero into its positive side (r0 > 0: the side of its mode) and
    // is back across zero at the end, falling: it crossed zero inside the step. Only r0 > 0: a
    // start rate the other way is a rounding-level start against the mode, not a crossing.
    const bool from_zero = g0 == 0.0 && r0 > 0 && g1 < 0 && r1 < 0;
    // A function on one side at both ends whose rate points towards zero at the start and away at
    // the end (a dip).
    const bool dip = g0 != 0.0 && (g0 < 0) == (g1 < 0) && (g0 < 0 ? r0 > 0 && r1 < 0 : r0 < 0 && r1 > 0);
    if (!from_zero && !dip) continue;
    const double s = from_zero ? 1.0 : (g0 < 0 ? -1.0 : 1.0);  // the side of the extremum: s * g(t_m) across zero?
    // the interpolant g0 + a1 u + a2 u^2 + a3 u^3 on u in [0, 1]; its slope changes sign once
    const double a1 = h * r0, a2 = 3 * (g1 - g0) - h * (2 * r0 + r1), a3 = 2 * (g0 - g1) + h * (r0 + r1);
    // a dip's extremum is towards zero from side s (slope -s at the start), a start from zero's
    // away from it (slope +s)
    const double sl = from_zero ? 1.0 : -1.0;
    double lo = 0, hi = 1;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (sl * s * (a1 + mid * (2 * a2 + 3 * a3 * mid)) > 0) lo = mid; else hi = mid;
    }
    const double u = 0.5 * (lo + hi);
    const double gu = g0 + u * (a1 + u * (a2 + u * a3));
    if (dip ? s * gu > 0 : !(gu > 0)) continue;  // a dip that stays on its side; no excursion
    const double tm = tprev_ + u * h;
    if (!(tm > tprev_ && tm < t_)) continue;
    state_at(tm);  // on the Runge-Kutta solution
    g_(tm, ycache_.data(), gtmp_.data(), user_);
    ++ctr_.root_evaluations;
    if (dip ? s * gtmp_[k] > 0 : !(gtmp_[k] > 0)) continue;
    ++ctr_.dips;
    if (dip) {
      bt_[k] = tm;  // [t_prev, t_m] brackets the first crossing
      bg_[k] = gtmp_[k];
    } else {
      // positive on (t_prev, t_m], negative at t: the side the function left zero to stands for
      // the start of the bracket [t_prev, t], whose inner points are all evaluated on that side
      g0_[k] = gtmp_[k];
    }
  }
}

double ErkStepper::state_at(double tc) {
  // the last state computed from this step's start is reused (attempt() is deterministic, so a
  // reuse is bit-identical to a recomputation)
  if (cache_valid_ && tc == tcache_) return tc;
  const long nf_before = nf_;
  attempt(tprev_, yprev_.data(), fprev_.data(), tc - tprev_, ycache_.data());
  ctr_.rhs_root += nf_ - nf_before;
  tcache_ = tc;
  cache_valid_ = true;
  return tc;
}

double ErkStepper::polish(std::size_t k, double ta, double ga, double tb, double gb, double hint) {
  ++ctr_.polishes;
  auto g = [&](double tc) {
    ++ctr_.polish_steps;
    state_at(tc);
    g_(tc, ycache_.data(), gtmp_.data(), user_);
    ++ctr_.root_evaluations;
    return gtmp_[k];
  };
  if (gd_) {
    // Newton on the Runge-Kutta solution for a function whose rate is known (a gap: linear in the
    // state, rate = the relative speed; docs/model.md 11.9), from the interpolant's root. The
    // time tolerance is derived: a time error dt moves the gap by |rate| dt, which is held to
    // kEventGapTol (1e-3 of atol). The last point is put just past the predicted root, on tb's
    // side, so the event state has crossed (gap <= 0 by at most |rate| tol); the event handler
    // projects the gap to zero.
    const bool start_negative = ga < 0;  // ga != 0: the function's side before the crossing
    double tc = hint > ta && hint < tb ? hint : 0.5 * (ta + tb);
    for (int it = 0; it < 4; ++it) {
      const double gc = g(tc);
      if (gc == 0.0) return tc;
      const bool crossed = (gc < 0) != start_negative;
      if (crossed) {
        tb = tc;
        gb = gc;
      } else {
        ta = tc;
        ga = gc;
      }
      gd_(tc, ycache_.data(), gdtmp_.data(), user_);
      const double rate = gdtmp_[k];
      if (!(std::isfinite(rate) && rate != 0.0)) break;
      const double tol = std::max(4e-16 * std::max(1.0, std::fabs(tb)), atol_ * kEventGapTol / std::fabs(rate));
      const double d = -gc / rate;
      if (crossed && std::fabs(d) <= tol) return tc;   // crossed, within the tolerance of the root
      const double tn = tc + d + 0.5 * tol;  // just past the predicted root
      if (!(tn > ta && tn < tb)) break;
      tc = tn;
    }
    if (std::fabs(tb - ta) <= 4e-16 * std::max(1.0, std::fabs(tb))) return tb;
  }
  // the interpolant's root first, with a closing point 1e-6 of the step beyond it (the
  // interpolant's error in the root time is far smaller)
  return refine_crossing(g, ta, ga, tb, gb, 4e-16 * std::max(1.0, std::fabs(tb)), hint, 1e-6 * (tb - ta));
}

void ErkStepper::dense(double t, double* out) const {
  const double h = t_ - tprev_;
  if (h <= 0) {
    std::copy(y_.begin(), y_.end(), out);
    return;
  }
  const double th = (t - tprev_) / h;
  const double h00 = (1 + 2 * th) * (1 - th) * (1 - th), h10 = th * (1 - th) * (1 - th);
  const double h01 = th * th * (3 - 2 * th), h11 = th * th * (th - 1);
  for (std::size_t m = 0; m < n_; ++m)
    out[m] = h00 * yprev_[m] + h10 * h * fprev_[m] + h01 * y_[m] + h11 * h * f0_[m];
}

}  // namespace abuopt::detail
