// Unit tests of the native explicit Runge-Kutta stepper (core/src/erk_stepper.hpp) on problems
// with known solutions: order of accuracy, step rejection, dense output and root location.
#include "erk_stepper.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

using abuopt::detail::ButcherTable;
using abuopt::detail::ErkStepper;

namespace {

// y'' = -y as a first-order system: y = (sin t, cos t) from (0, 1).
void oscillator(double, const double* y, double* yd, void*) {
  yd[0] = y[1];
  yd[1] = -y[0];
}

// Integrates the oscillator to t = 1 with fixed steps h: a tolerance so loose that every step is
// accepted, and a stop time at every step end, force the step size.
double fixed_step_error(const std::string& table, double h) {
  // (the first steps are short: the stepper's starting heuristic; they only add accurate steps)
  ErkStepper st(ButcherTable::from_arkode(table), 2, oscillator, nullptr, 0, nullptr, 1e10, 1e10, 1'000'000);
  const double y0[2] = {0.0, 1.0};
  st.reset(0.0, y0);
  const int n = static_cast<int>(std::lround(1.0 / h));
  for (int k = 1; k <= n; ++k) {
    st.set_stop_time(k * h);
    while (st.t() < k * h) {
      const auto s = st.step();
      EXPECT_GE(s, 0);
      if (s < 0) return NAN;
    }
  }
  return std::hypot(st.y()[0] - std::sin(1.0), st.y()[1] - std::cos(1.0));
}

struct OrderCase {
  const char* table;
  int order;
  double h;    // coarse step: errors at h and h/2 must be well above rounding
  double tol;  // on the measured order
};

}  // namespace

TEST(ErkStepper, ObservedOrderMatchesTheTable) {
  // Global error ~ C h^p: halving the step divides it by 2^p. Measured p within 0.3 of the table's;
  // for the 8th-order table the smallest step pair whose errors stay well above rounding
  // (8.5e-10, 4.6e-12) is not yet asymptotic: measured 7.53, accepted within 0.6.
  for (const OrderCase& c : {OrderCase{"ARKODE_HEUN_EULER_2_1_2", 2, 0.05, 0.3},
                             OrderCase{"ARKODE_BOGACKI_SHAMPINE_4_2_3", 3, 0.05, 0.3},
                             OrderCase{"ARKODE_ZONNEVELD_5_3_4", 4, 0.1, 0.3},
                             OrderCase{"ARKODE_DORMAND_PRINCE_7_4_5", 5, 0.1, 0.3},
                             OrderCase{"ARKODE_FEHLBERG_13_7_8", 8, 0.5, 0.6}}) {
    const double e1 = fixed_step_error(c.table, c.h), e2 = fixed_step_error(c.table, c.h / 2);
    const double p = std::log2(e1 / e2);
    EXPECT_NEAR(p, c.order, c.tol) << c.table << ": errors " << e1 << ", " << e2;
    EXPECT_EQ(ButcherTable::from_arkode(c.table).order, c.order) << c.table;
  }
}

TEST(ErkStepper, UnknownOrEmbeddinglessTableIsRejected) {
  EXPECT_THROW(ButcherTable::from_arkode("NO_SUCH_TABLE"), std::invalid_argument);
  EXPECT_THROW(ButcherTable::from_arkode("ARKODE_KNOTH_WOLKE_3_3"), std::invalid_argument);  // no embedding
}

namespace {
// y' = -50 (y - sin t): the solution follows sin t after a fast transient; an explicit method
// near its stability limit has to reject steps. Exact solution from y(0) = 1:
// y = (2500 sin t - 50 cos t)/2501 + (1 + 50/2501) exp(-50 t).
void relaxation(double t, const double* y, double* yd, void*) { yd[0] = -50.0 * (y[0] - std::sin(t)); }
double relaxation_exact(double t) {
  return (2500.0 * std::sin(t) - 50.0 * std::cos(t)) / 2501.0 + (1.0 + 50.0 / 2501.0) * std::exp(-50.0 * t);
}
}  // namespace

TEST(ErkStepper, RejectsStepsAndStillMeetsTheTolerance) {
  const ButcherTable tab = ButcherTable::from_arkode("ARKODE_DORMAND_PRINCE_7_4_5");
  ErkStepper st(tab, 1, relaxation, nullptr, 0, nullptr, 1e-8, 1e-10, 1'000'000);
  const double y0 = 1.0;
  st.reset(0.0, &y0);
  st.set_stop_time(10.0);
  ErkStepper::Status s = ErkStepper::Ok;
  double worst = 0;
  while ((s = st.step()) == ErkStepper::Ok || s == ErkStepper::StopReached) {
    worst = std::max(worst, std::fabs(st.y()[0] - relaxation_exact(st.t())));
    if (s == ErkStepper::StopReached) break;
  }
  ASSERT_EQ(s, ErkStepper::StopReached);
  EXPECT_DOUBLE_EQ(st.t(), 10.0);
  // Every accepted step costs stages - 1 stage evaluations plus one at its end; reset costs one.
  // Anything beyond that is rejected attempts (stages - 1 evaluations each).
  const long accepted_cost = 1 + st.steps() * tab.stages;
  const long rejected = (st.rhs_calls() - accepted_cost) / (tab.stages - 1);
  EXPECT_GT(rejected, 0) << "steps " << st.steps() << ", rhs calls " << st.rhs_calls();
  EXPECT_LT(worst, 1e-6);  // global error of a 1e-8 local tolerance over 10 time units
}

TEST(ErkStepper, BlowUpEndsWithStepTooSmallNotALoop) {
  // y' = y^2, y(0) = 1: y = 1/(1 - t) blows up at t = 1.
  auto blowup = [](double, const double* y, double* yd, void*) { yd[0] = y[0] * y[0]; };
  ErkStepper st(ButcherTable::from_arkode("ARKODE_DORMAND_PRINCE_7_4_5"), 1, blowup, nullptr, 0, nullptr, 1e-8,
                1e-10, 1'000'000);
  const double y0 = 1.0;
  st.reset(0.0, &y0);
  st.set_stop_time(2.0);
  ErkStepper::Status s = ErkStepper::Ok;
  while ((s = st.step()) == ErkStepper::Ok) {
  }
  EXPECT_EQ(s, ErkStepper::StepTooSmall);
  EXPECT_NEAR(st.t(), 1.0, 1e-2);  // ends at the pole (give or take rounding), never loops
}

TEST(ErkStepper, StepBudgetEndsWithTooManySteps) {
  ErkStepper st(ButcherTable::from_arkode("ARKODE_HEUN_EULER_2_1_2"), 2, oscillator, nullptr, 0, nullptr, 1e-10,
                1e-12, 50);
  const double y0[2] = {0.0, 1.0};
  st.reset(0.0, y0);
  st.set_stop_time(100.0);
  ErkStepper::Status s = ErkStepper::Ok;
  while ((s = st.step()) == ErkStepper::Ok) {
  }
  EXPECT_EQ(s, ErkStepper::TooManySteps);
  EXPECT_EQ(st.steps(), 50);
}

TEST(ErkStepper, DenseOutputIsTheCubicHermiteInterpolantOfTheStep) {
  // One step of h = 0.5 on y = sin t (8th order: the step's own error is 7.7e-10). The cubic
  // Hermite interpolant through the end values and slopes errs by at most
  // max|y''''| (t - a)^2 (t - b)^2 / 4!, i.e. h^4 / 384 at the midpoint.
  ErkStepper st(ButcherTable::from_arkode("ARKODE_FEHLBERG_13_7_8"), 2, oscillator, nullptr, 0, nullptr, 1e10, 1e10,
                100);
  const double y0[2] = {0.0, 1.0};
  st.reset(0.0, y0);
  st.set_stop_time(50.0);  // let the step size grow (reset keeps it as the next first guess)
  while (st.step() == ErkStepper::Ok) {
  }
  st.reset(0.0, y0);
  st.set_stop_time(0.5);
  ASSERT_EQ(st.step(), ErkStepper::StopReached);  // one step [0, 0.5]
  const double h = 0.5;
  double out[2];
  st.dense(0.0, out);
  EXPECT_NEAR(out[0], 0.0, 1e-15);
  st.dense(h, out);
  EXPECT_NEAR(out[0], std::sin(h), 1e-9);
  for (double th : {0.1, 0.25, 0.5, 0.75, 0.9}) {
    const double t = th * h;
    st.dense(t, out);
    const double bound = std::pow(t * (h - t), 2) / 24.0 * std::sin(h) + 1e-9;  // |sin''''| <= sin h on [0, h]
    EXPECT_LE(std::fabs(out[0] - std::sin(t)), bound) << "t = " << t;
    EXPECT_LE(std::fabs(out[1] - std::cos(t)), std::pow(t * (h - t), 2) / 24.0 + 1e-9) << "t = " << t;
  }
  // The midpoint error is of the predicted size (a cubic, not a linear interpolant: that would
  // err by ~h^2/8 sin(h/2) = 7.5e-3).
  st.dense(h / 2, out);
  EXPECT_GT(std::fabs(out[0] - std::sin(h / 2)), 0.2 * std::pow(h, 4) / 384.0 * std::sin(h / 2));
}

namespace {
void sine_root(double, const double* y, double* g, void*) {
  g[0] = y[0] - 0.5;  // sin t = 1/2 at t = pi/6 and 5 pi/6
  g[1] = y[1];        // cos t = 0 at t = pi/2
  g[2] = y[0];        // zero at the start: ignored there (SUNDIALS' convention); next root t = pi
}
}  // namespace

// What the root finder guarantees today (measured here, and the reason for the tolerances): the
// root time is found on the step's cubic Hermite interpolant, so it is as accurate as that
// interpolant (error ~ h^4/384 max|g''''| / |g'|: up to ~1e-5 with steps of ~0.3); the state at
// the reported time is a fresh Runge-Kutta step, accurate to the method's tolerance. When the
// interpolant's root lies before the true one, the same root is reported again (more closely)
// on the next step. Every root is found, in order, and none is missed.
TEST(ErkStepper, LocatesRootsInOrderWithTheInterpolantsAccuracy) {
  ErkStepper st(ButcherTable::from_arkode("ARKODE_FEHLBERG_13_7_8"), 2, oscillator, sine_root, 3, nullptr, 1e-10,
                1e-12, 100000);
  const double y0[2] = {0.0, 1.0};
  st.reset(0.0, y0);
  st.set_stop_time(4.0);
  struct Hit {
    double t;
    int k;
  };
  std::vector<Hit> hits;
  for (;;) {
    const auto s = st.step();
    ASSERT_GE(s, 0);
    if (s == ErkStepper::Root) {
      for (int k = 0; k < 3; ++k)
        if (st.roots_found()[static_cast<std::size_t>(k)]) hits.push_back({st.t(), k});
      // the state is the Runge-Kutta solution at the reported time, whatever its error
      EXPECT_NEAR(st.y()[0], std::sin(st.t()), 1e-10);
      EXPECT_NEAR(st.y()[1], std::cos(st.t()), 1e-10);
      const std::vector<double> y = st.y();
      st.reset(st.t(), y.data());
    }
    if (s == ErkStepper::StopReached) break;
  }
  const std::vector<Hit> truth = {{M_PI / 6, 0}, {M_PI / 2, 1}, {5 * M_PI / 6, 0}, {M_PI, 2}};
  std::size_t j = 0;
  for (const Hit& h : hits) {
    while (j < truth.size() && !(truth[j].k == h.k && std::fabs(truth[j].t - h.t) < 2e-5)) ++j;
    ASSERT_LT(j, truth.size()) << "unexpected root of g" << h.k << " at t = " << h.t;
  }
  for (const Hit& want : truth) {
    bool seen = false;
    for (const Hit& h : hits) seen |= h.k == want.k && std::fabs(h.t - want.t) < 2e-5;
    EXPECT_TRUE(seen) << "root of g" << want.k << " at t = " << want.t << " missed";
  }
  EXPECT_LE(hits.size(), 3 * truth.size());
  EXPECT_NEAR(st.y()[0], std::sin(4.0), 1e-8);
}

TEST(ErkStepper, ARootAtTheStartOfAStepIsIgnored) {
  // g = y0 starts at exactly zero: no root at t = 0, the first one is at t = pi.
  auto g_start = [](double, const double* y, double* g, void*) { g[0] = y[0]; };
  ErkStepper st(ButcherTable::from_arkode("ARKODE_DORMAND_PRINCE_7_4_5"), 2, oscillator, g_start, 1, nullptr, 1e-10,
                1e-12, 100000);
  const double y0[2] = {0.0, 1.0};
  st.reset(0.0, y0);
  st.set_stop_time(4.0);
  ErkStepper::Status s;
  while ((s = st.step()) == ErkStepper::Ok) {
  }
  ASSERT_EQ(s, ErkStepper::Root);
  EXPECT_NEAR(st.t(), M_PI, 2e-5);
}

namespace {
// y'' = 1 from y = 1e-3, y' = -0.1: y(t) = 1e-3 - 0.1 t + t^2 / 2 dips to -4e-3 at t = 0.1 and is
// positive again from t = 0.1 + sqrt(0.008) = 0.1894 on; the first zero is 0.1 - sqrt(0.008).
void parabola(double, const double* y, double* yd, void*) {
  yd[0] = y[1];
  yd[1] = 1.0;
}
void parabola_root(double, const double* y, double* g, void*) { g[0] = y[0]; }
void parabola_rate(double, const double* y, double* gd, void*) { gd[0] = y[1]; }

// The stepper of the parabola tests (7(8) table, rtol 1e-6, atol 1e-9, roots polished), its root
// function y0: a gap's or a sliding speed's, as the test gives it a rate.
std::unique_ptr<ErkStepper> parabola_stepper() {
  auto st = std::make_unique<ErkStepper>(ButcherTable::from_arkode("ARKODE_FEHLBERG_13_7_8"), 2, parabola, parabola_root,
                                         1, nullptr, 1e-6, 1e-9, 1000);
  st->set_polish_roots(true);
  return st;
}

// Runs st from t = -20 (state y0) to the stop time -0.2 and sets the stop time 1, so that its next
// step holds both zeros of the parabola (the step size has grown large by then).
void step_to_before_both_zeros(ErkStepper& st, const double* y0) {
  st.reset(-20.0, y0);
  st.set_stop_time(-0.2);
  ErkStepper::Status s = ErkStepper::Ok;
  while (s == ErkStepper::Ok) s = st.step();
  ASSERT_EQ(s, ErkStepper::StopReached);
  st.set_stop_time(1.0);
}
}  // namespace

TEST(ErkStepper, ARootFunctionThatDipsThroughZeroInsideAStepIsFoundWithItsRate) {
  // The solution is a polynomial of degree 2, which the 7(8) table integrates exactly, so the
  // step size grows fast: from t = -20 to a stop time at -0.2, then one step to the stop time 1,
  // which holds both crossings (g = y has the same sign at its ends). Without rates that step sees
  // no root; with the rate dg/dt = y' the stepper finds the minimum on the interpolant and the
  // crossing before it, polished on the Runge-Kutta solution to rounding.
  auto y_at = [](double t) { return 1e-3 - 0.1 * t + 0.5 * t * t; };
  const double y0[2] = {y_at(-20.0), -0.1 - 20.0};
  const double first = 0.1 - std::sqrt(0.008);
  for (bool rates : {false, true}) {
    auto stepper = parabola_stepper();
    ErkStepper& st = *stepper;
    if (rates) st.set_root_rates(parabola_rate);
    step_to_before_both_zeros(st, y0);
    const ErkStepper::Status s = st.step();
    if (!rates) {
      EXPECT_EQ(s, ErkStepper::StopReached);  // one step over both crossings: nothing seen
      EXPECT_EQ(st.t(), 1.0);
      continue;
    }
    // (the state carries the rounding of y(-20) = 202, ~3e-14, through the steps; divided by the
    // slope 0.089 at the root that is ~1e-12 in time)
    ASSERT_EQ(s, ErkStepper::Root);
    EXPECT_NEAR(st.t(), first, 1e-11);
    EXPECT_NEAR(st.y()[0], 0.0, 1e-12);
  }
}

namespace {
// A sliding ball's speed that reverses and back (docs/model.md 11.11): v(t) = a (t - t1) (t - t2)
// with a = 0.5, t1 = 0.1 - sqrt(0.008), t2 = 0.1 + sqrt(0.008) (the parabola above), as the state
// (v, w = v'), w' = 2 a = 1. The stop function is sigma v (sigma = +1: slipping forward); its rate
// is sigma v' = the component 0 of the right-hand side, given to the dip check only (a RateFn
// from dydt, as the simulator's stop functions), so the root is refined without Newton.
// The right-hand side and the stop function are the parabola's above (parabola, parabola_root).
void stop_rate(double, const double*, const double* dydt, double* gd, void*) { gd[0] = dydt[0]; }
}  // namespace

TEST(ErkStepper, ASpeedThatReversesAndBackInsideAStepIsStoppedWithItsRateFromTheRhs) {
  // As for the gap above: from t = -20 to a stop time at -0.2, then one step to 1 over both zeros
  // of v. Without dip rates (contact model version 4: only gaps had rates) the stop is missed;
  // with the rate from f at the step's ends the minimum on the interpolant (exact: v is a state
  // component, its Hermite interpolant has v' from f) is below zero on the Runge-Kutta solution,
  // and the first zero is refined by Illinois to 2 ulp of the time: within 1e-11 of t1 (the
  // rounding of v(-20) ~ 3e-14 over the slope |v'(t1)| = 0.089), the speed at the event within
  // 1e-12 of 0, and no Newton iteration (no rate from set_root_rates).
  auto v_at = [](double t) { return 1e-3 - 0.1 * t + 0.5 * t * t; };
  const double y0[2] = {v_at(-20.0), -0.1 - 20.0};
  const double t1 = 0.1 - std::sqrt(0.008);
  for (bool rates : {false, true}) {
    auto stepper = parabola_stepper();
    ErkStepper& st = *stepper;
    if (rates) st.set_dip_rates(stop_rate);
    step_to_before_both_zeros(st, y0);
    const abuopt::SimCounters before = abuopt::sim_counters();
    const ErkStepper::Status s = st.step();
    if (!rates) {
      EXPECT_EQ(s, ErkStepper::StopReached);  // the missed stop of version 4
      EXPECT_EQ(st.t(), 1.0);
      EXPECT_GT(st.y()[0], 0.0);
      continue;
    }
    ASSERT_EQ(s, ErkStepper::Root);
    EXPECT_NEAR(st.t(), t1, 1e-11);
    EXPECT_NEAR(st.y()[0], 0.0, 1e-12);
    EXPECT_EQ(st.roots_found()[0], 1);
    EXPECT_EQ(abuopt::sim_counters().dips - before.dips, 1);
    EXPECT_EQ(abuopt::sim_counters().polishes - before.polishes, 1);
  }
}

// A function that moves towards zero and turns away before reaching it (v stays > 0) is not a
// stop: the minimum is checked on the Runge-Kutta solution, so no false stop (a ball whose speed
// only approaches zero keeps slipping).
TEST(ErkStepper, ASpeedThatOnlyApproachesZeroIsNotStopped) {
  auto v_at = [](double t) { return 1e-2 - 0.1 * t + 0.5 * t * t; };  // minimum 5e-3 at t = 0.1
  const double y0[2] = {v_at(-20.0), -0.1 - 20.0};
  auto stepper = parabola_stepper();
  ErkStepper& st = *stepper;
  st.set_dip_rates(stop_rate);
  st.reset(-20.0, y0);
  st.set_stop_time(1.0);
  ErkStepper::Status s = ErkStepper::Ok;
  while (s == ErkStepper::Ok) s = st.step();
  EXPECT_EQ(s, ErkStepper::StopReached);
  EXPECT_EQ(st.t(), 1.0);
}

namespace {
// A cluster released from rest (docs/model.md 11.12): its stop function v is exactly 0 at the
// reset, and it starts at the rate r0 into its slip side; the state (v, w = v'), w' = -1, so
// v(t) = r0 (t - t0) - (t - t0)^2 / 2 reverses and is back at zero at t0 + 2 r0.
void hill(double, const double* y, double* yd, void*) {
  yd[0] = y[1];
  yd[1] = -1.0;
}

// The hill's stepper with its step size grown (from t = -20 to -0.2), reset at t0 = 0 to (0, r0)
// with the stop time 1, as the simulator resets at an event and keeps its step size.
std::unique_ptr<ErkStepper> hill_released(double r0, bool rates) {
  auto st = std::make_unique<ErkStepper>(ButcherTable::from_arkode("ARKODE_FEHLBERG_13_7_8"), 2, hill, parabola_root, 1,
                                         nullptr, 1e-6, 1e-9, 1000);
  st->set_polish_roots(true);
  if (rates) st->set_dip_rates(stop_rate);
  const double far[2] = {1e3, 0.0};  // positive until t = -20 + sqrt(2000): no root before -0.2
  st->reset(-20.0, far);
  st->set_stop_time(-0.2);
  ErkStepper::Status s = ErkStepper::Ok;
  while (s == ErkStepper::Ok) s = st->step();
  EXPECT_EQ(s, ErkStepper::StopReached);
  const double released[2] = {0.0, r0};
  st->reset(0.0, released);
  st->set_stop_time(1.0);
  return st;
}
}  // namespace

// The first step after a release holds the reversal (r0 = 0.05: v is back at zero at 0.1 and -0.45
// at the step's end, 1). The stop function is exactly zero at the step's start, so neither the
// sign-change test nor the dip check of 11.11 sees the stop (contact model version 5, the miss of
// 11.12); with the check for a function leaving zero into its side (version 6), the extremum of
// the interpolant (at 0.05, exact: a state component) is confirmed positive on the Runge-Kutta
// state and the crossing refined by Illinois: at 0.1 within 1e-12, v there within 1e-12 of 0.
// A function that leaves zero against its side (r0 < 0: the rounding-level start of a cluster
// released against its acceleration) is not a crossing and gives no event.
TEST(ErkStepper, AStopInsideTheFirstStepAfterAReleaseFromRestIsFound) {
  for (bool rates : {false, true}) {
    auto st = hill_released(0.05, rates);
    const abuopt::SimCounters before = abuopt::sim_counters();
    const ErkStepper::Status s = st->step();
    if (!rates) {
      EXPECT_EQ(s, ErkStepper::StopReached);  // one step over the reversal: the stop is missed
      EXPECT_EQ(st->t(), 1.0);
      EXPECT_NEAR(st->y()[0], -0.45, 1e-12);
      continue;
    }
    ASSERT_EQ(s, ErkStepper::Root);
    EXPECT_NEAR(st->t(), 0.1, 1e-12);
    EXPECT_NEAR(st->y()[0], 0.0, 1e-12);
    EXPECT_EQ(st->roots_found()[0], 1);
    EXPECT_EQ(abuopt::sim_counters().dips - before.dips, 1);
  }
  auto against = hill_released(-0.05, true);
  EXPECT_EQ(against->step(), ErkStepper::StopReached);
  EXPECT_EQ(against->t(), 1.0);
}

namespace {
// A gap closing on a known trajectory: y = (sin t, cos t); the "gap" g = 0.8 - y0 (a ball at
// sin t approaching a resting ball at 0.8) closes at t* = asin(0.8), at the rate g' = -y1 = -0.6.
void closing_gap(double, const double* y, double* g, void*) { g[0] = 0.8 - y[0]; }
void closing_gap_rate(double, const double* y, double* gd, void*) { gd[0] = -y[1]; }

struct GapEvent {
  double t = NAN, g = NAN;
  long polishes = 0, polish_steps = 0;
};
GapEvent locate_gap(bool rates, double rtol, double atol) {
  ErkStepper st(ButcherTable::from_arkode("ARKODE_FEHLBERG_13_7_8"), 2, oscillator, closing_gap, 1, nullptr, rtol, atol,
                100000);
  st.set_polish_roots(true);
  if (rates) st.set_root_rates(closing_gap_rate);
  const double y0[2] = {0.0, 1.0};
  const abuopt::SimCounters before = abuopt::sim_counters();
  st.reset(0.0, y0);
  st.set_stop_time(2.0);
  ErkStepper::Status s = ErkStepper::Ok;
  while (s == ErkStepper::Ok) s = st.step();
  GapEvent ev;
  if (s != ErkStepper::Root) return ev;
  ev.t = st.t();
  closing_gap(ev.t, st.y().data(), &ev.g, nullptr);
  ev.polishes = abuopt::sim_counters().polishes - before.polishes;
  ev.polish_steps = abuopt::sim_counters().polish_steps - before.polish_steps;
  return ev;
}
}  // namespace

// Newton on the Runge-Kutta solution for a root function with a known rate (a gap; docs/model.md
// 11.9): the time tolerance is atol * kEventGapTol / |rate|, and the state at the event has just
// crossed (gap in [-|rate| tol, 0]), for the event handler to project to zero.
TEST(ErkStepper, AClosingGapIsLocatedByNewtonToItsDerivedTolerance) {
  const double t_star = std::asin(0.8);
  // tight tolerances: the Runge-Kutta solution is exact to ~1e-13, so the located time is the
  // closed form's to that over the rate (|g'| = 0.6), plus the time tolerance (rounding here)
  const GapEvent tight = locate_gap(true, 1e-12, 1e-14);
  ASSERT_TRUE(std::isfinite(tight.t));
  EXPECT_NEAR(tight.t, t_star, 1e-12);
  EXPECT_LE(tight.g, 0.0);
  EXPECT_GE(tight.g, -1e-13);
  // default tolerances: against the 2-ulp polish (Illinois with closing points) of the same
  // Runge-Kutta solution, the Newton root is within the derived tolerance, on the crossed side
  const double rtol = 1e-6, atol = 1e-9;
  const GapEvent newton = locate_gap(true, rtol, atol), ulp = locate_gap(false, rtol, atol);
  ASSERT_TRUE(std::isfinite(newton.t) && std::isfinite(ulp.t));
  const double tol_t = atol * abuopt::detail::kEventGapTol / 0.6;  // 1.7e-12
  EXPECT_NEAR(newton.t, ulp.t, tol_t);
  EXPECT_GE(newton.t, ulp.t - 4e-16);  // never before the crossing
  EXPECT_LE(newton.g, 0.0);
  EXPECT_GE(newton.g, -0.6 * tol_t * 1.01);
  EXPECT_NEAR(ulp.g, 0.0, 1e-15);
  // both near the closed form within the method's error at rtol 1e-6 (~1e-8 in y, over 0.6)
  EXPECT_NEAR(newton.t, t_star, 1e-7);
  // cost: Newton takes at most 3 Runge-Kutta evaluations for the root (the interpolant's root,
  // one Newton step landing past the root, the check), the 2-ulp polish more
  EXPECT_EQ(newton.polishes, 1);
  EXPECT_LE(newton.polish_steps, 3);
  EXPECT_GT(ulp.polish_steps, newton.polish_steps);
}
