// Properties of the simulator over random parameters (fixed seeds, so a failure is replayable):
//  1. every run ends with a status, and a run that ends ok has no NaN or inf in its outcome;
//  2. frictionless and undamped at constant speed, the Jacobi integral (energy in the rotating
//     frame) is conserved (derivation below);
//  3. balls that start stuck stay stuck, exactly, when the equilibrium set covers the whole torus
//     at every speed the profile passes through (slow ramp, checked with full_coverage_margin).
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "abuopt/core/equilibrium_set.hpp"
#include "abuopt/core/simulator.hpp"

namespace {

using namespace abuopt;

constexpr double kTwoPi = 6.283185307179586;

struct Rng {
  std::mt19937_64 g;
  explicit Rng(std::uint64_t seed) : g(seed) {}
  double operator()(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(g); }
  std::size_t count(std::size_t lo, std::size_t hi) { return std::uniform_int_distribution<std::size_t>(lo, hi)(g); }
};

AbuParameters random_abu(Rng& r) {
  AbuParameters a;
  a.table_mass_kg = r(0.1, 1.0);
  a.damping_Ns_per_m = r(0.0, 5.0);
  a.stiffness_N_per_m = r(3e3, 3e4);
  a.ball_track_radius_m = r(0.008, 0.03);
  a.imbalance_mass_kg = r(1e-4, 1.5e-3);
  a.eccentricity_m = r(1e-3, 6e-3);
  a.friction_mu = r(0.0, 0.1);
  a.balls.resize(r.count(1, 3));
  for (Ball& b : a.balls) {
    b.mass_kg = r(5e-5, 4e-4);
    b.diameter_m = r(1.5e-3, 0.5 * a.ball_track_radius_m);
  }
  return a;
}

TEST(SimulatorProperties, EveryRunEndsWithAStatusAndNoNaN) {
  Rng r(20261123);
  int ok = 0;
  const int cases = 40;
  for (int c = 0; c < cases; ++c) {
    SimulationSetup s;
    s.abu = random_abu(r);
    std::vector<InclinedSineSegment> segs(r.count(1, 3));
    for (auto& g : segs) g = {r(0.0, 60.0), r(0.05, 0.5)};
    s.profile = StartupProfile(segs, r(0.0, 10.0));
    if (c % 3 == 0) {
      s.motor.kind = MotorKind::PI;
      s.motor.omega_m_rad_s = r(1.0, 20.0);
      s.motor.xi = r(0.2, 1.5);
    }
    s.options.method = c % 4 == 1 ? FrictionMethod::SwitchModel : FrictionMethod::EventDriven;
    s.options.max_steps = 300'000;
    const Simulator sim(s);
    std::vector<double> beta0(s.abu.balls.size());
    for (double& b : beta0) b = r(0.0, kTwoPi);
    const RunOutcome o = sim.run(beta0);
    const std::string status = to_string(o.status);
    EXPECT_FALSE(status.empty()) << "case " << c;
    if (!o.ok()) continue;
    ++ok;
    EXPECT_TRUE(std::isfinite(o.residual_imbalance_kgm)) << "case " << c;
    EXPECT_TRUE(std::isfinite(o.residual_imbalance_x_kgm)) << "case " << c;
    EXPECT_TRUE(std::isfinite(o.max_amplitude_mm)) << "case " << c;
    EXPECT_TRUE(std::isfinite(o.settling_time_s)) << "case " << c;
    EXPECT_EQ(o.beta_final.size(), beta0.size());
    for (double b : o.beta_final) EXPECT_TRUE(std::isfinite(b) && b >= 0 && b < kTwoPi) << "case " << c << ": " << b;
  }
  EXPECT_GE(ok, cases * 3 / 4);  // the ranges are physical: most runs end normally
}

// Jacobi integral. In the frame rotating at constant Omega, with table position (x, y) and ball
// angles beta_i (spec section 1), the Lagrangian has no explicit time dependence, so
//   h = T2 - T0 + V
// is conserved when nothing dissipates (b = 0, no ball damping, mu = 0), where
//   T2 = 1/2 M (x'^2 + y'^2) + sum m_i L beta_i' (-sin beta_i x' + cos beta_i y')
//        + 1/2 sum m_i L^2 (1 + 4/10) beta_i'^2     (rolling balls: J_i = m_i d_i^2 / 10)
//   T0 = 1/2 Omega^2 [M_T (x^2 + y^2) + m_I ((x + e)^2 + y^2)
//        + sum m_i ((x + L cos beta_i)^2 + (y + L sin beta_i)^2)]
//   V  = 1/2 k (x^2 + y^2),   M = M_T + m_I + sum m_i.
// (The ball spin Omega - 2 L beta_i'/d_i adds a term linear in beta_i', which drops out of h, and
// a constant.) Velocities come from central differences of the recorded trajectory.
double jacobi(const AbuParameters& a, double omega, const TrajectoryPoint& prev, const TrajectoryPoint& at,
              const TrajectoryPoint& next) {
  const double dt = next.t_s - prev.t_s;
  const double x = at.x_m, y = at.y_m;
  const double xd = (next.x_m - prev.x_m) / dt, yd = (next.y_m - prev.y_m) / dt;
  const double L = a.ball_track_radius_m;
  double M = a.table_mass_kg + a.imbalance_mass_kg;
  for (const Ball& b : a.balls) M += b.mass_kg;
  double t2 = 0.5 * M * (xd * xd + yd * yd);
  double t0 = a.table_mass_kg * (x * x + y * y) +
              a.imbalance_mass_kg * ((x + a.eccentricity_m) * (x + a.eccentricity_m) + y * y);
  for (std::size_t i = 0; i < a.balls.size(); ++i) {
    const double m = a.balls[i].mass_kg, c = std::cos(at.beta[i]), s = std::sin(at.beta[i]);
    double db = next.beta[i] - prev.beta[i];
    db = std::remainder(db, kTwoPi);  // angles are wrapped to [0, 2 pi)
    const double bd = db / dt;
    t2 += m * L * bd * (-s * xd + c * yd) + 0.5 * m * L * L * 1.4 * bd * bd;
    t0 += m * ((x + L * c) * (x + L * c) + (y + L * s) * (y + L * s));
  }
  t0 *= 0.5 * omega * omega;
  const double v = 0.5 * a.stiffness_N_per_m * (x * x + y * y);
  return t2 - t0 + v;
}

TEST(SimulatorProperties, FrictionlessUndampedRunsConserveTheJacobiIntegral) {
  Rng r(777);
  for (int c = 0; c < 6; ++c) {
    SimulationSetup s;
    s.abu = random_abu(r);
    s.abu.damping_Ns_per_m = 0;
    s.abu.ball_damping_Nms = 0;
    s.abu.friction_mu = 0;
    const double f = r(5.0, 60.0);
    s.profile = StartupProfile({{f, 1.0}}, f);  // constant speed from t = 0
    s.options.rtol = 1e-11;
    s.options.atol = 1e-13;
    s.options.end_time_s = 0.1;
    s.options.trajectory_interval_s = 2e-5;
    const Simulator sim(s);
    std::vector<double> beta0(s.abu.balls.size());
    for (double& b : beta0) b = r(0.0, kTwoPi);
    std::vector<TrajectoryPoint> tr;
    const RunOutcome o = sim.run(beta0, {}, &tr);
    ASSERT_TRUE(o.ok()) << o.message;
    ASSERT_GT(tr.size(), 1000u);
    const double omega = kTwoPi * f;
    const double h0 = jacobi(s.abu, omega, tr[9], tr[10], tr[11]);
    // Scale: the largest of the terms (|h| itself may be near zero).
    const double scale = 0.5 * omega * omega * s.abu.imbalance_mass_kg * s.abu.eccentricity_m * s.abu.eccentricity_m +
                         std::fabs(h0);
    double worst = 0;
    for (std::size_t k = 10; k + 11 < tr.size(); k += 50)
      worst = std::max(worst, std::fabs(jacobi(s.abu, omega, tr[k - 1], tr[k], tr[k + 1]) - h0));
    // Central differences over 2e-5 s: O((omega_n dt)^2) ~ 1e-5 relative error in velocities.
    EXPECT_LT(worst / scale, 1e-4) << "case " << c << ", f = " << f << " Hz, h0 = " << h0;
  }
}

// The equilibrium set is a constant-speed notion; a profile adds the disc's angular acceleration
// W' to the friction a ball needs (h_b's W' term, about W' per unit of m_i omega_n^2 L), while the
// spare friction of the full-coverage margin m(W) is m W^2. So the run starts at a constant speed
// f0 = 0.3 f_n (from rest, the table's transient there is about |C| W0^2, small against mu W0^2)
// and ramps so slowly that W' <= m_req W0^2 / 4, where m_req is the smallest margin over the ramp.
TEST(SimulatorProperties, StuckBallsStayStuckWhereTheSetCoversThePlane) {
  Rng r(4242);
  int tested = 0;
  for (int c = 0; c < 40 && tested < 8; ++c) {
    SimulationSetup s;
    s.abu = random_abu(r);
    s.abu.friction_mu = r(0.05, 0.3);
    const EquilibriumSet set(s.abu);
    const double fn = s.abu.natural_frequency_hz();
    const double f0 = 0.3 * fn;
    const double m_req = 0.3 * s.abu.friction_mu;
    double f_end = 0;
    for (double f = f0; f < 0.9 * fn; f += 0.01 * fn) {
      if (set.full_coverage_margin(f) <= m_req) break;
      f_end = f;
    }
    if (f_end < f0 + 1.0) continue;
    ++tested;
    const double w0 = f0 / fn, dw = (f_end - f0) / fn;
    const double dtbar = 2.0 * dw / (0.25 * m_req * w0 * w0);  // the inclined sine peaks at 2 dW/dt
    s.profile = StartupProfile({{f0, 0.5}, {f_end, dtbar / (2 * M_PI * fn)}}, f0);
    const Simulator sim(s);
    std::vector<double> beta0(s.abu.balls.size());
    for (double& b : beta0) b = r(0.0, kTwoPi);
    const RunOutcome o = sim.run(beta0);
    ASSERT_TRUE(o.ok()) << o.message;
    EXPECT_EQ(o.events, 0) << "case " << c << ", " << f0 << " -> " << f_end << " Hz";
    ASSERT_EQ(o.beta_final.size(), beta0.size());
    for (std::size_t i = 0; i < beta0.size(); ++i) EXPECT_EQ(o.beta_final[i], beta0[i]) << "case " << c;
  }
  EXPECT_GE(tested, 4);
}

}  // namespace
