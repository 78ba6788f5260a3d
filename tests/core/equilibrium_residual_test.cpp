// The residual imbalance an equilibrium set allows, against the closed forms of
// docs/equilibrium_sets.md section 4.
#include "abuopt/core/equilibrium_residual.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <stdexcept>

using abuopt::AbuParameters;
using abuopt::Ball;
using abuopt::EquilibriumSet;
using abuopt::NondimParameters;

namespace {

double report_balancing_angle(const AbuParameters& p) {
  return std::acos(-p.imbalance_kgm() / (2 * p.balls[0].mass_kg * p.ball_track_radius_m));
}

double magnitude(const AbuParameters& p, const std::vector<double>& beta) {
  const auto u = abuopt::residual_vector_kgm(p, beta);
  return std::hypot(u.first, u.second);
}

// Largest change of |U| between a point and a grid neighbour h away in one angle: m L h.
double grid_step_kgm(const AbuParameters& p, std::size_t n) {
  return p.balls[0].mass_kg * p.ball_track_radius_m * 2 * M_PI / static_cast<double>(n);
}

}  // namespace

// Two equal balls: the balancing points are (beta*, -beta*) and (-beta*, beta*) with
// cos beta* = -m_I e / (2 m L) (130.05 deg for the report); U = 0 there.
TEST(EquilibriumResidual, BalancingAnglesOfTwoEqualBalls) {
  const AbuParameters p;
  const double b = report_balancing_angle(p);
  EXPECT_NEAR(b * 180 / M_PI, 130.05, 0.01);
  const auto bal = abuopt::balancing_angles(p);
  ASSERT_EQ(bal.size(), 2u);
  for (const auto& [b1, b2] : bal) {
    EXPECT_LT(magnitude(p, {b1, b2}), 1e-20);
    EXPECT_NEAR(std::cos(b1), std::cos(b), 1e-12);
    EXPECT_NEAR(std::sin(b1), -std::sin(b2), 1e-12);
  }
  // Three balls, the third at 3 rad: still U = 0 at both solutions (at 1 rad |T| > 2 m L: none).
  AbuParameters q;
  q.balls = {Ball{}, Ball{}, Ball{}};
  const auto bal3 = abuopt::balancing_angles(q, {3.0});
  ASSERT_EQ(bal3.size(), 2u);
  for (const auto& [b1, b2] : bal3) EXPECT_LT(magnitude(q, {b1, b2, 3.0}), 1e-20);
  EXPECT_TRUE(abuopt::balancing_angles(q, {1.0}).empty());
  // Balls too light to balance: no solution.
  AbuParameters light;
  light.balls = {Ball{1e-5, 3e-3}, Ball{1e-5, 3e-3}};
  EXPECT_TRUE(abuopt::balancing_angles(light).empty());
  EXPECT_THROW(abuopt::balancing_angles(q), std::invalid_argument);
}

// The balancing points have z = 0, so fw = 0 and fn = W^2: they are in the set at every speed with
// the friction margin mu W^2 (below, through and above resonance).
TEST(EquilibriumResidual, BalancingPointsAreInEverySet) {
  const AbuParameters p;
  const EquilibriumSet set(p, 0.02);
  for (double f : {5.0, 20.0, 28.0, 28.5, 28.885, 29.0, 29.2, 29.5, 30.0, 35.0, 100.0, 200.0}) {
    const double W = set.speed_ratio(f);
    for (const auto& [b1, b2] : abuopt::balancing_angles(p)) {
      const auto pt = set.point(f, {b1, b2});
      EXPECT_TRUE(pt.in_set) << f;
      EXPECT_LT(pt.amplitude_mm, 1e-12) << f;
      EXPECT_NEAR(pt.min_margin, 0.02 * W * W, 1e-12 * W * W) << f;
    }
    // On the grid, the part around them is never empty and holds a point within one grid step.
    const auto r = abuopt::equilibrium_residual(set, f, 64);
    EXPECT_GT(r.around_balance.magnitude.count, 0u) << f;
    EXPECT_LE(r.around_balance.magnitude.min, std::sqrt(2.0) * grid_step_kgm(p, 64)) << f;
  }
}

// r_in(f) = M L mu / ((1 + mu) |G(W)|): every grid point with |U| <= r_in is in the set, the
// boundary of the part around the balancing points is no more than one grid step inside r_in, and
// the disc is nearly tight near resonance (a point outside the set within 1.3 r_in).
TEST(EquilibriumResidual, InscribedDiscIsInsideTheSet) {
  const AbuParameters p;
  const EquilibriumSet set(p, 0.02);
  const NondimParameters nd = NondimParameters::from(p);
  const std::size_t n = 96;
  for (double f : {27.0, 28.2, 28.6, 28.885, 29.1, 29.3, 29.6, 31.0}) {
    const double W = set.speed_ratio(f);
    const double G = W * W / std::abs(std::complex<double>(1 - W * W, 2 * nd.bbar * W));
    const double r_in = abuopt::inscribed_residual_kgm(set, f);
    EXPECT_NEAR(r_in, p.total_mass_kg() * p.ball_track_radius_m * 0.02 / (1.02 * G), 1e-12 * r_in) << f;
    const auto g = set.grid(f, n);
    double closest_outside = INFINITY;
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) {
        const double u = magnitude(p, {g.beta(i), g.beta(j)});
        if (u <= r_in) {
          EXPECT_TRUE(g.in_set[g.index(i, j)]) << f << " " << i << " " << j;
        }
        if (!g.in_set[g.index(i, j)]) closest_outside = std::min(closest_outside, u);
      }
    const auto r = abuopt::equilibrium_residual(set, f, n);
    if (r.boundary.magnitude.count > 0) {
      EXPECT_GE(r.boundary.magnitude.min, r_in - grid_step_kgm(p, n)) << f;
    }
    if (f > 28.5 && f < 29.4) {
      EXPECT_LT(closest_outside, 1.3 * r_in) << f;
    }
  }
}

// r_lock = min_f r_in(f) = M L mu 2 bbar sqrt(1 - bbar^2) / (1 + mu): 15.90e-7 kg m for the report's
// ABU at mu = 0.02, and no r_in on a fine scan falls below it.
TEST(EquilibriumResidual, LockedResidualIsTheSmallestInscribedRadius) {
  const AbuParameters p;
  const EquilibriumSet set(p, 0.02);
  const NondimParameters nd = NondimParameters::from(p);
  const double lock = abuopt::locked_residual_kgm(set);
  EXPECT_NEAR(lock, p.total_mass_kg() * p.ball_track_radius_m * 0.02 * 2 * nd.bbar * std::sqrt(1 - nd.bbar * nd.bbar) / 1.02,
              1e-15);
  EXPECT_NEAR(lock / 1e-7, 15.90, 0.01);
  double smallest = INFINITY;
  for (double f = 20; f <= 40; f += 0.001) smallest = std::min(smallest, abuopt::inscribed_residual_kgm(set, f));
  EXPECT_GE(smallest, lock * (1 - 1e-12));
  EXPECT_LT(smallest, lock * (1 + 1e-6));
}

// Away from resonance the set is the whole torus: the statistics over the set are those of every
// grid point (max |U| = m_I e + 2 m L at beta = (0, 0), a grid point), the part around the
// balancing points is everything and has no boundary.
TEST(EquilibriumResidual, FullCoverageStatisticsAreThoseOfTheTorus) {
  const AbuParameters p;
  const EquilibriumSet set(p, 0.02);
  const std::size_t n = 64;
  const auto r = abuopt::equilibrium_residual(set, 10.0, n);
  EXPECT_EQ(r.coverage, 1.0);
  EXPECT_EQ(r.in_set.magnitude.count, n * n);
  EXPECT_EQ(r.around_balance.magnitude.count, n * n);
  EXPECT_EQ(r.around_balance_fraction, 1.0);
  EXPECT_EQ(r.boundary.magnitude.count, 0u);
  EXPECT_TRUE(std::isnan(r.boundary.magnitude.median));
  const double top = p.imbalance_kgm() + 2 * p.balls[0].mass_kg * p.ball_track_radius_m;
  EXPECT_NEAR(r.in_set.magnitude.max, top, 1e-18);
  EXPECT_NEAR(r.in_set.x.max, top, 1e-18);
  // Independent sums over the grid.
  double sum = 0, sum_x = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      const double b1 = 2 * M_PI * i / n, b2 = 2 * M_PI * j / n;
      sum += magnitude(p, {b1, b2});
      sum_x += std::abs(abuopt::residual_vector_kgm(p, {b1, b2}).first);
    }
  EXPECT_NEAR(r.in_set.magnitude.mean, sum / (n * n), 1e-18);
  EXPECT_NEAR(r.in_set.x.mean, sum_x / (n * n), 1e-18);
  EXPECT_LE(r.in_set.magnitude.min, r.in_set.magnitude.median);
  EXPECT_LE(r.in_set.magnitude.median, r.in_set.magnitude.max);
}

// Near resonance the set shrinks: its statistics are over fewer points, the median |I_r| over the set
// is below the torus median, the part around the balancing points lies inside the set.
TEST(EquilibriumResidual, NearResonanceTheSetAllowsLessImbalance) {
  const AbuParameters p;
  const EquilibriumSet set(p, 0.02);
  const auto far = abuopt::equilibrium_residual(set, 10.0, 64);
  const auto near = abuopt::equilibrium_residual(set, 28.9, 64);
  EXPECT_NEAR(near.coverage, 0.29, 0.01);
  EXPECT_EQ(near.in_set.magnitude.count, static_cast<std::size_t>(std::lround(near.coverage * 64 * 64)));
  EXPECT_LT(near.in_set.magnitude.median, far.in_set.magnitude.median);
  EXPECT_LE(near.around_balance.magnitude.count, near.in_set.magnitude.count);
  EXPECT_GT(near.boundary.magnitude.count, 0u);
  EXPECT_LE(near.boundary.magnitude.count, near.around_balance.magnitude.count);
  const auto scan = abuopt::equilibrium_residual_scan(set, 28, 30, 0.5, 32);
  ASSERT_EQ(scan.size(), 5u);
  EXPECT_DOUBLE_EQ(scan[2].frequency_hz, 29.0);
  EXPECT_THROW(abuopt::equilibrium_residual_scan(set, 30, 28, 0.5, 32), std::invalid_argument);
  EXPECT_THROW(abuopt::inscribed_residual_kgm(set, 0), std::invalid_argument);
}

// Two equal balls s apart leave at least |m_I e - 2 m L cos(s/2)|: 11.48e-7 kg m when they sit
// together (s = 0), 0 at the balancing separation 2 (pi - beta*) = 1.7435 rad; brute force over the
// pair's orientation never goes below the bound and reaches it within 1e-3 of the orientation grid.
TEST(EquilibriumResidual, PairSeparationFloor) {
  const AbuParameters p;
  const double mL = p.balls[0].mass_kg * p.ball_track_radius_m;
  EXPECT_NEAR(abuopt::pair_separation_floor_kgm(p, 0) / 1e-7, 11.48, 1e-9);
  const double s_bal = 2 * (M_PI - report_balancing_angle(p));
  EXPECT_NEAR(s_bal, 1.7435, 1e-4);
  EXPECT_NEAR(abuopt::pair_separation_floor_kgm(p, s_bal), 0, 1e-18);
  for (double s : {0.0, 0.262, 0.5, 1.0, 1.06, 1.5, 2.5, M_PI}) {
    const double bound = abuopt::pair_separation_floor_kgm(p, s);
    EXPECT_NEAR(bound, std::abs(p.imbalance_kgm() - 2 * mL * std::cos(s / 2)), 1e-18) << s;
    double best = INFINITY;
    for (int k = 0; k < 20000; ++k) {
      const double th = 2 * M_PI * k / 20000;
      best = std::min(best, magnitude(p, {th, th + s}));
    }
    EXPECT_GE(best, bound * (1 - 1e-12)) << s;
    EXPECT_LT(best - bound, 1e-3 * 2 * mL) << s;
  }
  AbuParameters three;
  three.balls = {Ball{}, Ball{}, Ball{}};
  EXPECT_THROW(abuopt::pair_separation_floor_kgm(three, 0), std::invalid_argument);
}
