// The exact propagator of the all-stuck phase (core/src/stuck_propagator.hpp,
// docs/stuck_propagator.md) against closed forms (steady orbit, free decay), against the
// Fehlberg 7(8) integration of the same rows at a tight tolerance, and whole runs against the
// Runge-Kutta path.
#include "stuck_propagator.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <complex>
#include <random>
#include <thread>
#include <vector>

#include "abuopt/core/simulator.hpp"
#include "erk_stepper.hpp"
#include "run_forcing_table.hpp"

namespace {

using abuopt::AbuParameters;
using abuopt::BallMode;
using abuopt::StartupProfile;
using abuopt::detail::ButcherTable;
using abuopt::detail::cplx;
using abuopt::detail::ErkStepper;
using abuopt::detail::RunState;
using abuopt::detail::StuckForcingTable;
using abuopt::detail::StuckPropagator;
using abuopt::NondimParameters;
using abuopt::detail::ForcingSamples;
using abuopt::detail::SimulatorForcing;

// Every ball stuck at the given angles, ideal motor, event-driven (the frozen right-hand side).
struct Stuck {
  AbuParameters p;
  StartupProfile profile;
  RunState rs;
  std::vector<double> y;
  Stuck(const StartupProfile& prof, const std::vector<double>& beta) : profile(prof), rs(p) {
    rs.profile = &profile;
    rs.omega_n = rs.nd.omega_n;
    rs.mu = p.friction_mu;
    rs.n = p.balls.size();
    rs.modes.assign(rs.n, BallMode::Stick);
    rs.forces.resize(rs.n);
    rs.off_a.assign(rs.n, 0);
    rs.off_b.assign(rs.n, 0);
    y.assign(rs.lay().size(), 0.0);
    for (std::size_t i = 0; i < rs.n; ++i) y[rs.lay().beta(i)] = beta[i];
    rs.modes_changed(y.data());
  }
  cplx C() const {
    cplx c(rs.nd.mbar_I * rs.nd.ebar, 0);
    for (std::size_t i = 0; i < rs.n; ++i) c += rs.nd.mbar[i] * std::polar(1.0, y[rs.lay().beta(i)]);
    return c;
  }
};

// No events: the margins are never checked against zero.
void no_roots(double, const double*, double* g, void* user) {
  auto& rs = *static_cast<RunState*>(user);
  for (std::size_t k = 0; k < rs.nroots(); ++k) g[k] = 1.0;
}

TEST(StuckPropagator, SteadyOrbitAtConstantSpeedStaysPut) {
  Stuck s(StartupProfile({}, 40.0), {0.7, 2.9});
  const double W = 2 * M_PI * 40.0 / s.rs.nd.omega_n, bb = s.rs.nd.bbar;
  const cplx zs = s.C() * W * W / cplx(1 - W * W, 2 * bb * W);
  s.y[0] = zs.real();
  s.y[1] = zs.imag();
  const double t_end = 400.0;
  StuckForcingTable tab(s.profile, s.rs.nd, t_end);
  StuckPropagator prop(tab, s.rs, no_roots);
  std::vector<int> roots;
  double t = 3.3, peak = 0;  // start off the grid: a partial interval first
  ASSERT_EQ(prop.advance(t, s.y, t_end, roots, peak), StuckPropagator::Stop);
  EXPECT_EQ(t, t_end);
  EXPECT_NEAR(s.y[0], zs.real(), 1e-11 * std::abs(zs));
  EXPECT_NEAR(s.y[1], zs.imag(), 1e-11 * std::abs(zs));
  EXPECT_NEAR(s.y[2], 0.0, 1e-11 * std::abs(zs));
  EXPECT_NEAR(s.y[3], 0.0, 1e-11 * std::abs(zs));
  EXPECT_NEAR(peak, std::abs(zs) * s.p.ball_track_radius_m * 1e3, 1e-12);
  EXPECT_GT(prop.intervals(), 100);  // grid of a quarter period of W + wd
}

TEST(StuckPropagator, FreeDecayMatchesClosedForm) {
  Stuck s(StartupProfile({}, 0.0), {1.0, 4.0});  // W = 0: no force, no rotation
  const cplx z0(2e-3, -1e-3), zd0(-5e-4, 3e-3);
  s.y[0] = z0.real();
  s.y[1] = z0.imag();
  s.y[2] = zd0.real();
  s.y[3] = zd0.imag();
  const double bb = s.rs.nd.bbar, wd = std::sqrt(1 - bb * bb);
  const double t_end = 150.0;
  StuckForcingTable tab(s.profile, s.rs.nd, t_end);
  StuckPropagator prop(tab, s.rs, no_roots);
  std::vector<int> roots;
  double peak = 0;
  for (double stop : {0.37, 11.0, 64.2, t_end}) {  // stops off and on the grid
    double t = 0;
    std::vector<double> y = s.y;
    ASSERT_EQ(prop.advance(t, y, stop, roots, peak), StuckPropagator::Stop);
    const cplx z = std::exp(-bb * stop) * (z0 * std::cos(wd * stop) + (zd0 + bb * z0) / wd * std::sin(wd * stop));
    const cplx zd = std::exp(-bb * stop) *
                    (zd0 * std::cos(wd * stop) - (z0 + bb * zd0) / wd * std::sin(wd * stop));
    EXPECT_NEAR(y[0], z.real(), 1e-14) << stop;
    EXPECT_NEAR(y[1], z.imag(), 1e-14) << stop;
    EXPECT_NEAR(y[2], zd.real(), 1e-14) << stop;
    EXPECT_NEAR(y[3], zd.imag(), 1e-14) << stop;
  }
}

// The rotating-frame rows with every ball stuck, integrated by Fehlberg 7(8) at rtol 1e-12.
std::vector<double> reference(Stuck& s, double t0, double t1) {
  ErkStepper st(ButcherTable::from_arkode("ARKODE_FEHLBERG_13_7_8"), s.y.size(), abuopt::detail::rhs_plain,
                nullptr, 0, &s.rs, 1e-12, 1e-15, 10'000'000);
  st.reset(t0, s.y.data());
  st.set_stop_time(t1);
  while (st.step() == ErkStepper::Ok) {
  }
  EXPECT_EQ(st.t(), t1);
  return st.y();
}

TEST(StuckPropagator, RampThroughResonanceMatchesTightRungeKutta) {
  // the report's final profile: the 29.5 -> 100 Hz ramp from an arbitrary table state
  Stuck s(StartupProfile::report_final(), {0.4, 3.7});
  const double w = s.rs.nd.omega_n;
  s.y[0] = 0.01;
  s.y[1] = -0.004;
  s.y[2] = 0.003;
  s.y[3] = 0.02;
  const double t0 = 10.7 * w, t1 = 19.0 * w;
  const std::vector<double> ref = reference(s, t0, t1);
  StuckForcingTable tab(s.profile, s.rs.nd, 38.0 * w);
  StuckPropagator prop(tab, s.rs, no_roots);
  std::vector<int> roots;
  double t = t0, peak = 0;
  std::vector<double> y = s.y;
  ASSERT_EQ(prop.advance(t, y, t1, roots, peak), StuckPropagator::Stop);
  double scale = 0;
  for (int k = 0; k < 4; ++k) scale = std::max(scale, std::fabs(ref[k]));
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(y[k], ref[k], 1e-9 * scale) << k;
  for (std::size_t k = 4; k < y.size(); ++k) EXPECT_EQ(y[k], s.y[k]);
}

// Event location: the first time xbar falls below a level, against the stepper's polished roots.
void level_root(double, const double* y, double* g, void* user) {
  auto& rs = *static_cast<RunState*>(user);
  for (std::size_t k = 0; k < rs.nroots(); ++k) g[k] = 1.0;
  g[0] = y[0] + 0.012;
}

TEST(StuckPropagator, LocatesARootOnTheExactSolution) {
  Stuck s(StartupProfile::report_final(), {0.4, 3.7});
  const double w = s.rs.nd.omega_n;
  const double t0 = 11.0 * w, t1 = 19.0 * w;
  ErkStepper st(ButcherTable::from_arkode("ARKODE_FEHLBERG_13_7_8"), s.y.size(), abuopt::detail::rhs_plain,
                level_root, s.rs.nroots(), &s.rs, 1e-12, 1e-15, 10'000'000);
  st.set_polish_roots(true);
  st.reset(t0, s.y.data());
  st.set_stop_time(t1);
  ErkStepper::Status r;
  while ((r = st.step()) == ErkStepper::Ok) {
  }
  ASSERT_EQ(r, ErkStepper::Root);
  StuckForcingTable tab(s.profile, s.rs.nd, 38.0 * w);
  StuckPropagator prop(tab, s.rs, level_root);
  std::vector<int> roots;
  double t = t0, peak = 0;
  std::vector<double> y = s.y;
  ASSERT_EQ(prop.advance(t, y, t1, roots, peak), StuckPropagator::Root);
  EXPECT_EQ(roots[0], 1);
  EXPECT_NEAR(t, st.t(), 1e-8);
  EXPECT_LE(y[0] + 0.012, 0.0);  // on the far side of the crossing
  EXPECT_NEAR(y[0], -0.012, 1e-12);
}

TEST(StuckPropagator, WholeRunsAgreeWithTheRungeKuttaPathAtTightTolerance) {
  abuopt::SimulationSetup s;
  s.options.rtol = 1e-10;
  s.options.atol = 1e-13;
  s.options.stuck_integrator = abuopt::StuckIntegrator::RungeKutta;
  abuopt::Simulator rk(s);
  s.options.stuck_integrator = abuopt::StuckIntegrator::Exact;
  abuopt::Simulator ex(s);
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  double worst = 0;
  long exact_intervals = 0;
  for (int r = 0; r < 12; ++r) {
    const std::vector<double> b0 = {u(rng), u(rng)};
    const auto a = rk.run(b0), b = ex.run(b0);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a.events, b.events) << r;
    EXPECT_EQ(a.settled, b.settled) << r;
    for (int i = 0; i < 2; ++i) {
      const double d = std::fabs(std::remainder(a.beta_final[i] - b.beta_final[i], 2 * M_PI));
      worst = std::max(worst, d);
    }
    EXPECT_NEAR(a.max_amplitude_mm, b.max_amplitude_mm, 1e-3 * a.max_amplitude_mm) << r;
    EXPECT_LT(b.rhs_evaluations, a.rhs_evaluations) << r;
    exact_intervals += b.steps;
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(exact_intervals, 0);
}

}  // namespace

// The process-wide cache of forcing tables: the same (profile, omega_n, bbar, end time) gives the
// same table, any difference a new one; the least recently used of more than kSharedTables is
// dropped; a cached table equals a freshly built one.
TEST(StuckForcingTable, SharedTablesAreReusedForTheSameProfileAndTableOnly) {
  const auto nd = abuopt::NondimParameters::from(AbuParameters{});
  const StartupProfile p({{25.0, 0.5}, {40.0, 0.5}});
  const double tend = 2.0 * nd.omega_n;
  const auto a = StuckForcingTable::shared(p, nd, tend);
  EXPECT_EQ(StuckForcingTable::shared(p, nd, tend), a);
  EXPECT_NE(StuckForcingTable::shared(p, nd, 1.5 * nd.omega_n), a);                             // end time
  EXPECT_NE(StuckForcingTable::shared(StartupProfile({{25.0, 0.5}, {40.0, 0.6}}), nd, tend), a);  // a duration
  EXPECT_NE(StuckForcingTable::shared(StartupProfile({{25.0, 0.5}, {41.0, 0.5}}), nd, tend), a);  // a frequency
  auto nd2 = nd;
  nd2.bbar *= 1.01;
  EXPECT_NE(StuckForcingTable::shared(p, nd2, tend), a);
  // a is the least recently used of the five now: dropped, built again
  const auto b = StuckForcingTable::shared(p, nd, tend);
  EXPECT_NE(b, a);
  const StuckForcingTable fresh(p, nd, tend);
  ASSERT_EQ(b->intervals(), fresh.intervals());
  for (std::size_t j = 0; j < fresh.intervals(); ++j) {
    EXPECT_EQ(b->t(j), fresh.t(j));
    EXPECT_EQ(b->forcing(0, j), fresh.forcing(0, j));
    EXPECT_EQ(b->forcing(1, j), fresh.forcing(1, j));
  }
  EXPECT_EQ(StuckForcingTable::kSharedTables, 4u);
}

// The constant-speed span after the profile is not stored (issue 29: a run of end_time_s 1e6 grew
// to 12.6 GB): a table over 1e7 s is built at once, and its values on that span equal the
// quadrature of the same integrals (P_k by Gauss-Legendre, e^{lambda h}, e^{-i phi} from the
// profile) at interval boundaries near the profile's end, in the middle and at the end.
TEST(StuckForcingTable, TheConstantSpeedSpanAfterTheProfileIsComputedNotStored) {
  const auto nd = abuopt::NondimParameters::from(AbuParameters{});
  const StartupProfile p({{25.0, 1.0}, {29.5, 10.0}, {100.0, 8.0}});
  const double tend = 1e7 * nd.omega_n;
  const auto t0 = std::chrono::steady_clock::now();
  const StuckForcingTable tab(p, nd, tend);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0);
  EXPECT_GT(tab.intervals(), 1e9);  // every interval is still there, as values computed when asked
  EXPECT_EQ(tab.t(tab.intervals()), tend);
  const std::size_t stored = tab.interval(19.0 * nd.omega_n + 1e-9);  // the first interval of the span
  for (const std::size_t j : {stored, stored + 1, stored + 12345, tab.intervals() / 2, tab.intervals() - 2,
                              tab.intervals() - 1}) {
    const double a = tab.t(j), b = tab.t(j + 1);
    ASSERT_LT(a, b) << j;
    EXPECT_EQ(tab.interval(0.5 * (a + b)), j);
    EXPECT_EQ(tab.interval(a), j);
    // the phase grows to ~1e10 rad at the end: e^{i phi} from the span's start and from the
    // profile's revolution count agree to the rounding of a phase that large (~1e-6 rad)
    const double tol = j > tab.intervals() / 4 ? 1e-4 : 1e-9;
    cplx P[2];
    tab.partial(a, b - a, P);
    for (int k = 0; k < 2; ++k) {
      EXPECT_LT(std::abs(tab.forcing(k, j) - P[k]), tol * std::abs(P[k]) + 1e-12) << j;
      EXPECT_LT(std::abs(tab.decay(k, j) - std::exp(tab.lambda(k) * (b - a))), tol) << j;  // b - a rounds at 4e9
    }
    double W, Wp;
    cplx e;
    tab.sample(b, W, Wp, e);
    EXPECT_LT(std::abs(tab.unrotate(j + 1) - std::conj(e)), tol) << j;
    EXPECT_DOUBLE_EQ(tab.speed(j + 1), W);
    EXPECT_EQ(tab.speed_rate(j + 1), 0.0);
  }
}

// A Simulator's forcing (run_forcing_table.hpp, SimulatorForcing): each ladder rung is built once,
// by the first thread that asks, and every thread gets that one; the nominal table only for the
// Simulator's own omega_n and bbar.
TEST(SimulatorForcing, OneBuildPerRungAndNominalOnlyWhenItMatches) {
  const StartupProfile p({{25.0, 0.5}, {40.0, 0.5}});
  const NondimParameters nd = NondimParameters::from(AbuParameters{});
  SimulatorForcing f(p, nd, 2.0);
  const double wd = 2 * M_PI * 28.0;
  std::vector<std::shared_ptr<const ForcingSamples>> got(6);
  {
    std::vector<std::thread> threads;
    for (std::size_t i = 0; i < got.size(); ++i) threads.emplace_back([&, i] { got[i] = f.samples(wd); });
    for (auto& t : threads) t.join();
  }
  for (const auto& g : got) EXPECT_EQ(g, got[0]);
  EXPECT_EQ(f.rungs(), 1u);
  EXPECT_EQ(f.samples(wd * 1.001), got[0]);  // the same rung (ladder step at or above)
  EXPECT_NE(f.samples(wd * 1.05), got[0]);   // the next one up
  EXPECT_EQ(f.rungs(), 2u);
  EXPECT_EQ(got[0]->wd_ref_, ForcingSamples::ladder(wd));
  NondimParameters other = nd;
  other.omega_n *= 1.01;
  EXPECT_EQ(f.nominal(other), nullptr);
  const StuckForcingTable* t = f.nominal(nd);
  ASSERT_NE(t, nullptr);
  EXPECT_TRUE(t->matches(nd));
  EXPECT_EQ(f.nominal(nd), t);
}
