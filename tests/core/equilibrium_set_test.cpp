// Equilibrium sets against the closed forms of docs/equilibrium_sets.md.
#include "abuopt/core/equilibrium_set.hpp"

#include "abuopt/core/ball_contact.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <stdexcept>

using abuopt::AbuModel;
using abuopt::AbuParameters;
using abuopt::Ball;
using abuopt::BallMode;
using abuopt::EquilibriumSet;
using abuopt::ModelForces;
using abuopt::NondimParameters;

namespace {

// z = G(W) C with G = W^2 / (1 - W^2 + 2 i bbar W), C = mbar_I ebar + sum mbar_i e^{i beta_i}.
std::complex<double> closed_form_z(const AbuParameters& p, double f_hz, const std::vector<double>& beta) {
  const NondimParameters nd = NondimParameters::from(p);
  const double W = 2 * M_PI * f_hz / nd.omega_n;
  std::complex<double> C = nd.mbar_I * nd.ebar;
  for (std::size_t i = 0; i < beta.size(); ++i) C += nd.mbar[i] * std::polar(1.0, beta[i]);
  return W * W / std::complex<double>(1 - W * W, 2 * nd.bbar * W) * C;
}

double balancing_angle(const AbuParameters& p) {
  return std::acos(-p.imbalance_kgm() / (2 * p.balls[0].mass_kg * p.ball_track_radius_m));
}

}  // namespace

// The steady state is an equilibrium of the model itself: with all balls stuck at W' = 0 and the
// table at (x_s, y_s) at rest, AbuModel::evaluate gives x'' = y'' = 0 (to rounding, 1e-15).
TEST(EquilibriumSet, SteadyStateIsAnEquilibriumOfTheModel) {
  const AbuParameters p;
  const EquilibriumSet set(p);
  const NondimParameters nd = NondimParameters::from(p);
  const AbuModel model(nd);
  for (double f : {10.0, 28.9, 29.5, 100.0}) {
    for (auto beta : {std::vector<double>{0.3, 2.0}, std::vector<double>{4.0, 4.5}, std::vector<double>{0, 0}}) {
      const auto [xs, ys] = set.steady_state(f, beta);
      std::vector<double> y = {xs, ys, 0, 0, beta[0], beta[1], 0, 0};
      const BallMode modes[2] = {BallMode::Stick, BallMode::Stick};
      ModelForces forces(2);
      model.evaluate(y.data(), set.speed_ratio(f), 0.0, modes, 0.02, forces);
      EXPECT_NEAR(forces.xdd, 0.0, 1e-15) << f;
      EXPECT_NEAR(forces.ydd, 0.0, 1e-15) << f;
    }
  }
}

// fw_i = W^2 Im(z e^{-i beta_i}), fn_i = W^2 (1 + Re(z e^{-i beta_i})), relative 1e-9; the
// margins are mu fn - |fw| and membership is all margins >= 0.
TEST(EquilibriumSet, ForcesMatchClosedForm) {
  const AbuParameters p;
  const EquilibriumSet set(p, 0.02);
  for (double f : {15.0, 28.5, 29.5, 60.0}) {
    const std::vector<double> beta = {1.1, 5.2};
    const auto pt = set.point(f, beta);
    const std::complex<double> z = closed_form_z(p, f, beta);
    EXPECT_NEAR(pt.xbar, z.real(), 1e-12 * std::abs(z));
    EXPECT_NEAR(pt.ybar, z.imag(), 1e-12 * std::abs(z));
    const double W = set.speed_ratio(f);
    bool all_in = true;
    for (int i = 0; i < 2; ++i) {
      const std::complex<double> w = z * std::polar(1.0, -beta[i]);
      const double fw = W * W * w.imag(), fn = W * W * (1 + w.real());
      EXPECT_NEAR(pt.fw[i], fw, 1e-9 * fn) << f;
      EXPECT_NEAR(pt.fn[i], fn, 1e-9 * fn) << f;
      EXPECT_NEAR(pt.margins[i], 0.02 * fn - std::abs(fw), 1e-9 * fn) << f;
      all_in = all_in && 0.02 * fn - std::abs(fw) >= 0;
    }
    EXPECT_EQ(pt.in_set, all_in) << f;
  }
}

// One ball: amplitude = L |U| W^2 / sqrt((1 - W^2)^2 + (2 bbar W)^2), U = (m_I e + m L e^{i beta}) / (M L),
// relative 1e-12 at 5 frequencies x 3 angles; at W = 1 it is L |U| / (2 bbar).
TEST(EquilibriumSet, SingleBallAmplitudeIsJeffcottFormula) {
  AbuParameters p;
  p.balls = {Ball{}};
  const EquilibriumSet set(p);
  const NondimParameters nd = NondimParameters::from(p);
  const double M = p.total_mass_kg(), L = p.ball_track_radius_m;
  for (double beta : {0.0, 1.0, 3.0}) {
    const std::complex<double> U =
        (p.imbalance_kgm() + p.balls[0].mass_kg * L * std::polar(1.0, beta)) / (M * L);
    for (double f : {5.0, 20.0, 28.0, 31.0, 150.0}) {
      const double W = set.speed_ratio(f);
      const double expect_mm =
          1e3 * L * std::abs(U) * W * W / std::hypot(1 - W * W, 2 * nd.bbar * W);
      EXPECT_NEAR(set.point(f, {beta}).amplitude_mm, expect_mm, 1e-12 * expect_mm) << f << " " << beta;
    }
    const double at_resonance = set.point(set.natural_frequency_hz(), {beta}).amplitude_mm;
    EXPECT_NEAR(at_resonance, 1e3 * L * std::abs(U) / (2 * nd.bbar), 1e-9 * at_resonance);
  }
}

// mu = 0: the frictionless balancing positions beta = +-arccos(-m_I e / (2 m L)) (130.05 deg for the
// report) give zero amplitude (< 1e-15 mm) and are in the set; on a 64 x 64 grid no point is.
TEST(EquilibriumSet, FrictionlessSetIsOnlyTheEquilibria) {
  const AbuParameters p;
  const EquilibriumSet set(p, 0.0);
  const double b = balancing_angle(p);
  EXPECT_NEAR(b * 180 / M_PI, 130.05, 0.01);
  for (double f : {40.0, 100.0}) {
    const auto pt = set.point(f, {b, -b});
    EXPECT_LT(pt.amplitude_mm, 1e-15);
    EXPECT_TRUE(pt.in_set);
    EXPECT_EQ(set.coverage(f, 64), 0.0) << f;
  }
  // A configuration off the equilibria is outside with mu = 0 but inside with mu = 0.02 at 100 Hz.
  EXPECT_FALSE(set.point(100, {0.5, 2.0}).in_set);
  EXPECT_TRUE(EquilibriumSet(p, 0.02).point(100, {0.5, 2.0}).in_set);
}

// mu = 0.02 (report fig 4.3): the set covers the whole plane at 10 Hz and 100 Hz (coverage 1 on a
// 64 x 64 grid, closed-form full-coverage margin > 0.018) and shrinks near resonance (28.9 Hz:
// 0.29 of the plane, 28.5 Hz: 0.65, 29.5 Hz: 0.82; each +-0.01).
TEST(EquilibriumSet, CoversThePlaneAwayFromResonanceAndShrinksNearIt) {
  const EquilibriumSet set(AbuParameters{}, 0.02);
  for (double f : {10.0, 100.0}) {
    EXPECT_EQ(set.coverage(f, 64), 1.0) << f;
    EXPECT_GT(set.full_coverage_margin(f), 0.018) << f;
  }
  EXPECT_NEAR(set.coverage(28.9, 64), 0.29, 0.01);
  EXPECT_NEAR(set.coverage(28.5, 64), 0.65, 0.01);
  EXPECT_NEAR(set.coverage(29.5, 64), 0.82, 0.01);
  // The grid's coverage agrees with a grid() call and with the closed-form full-coverage test.
  const auto g = set.grid(28.9, 64);
  EXPECT_DOUBLE_EQ(g.coverage(), set.coverage(28.9, 64));
  EXPECT_LT(set.full_coverage_margin(28.9), 0);
}

// Scan 20..40 Hz in 0.1 Hz: the band where coverage < 1 contains the natural frequency (28.885 Hz)
// and lies inside the closed-form band [28.152, 29.692] Hz (+-0.001), within one step of its edges;
// the grid's coverage is exactly 1 wherever the closed-form margin is >= 0.
TEST(EquilibriumSet, ScanBandContainsNaturalFrequency) {
  const EquilibriumSet set(AbuParameters{}, 0.02);
  const auto s = set.scan(20, 40, 0.1, 48);
  EXPECT_NEAR(s.natural_frequency_hz, 28.885, 0.001);
  ASSERT_EQ(s.frequency_hz.size(), 201u);
  ASSERT_TRUE(s.band_hz.has_value());
  EXPECT_LT(s.band_hz->first, s.natural_frequency_hz);
  EXPECT_GT(s.band_hz->second, s.natural_frequency_hz);
  const auto exact = set.exact_band_hz(1, 200);
  ASSERT_TRUE(exact.has_value());
  EXPECT_NEAR(exact->first, 28.152, 0.001);
  EXPECT_NEAR(exact->second, 29.692, 0.001);
  EXPECT_GE(s.band_hz->first, exact->first);
  EXPECT_LE(s.band_hz->second, exact->second);
  EXPECT_LT(s.band_hz->first - exact->first, 0.1 + 1e-9);
  EXPECT_LT(exact->second - s.band_hz->second, 0.1 + 1e-9);
  for (std::size_t k = 0; k < s.frequency_hz.size(); ++k) {
    if (set.full_coverage_margin(s.frequency_hz[k]) >= 0) {
      EXPECT_EQ(s.coverage[k], 1.0) << s.frequency_hz[k];
    }
  }
  // No band at all within 40..100 Hz.
  EXPECT_FALSE(set.scan(40, 100, 5, 16).band_hz.has_value());
}

// N = 3: the grid spans the first two balls, the third sits at the given angle; each grid point
// equals point() at the same angles, and margins are stored per ball.
TEST(EquilibriumSet, GridOfThreeBallsMatchesPointTests) {
  AbuParameters p;
  p.balls = {Ball{}, Ball{}, Ball{}};
  const EquilibriumSet set(p);
  const auto g = set.grid(29.0, 8, {1.0});
  ASSERT_EQ(g.margins.size(), 8u * 8u * 3u);
  for (std::size_t i = 0; i < 8; i += 3)
    for (std::size_t j = 0; j < 8; j += 2) {
      const auto pt = set.point(29.0, {g.beta(i), g.beta(j), 1.0});
      const std::size_t k = g.index(i, j);
      EXPECT_EQ(g.in_set[k] != 0, pt.in_set);
      EXPECT_DOUBLE_EQ(g.amplitude_mm[k], pt.amplitude_mm);
      for (std::size_t b = 0; b < 3; ++b) EXPECT_DOUBLE_EQ(g.margins[k * 3 + b], pt.margins[b]);
    }
}

TEST(EquilibriumSet, RejectsBadArguments) {
  const EquilibriumSet set(AbuParameters{});
  EXPECT_THROW(set.point(0, {0, 0}), std::invalid_argument);
  EXPECT_THROW(set.point(10, {0}), std::invalid_argument);
  EXPECT_THROW(set.grid(10, 1), std::invalid_argument);
  EXPECT_THROW(set.grid(10, 8, {1.0}), std::invalid_argument);
  EXPECT_THROW(set.scan(10, 5, 1, 8), std::invalid_argument);
  EXPECT_THROW(set.scan(10, 20, 0, 8), std::invalid_argument);
}

// Without damping the static balance is singular at W = 1: infinite amplitude, not in the set.
TEST(EquilibriumSet, UndampedResonanceIsOutside) {
  AbuParameters p;
  p.damping_Ns_per_m = 0;
  const EquilibriumSet set(p);
  const auto pt = set.point(p.natural_frequency_hz(), {1, 2});
  // 2 pi f / omega_n may round off 1; then the amplitude is huge instead of infinite.
  EXPECT_GT(pt.amplitude_mm, 1e6);
  EXPECT_FALSE(pt.in_set);
}

// --- hard ball contact (docs/equilibrium_sets.md section 5) ----------------------------------------

namespace contact_tests {

AbuParameters hard() {
  AbuParameters p;
  p.ball_contact = abuopt::BallContact::Hard;
  return p;
}

TEST(EquilibriumSetContact, OverlappingPointsAreNeverInTheSetAndTheRestIsUnchanged) {
  const AbuParameters pn;
  const AbuParameters ph = hard();
  for (double f : {10.0, 28.9, 100.0}) {
    const auto gn = EquilibriumSet(pn).grid(f, 64);
    const auto gh = EquilibriumSet(ph).grid(f, 64);
    EXPECT_TRUE(gn.excluded.empty());
    ASSERT_EQ(gh.excluded.size(), 64u * 64u);
    std::size_t excluded = 0;
    for (std::size_t i = 0; i < 64; ++i)
      for (std::size_t j = 0; j < 64; ++j) {
        const std::size_t k = gh.index(i, j);
        const double clearance = abuopt::min_contact_clearance(ph, {gh.beta(i), gh.beta(j)});
        EXPECT_EQ(gh.excluded[k] != 0, clearance < -1e-9) << f << " " << i << " " << j;
        if (gh.excluded[k]) {
          ++excluded;
          EXPECT_EQ(gh.in_set[k], 0);
        } else {  // apart (no grid point touches): exactly the no-contact answer
          EXPECT_EQ(gh.in_set[k], gn.in_set[k]);
          EXPECT_EQ(gh.margins[2 * k], gn.margins[2 * k]);
          EXPECT_EQ(gh.margins[2 * k + 1], gn.margins[2 * k + 1]);
        }
      }
    // |beta_1 - beta_2| < 0.2617 rad (mod 2 pi) on a 2 pi / 64 grid: the diagonal and 2 neighbours
    // on each side, 5 of 64 per row.
    EXPECT_EQ(excluded, 64u * 5u) << f;
  }
  const abuopt::EquilibriumPoint p = EquilibriumSet(ph).point(10.0, {1.0, 1.1});
  EXPECT_TRUE(p.overlapping);
  EXPECT_FALSE(p.in_set);
}

// A touching pair is one stuck cluster (docs/model.md 11.4): with N_i = mbar_i fw_i and
// C_i = mbar_i mu fn_i from the no-contact forces (the same steady state), the rear ball's margin is
// min(C_r + N_r, C_r + C_f - N_r - N_f) / mbar_r and the front's min(C_f - N_f, C_r + C_f + N_r + N_f) / mbar_f.
TEST(EquilibriumSetContact, TouchingPairIsJudgedAsOneCluster) {
  const AbuParameters ph = hard();
  const double delta = abuopt::contact_spacing(ph, 0, 1);
  const double m = abuopt::NondimParameters::from(ph).mbar[0];
  for (double f : {10.0, 28.5, 28.9, 29.5, 100.0})
    for (double b1 : {0.0, 1.0, 2.5, 4.0}) {
      const std::vector<double> beta{b1, b1 + delta};  // ball 1 rear, ball 2 front
      const abuopt::EquilibriumPoint c = EquilibriumSet(ph).point(f, beta);
      const abuopt::EquilibriumPoint n = EquilibriumSet(AbuParameters{}).point(f, beta);
      ASSERT_TRUE(c.touching);
      ASSERT_FALSE(c.overlapping);
      const double mu = ph.friction_mu;
      const double Cr = m * mu * n.fn[0], Nr = m * n.fw[0], Cf = m * mu * n.fn[1], Nf = m * n.fw[1];
      const double rear = std::min(Cr + Nr, Cr + Cf - Nr - Nf) / m;
      const double front = std::min(Cf - Nf, Cr + Cf + Nr + Nf) / m;
      EXPECT_NEAR(c.margins[0], rear, 1e-12 * std::abs(n.fn[0])) << f << " " << b1;
      EXPECT_NEAR(c.margins[1], front, 1e-12 * std::abs(n.fn[1])) << f << " " << b1;
      EXPECT_EQ(c.in_set, rear >= -1e-9 * n.fn[0] && front >= -1e-9 * n.fn[1]) << f << " " << b1;
    }
}

TEST(EquilibriumSetContact, TouchingPairsFarFromResonanceAreInTheSet) {
  const EquilibriumSet set(hard());
  for (double f : {10.0, 100.0}) {
    ASSERT_GE(set.full_coverage_margin(f), 0.0);  // without contact the set covers the plane
    const auto line = set.contact_line(f, 256);
    EXPECT_DOUBLE_EQ(line.coverage(0), 1.0) << f;
    EXPECT_DOUBLE_EQ(line.coverage(1), 1.0) << f;
  }
  // Near resonance part of the contact line is outside (the cluster needs more than its cone).
  const auto near = set.contact_line(28.9, 256);
  EXPECT_LT(near.coverage(0), 1.0);
  EXPECT_THROW(EquilibriumSet(AbuParameters{}).contact_line(10.0, 16), std::invalid_argument);
}

}  // namespace contact_tests
