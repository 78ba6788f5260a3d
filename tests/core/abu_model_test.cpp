// The reduced equations against what follows from their derivation (docs/model.md):
// exact equilibria, the rotating-frame energy (Jacobi integral), and the normal force.
#include "abuopt/core/abu_model.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace abuopt;

namespace {

AbuParameters report() { return AbuParameters{}; }

// Jacobi integral (energy in the rotating frame at constant W, b = 0, mu = 0), non-dimensional
// (divided by M omega_n^2 L^2): E = T2 - T0 + V with, per body,
//   table+imbalance: T2 = 1/2 (1 - sum mbar_i)(x'^2 + y'^2)
//                    T0 = 1/2 W^2 [(1 - sum mbar_i - mbar_I)(x^2 + y^2) + mbar_I((x + ebar)^2 + y^2)]
//   ball i:          T2 = 1/2 mbar_i [(x' - s beta')^2 + (y' + c beta')^2] + 1/2 mbar_i Jbar (2 ... )
// written out below from the velocities, independently of the code under test.
double jacobi(const NondimParameters& nd, const std::vector<double>& y, double W) {
  const std::size_t n = nd.mbar.size();
  double msum = 0;
  for (double m : nd.mbar) msum += m;
  const double x = y[0], yy = y[1], xd = y[2], yd = y[3];
  double T2 = 0.5 * (1 - msum) * (xd * xd + yd * yd);
  double T0 = 0.5 * W * W * ((1 - msum - nd.mbar_I) * (x * x + yy * yy) + nd.mbar_I * ((x + nd.ebar) * (x + nd.ebar) + yy * yy));
  for (std::size_t i = 0; i < n; ++i) {
    const double b = y[4 + i], bd = y[4 + n + i];
    const double s = std::sin(b), c = std::cos(b);
    const double vx = xd - s * bd, vy = yd + c * bd;
    // ball spin relative part: J (2L/d)^2 beta'^2 / 2 -> nondim mbar Jbar d^2 (2/d)^2 / 2 = 2 mbar Jbar
    T2 += 0.5 * nd.mbar[i] * (vx * vx + vy * vy) + 2.0 * nd.mbar[i] * NondimParameters::Jbar * bd * bd;
    T0 += 0.5 * W * W * nd.mbar[i] * ((x + c) * (x + c) + (yy + s) * (yy + s));
  }
  const double V = 0.5 * (x * x + yy * yy);  // k/(M omega_n^2) = 1
  return T2 - T0 + V;
}

void rk4(const AbuModel& m, std::vector<double>& y, double W, double h, const std::vector<BallMode>& modes) {
  const std::size_t n = m.n_balls(), N = y.size();
  ModelForces f(n);
  auto deriv = [&](const std::vector<double>& s, std::vector<double>& d) {
    m.evaluate(s.data(), W, 0.0, modes.data(), 0.0, f);
    d[0] = s[2];
    d[1] = s[3];
    d[2] = f.xdd;
    d[3] = f.ydd;
    for (std::size_t i = 0; i < n; ++i) {
      d[4 + i] = s[4 + n + i];
      d[4 + n + i] = f.betadd[i];
    }
  };
  std::vector<double> k1(N), k2(N), k3(N), k4(N), t(N);
  deriv(y, k1);
  for (std::size_t j = 0; j < N; ++j) t[j] = y[j] + 0.5 * h * k1[j];
  deriv(t, k2);
  for (std::size_t j = 0; j < N; ++j) t[j] = y[j] + 0.5 * h * k2[j];
  deriv(t, k3);
  for (std::size_t j = 0; j < N; ++j) t[j] = y[j] + h * k3[j];
  deriv(t, k4);
  for (std::size_t j = 0; j < N; ++j) y[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
}

}  // namespace

TEST(AbuModel, FrictionlessBalancingPositionIsAnExactEquilibrium) {
  const AbuParameters p = report();
  const AbuModel m(NondimParameters::from(p));
  const double b = std::acos(-p.imbalance_kgm() / (2 * p.balls[0].mass_kg * p.ball_track_radius_m));
  std::vector<double> y = {0, 0, 0, 0, b, -b, 0, 0};
  ModelForces f(2);
  const std::vector<BallMode> modes = {BallMode::SlipForward, BallMode::SlipForward};
  for (double W : {0.5, 1.0, 3.4}) {
    m.evaluate(y.data(), W, 0.0, modes.data(), 0.0, f);
    EXPECT_NEAR(f.xdd, 0, 1e-15);
    EXPECT_NEAR(f.ydd, 0, 1e-15);
    EXPECT_NEAR(f.betadd[0], 0, 1e-15);
    EXPECT_NEAR(f.betadd[1], 0, 1e-15);
    // the normal force is the centripetal one, (beta' + W)^2 = W^2
    EXPECT_NEAR(f.fn[0], W * W, 1e-14);
  }
  double ix, iy;
  const double beta[2] = {b, -b};
  AbuModel::imbalance_vector(p, beta, ix, iy);
  EXPECT_NEAR(std::hypot(ix, iy), 0.0, 1e-20);
}

TEST(AbuModel, JacobiIntegralIsConservedWithoutDampingAndFriction) {
  AbuParameters p = report();
  p.damping_Ns_per_m = 0;
  p.balls.push_back(Ball{2e-4, 4e-3});  // three unequal balls
  const NondimParameters nd = NondimParameters::from(p);
  const AbuModel m(nd);
  const std::vector<BallMode> modes(3, BallMode::SlipForward);
  std::vector<double> y = {0.01, -0.02, 0.003, 0.001, 0.3, 2.0, 4.0, 0.05, -0.02, 0.01};
  for (double W : {0.7, 1.3}) {
    std::vector<double> s = y;
    const double E0 = jacobi(nd, s, W);
    for (int k = 0; k < 20000; ++k) rk4(m, s, W, 1e-3, modes);
    const double E1 = jacobi(nd, s, W);
    // RK4 at h = 1e-3 over 20 time units: drift ~ h^4 -> far below 1e-10 of the energy scale
    EXPECT_NEAR(E1, E0, 1e-10 * (std::fabs(E0) + 1e-3)) << "W = " << W;
    EXPECT_GT(std::fabs(s[4 + 3] - y[4 + 3]) + std::fabs(s[0] - y[0]), 1e-3);  // it did move
  }
}

TEST(AbuModel, StuckBallNeedsNoFrictionAtItsFrictionlessEquilibrium) {
  const AbuParameters p = report();
  const AbuModel m(NondimParameters::from(p));
  const double b = std::acos(-p.imbalance_kgm() / (2 * p.balls[0].mass_kg * p.ball_track_radius_m));
  std::vector<double> y = {0, 0, 0, 0, b, -b, 0, 0};
  ModelForces f(2);
  const std::vector<BallMode> modes = {BallMode::Stick, BallMode::Stick};
  m.evaluate(y.data(), 2.0, 0.0, modes.data(), 0.02, f);
  EXPECT_NEAR(f.fw[0], 0, 1e-15);
  EXPECT_NEAR(f.fw[1], 0, 1e-15);
  EXPECT_GT(AbuModel::stick_margin(f, 0, 0.02), 0.0);
}

TEST(AbuModel, ChooseModesAtRestStartsBallsSlippingBackward) {
  // Just after a start from rest the disc accelerates and the balls lag behind.
  const AbuModel m(NondimParameters::from(report()));
  std::vector<double> y = {0, 0, 0, 0, 1.0, 4.0, 0, 0};
  std::vector<BallMode> modes(2, BallMode::Stick);
  ModelForces f(2);
  EXPECT_TRUE(m.choose_modes(y.data(), 1e-12, 1e-8, 0.02, 0.0, modes.data(), f));
  EXPECT_EQ(modes[0], BallMode::SlipBackward);
  EXPECT_EQ(modes[1], BallMode::SlipBackward);
  EXPECT_LT(f.betadd[0], 0);
  // with a large friction they would stick instead
  modes.assign(2, BallMode::Stick);
  EXPECT_TRUE(m.choose_modes(y.data(), 0.5, 1e-3, 0.9, 0.0, modes.data(), f));
  EXPECT_EQ(modes[0], BallMode::Stick);
  EXPECT_EQ(modes[1], BallMode::Stick);
}
