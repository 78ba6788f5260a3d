#pragma once
// Refining a sign change of a scalar function g(t) over [ta, tb] to a bracket of width <= tol,
// for the simulator's root location (the stepper's polished roots, the exact stuck propagator).
#include <cmath>

namespace abuopt::detail {

// Illinois (regula falsi, halving the value kept at an end that stays twice) on g over [ta, tb],
// g(ta) = ga and g(tb) = gb of opposite signs, until the bracket is no wider than tol(tb) or after
// max_iterations. Returns an exact zero found on the way, else tb: a time on tb's side of the
// crossing (where g has gb's sign). A secant point that rounds onto an end is replaced by the
// midpoint if `midpoint_at_ends` (the stepper's interpolant search keeps it: its roots, and with
// them every run's numbers, stay as they were).
template <class G, class Tol>
double illinois_crossing(G&& g, double ta, double ga, double tb, double gb, Tol&& tol, int max_iterations,
                         bool midpoint_at_ends = true) {
  int side = 0;
  for (int it = 0; it < max_iterations && std::fabs(tb - ta) > tol(tb); ++it) {
    double tc = (gb != ga) ? tb - gb * (tb - ta) / (gb - ga) : 0.5 * (ta + tb);
    if (midpoint_at_ends && !(tc > ta && tc < tb)) tc = 0.5 * (ta + tb);
    const double gc = g(tc);
    if (gc == 0.0) return tc;
    if ((gc < 0) == (gb < 0)) {
      tb = tc;
      gb = gc;
      if (side == -1) ga *= 0.5;
      side = -1;
    } else {
      ta = tc;
      ga = gc;
      if (side == 1) gb *= 0.5;
      side = 1;
    }
  }
  return tb;
}

// g(ta) = ga and g(tb) = gb have opposite signs (or gb == 0). Returns a time on tb's side of the
// crossing (where g has gb's sign or is zero), within tol of the crossing.
//
// Illinois alone ends slowly here: once a secant point lands within rounding of the root, every
// later point lands there too and the bracket shrinks from the far side only, by halves (20 and
// more evaluations to reach tol = 2 ulp). So after each Illinois point tc a closing point is
// tried at tc + 2 d, d = -g(tc) / slope the predicted distance to the root (at least tol): it
// usually lands just beyond the root, and the bracket collapses around it. An optional hint (a
// root estimate, e.g. on the step's interpolant) is tried first, with a closing point hint_width
// beyond it.
template <class G>
double refine_crossing(G&& g, double ta, double ga, double tb, double gb, double tol, double hint = NAN,
                       double hint_width = 0.0) {
  double fa = ga, fb = gb;  // the true values at the ends (ga, gb carry Illinois' halvings)
  int side = 0;
  auto take = [&](double tc, double gc, bool illinois) {
    if ((gc < 0) == (gb < 0)) {
      tb = tc;
      gb = fb = gc;
      if (illinois && side == -1) ga *= 0.5;
      side = -1;
    } else {
      ta = tc;
      ga = fa = gc;
      if (illinois && side == 1) gb *= 0.5;
      side = 1;
    }
  };
  // a closing point from tc, towards the root by twice its predicted distance; false: exact zero
  auto close = [&](double tc, double gc, double min_step) {
    const double slope = (fb - fa) / (tb - ta);
    if (!(std::isfinite(slope) && slope != 0.0)) return true;
    double d = -gc / slope;
    const double step = std::fmax(std::fabs(2.0 * d), min_step);
    const double t2 = (gc < 0) == (gb < 0) ? tc - step : tc + step;  // the root is before / after tc
    if (!(t2 > ta && t2 < tb)) return true;
    const double g2 = g(t2);
    if (g2 == 0.0) {
      tb = t2;
      return false;
    }
    take(t2, g2, false);
    return true;
  };
  if (hint > ta && hint < tb) {
    const double gc = g(hint);
    if (gc == 0.0) return hint;
    take(hint, gc, false);
    if (std::fabs(tb - ta) > tol && !close(hint, gc, hint_width)) return tb;
  }
  for (int it = 0; it < 100 && std::fabs(tb - ta) > tol; ++it) {
    double tc = (gb != ga) ? tb - gb * (tb - ta) / (gb - ga) : 0.5 * (ta + tb);
    if (!(tc > ta && tc < tb)) tc = 0.5 * (ta + tb);
    const double gc = g(tc);
    if (gc == 0.0) return tc;
    take(tc, gc, true);
    if (std::fabs(tb - ta) > tol && !close(tc, gc, tol)) return tb;
  }
  return tb;
}

}  // namespace abuopt::detail
