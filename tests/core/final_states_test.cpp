// Final states against the equilibrium set: the gauge, the lock gauge, the cluster floor and the
// early / late split of docs/equilibrium_sets.md section 6, against numbers worked by hand (the report's
// ABU, table 3.2: M = 0.32484 kg, L = 11.5 mm, bbar = 0.0108556, f_n = 28.8853 Hz).
#include "abuopt/core/final_states.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/equilibrium_set.hpp"

using abuopt::AbuParameters;
using abuopt::Ball;

namespace {

AbuParameters with_mu(double mu) {
  AbuParameters p;
  p.friction_mu = mu;
  return p;
}

// Six balls of the report's two balls' total mass, same material: m = 2 x 1.4e-4 / 6 kg, d = 3 mm (2/6)^(1/3).
AbuParameters six_balls(double mu = 0.02) {
  AbuParameters p = with_mu(mu);
  p.balls.assign(6, Ball{2 * 1.4e-4 / 6, 3.0e-3 * std::cbrt(2.0 / 6.0)});
  return p;
}

double contact_separation(const AbuParameters& p, std::size_t i, std::size_t j) {
  return 2 * std::asin((p.balls[i].diameter_m + p.balls[j].diameter_m) / (4 * p.ball_track_radius_m));
}

}  // namespace

// r_lock = 2 bbar sqrt(1 - bbar^2) M L mu / (1 + mu): 15.90e-7 kg m at mu 0.02, 23.62e-7 at mu 0.03
// (docs/equilibrium_sets.md section 4); it is the least r_in over the speeds.
TEST(FinalStates, LockRadiusAndInscribedDisc) {
  EXPECT_NEAR(abuopt::lock_radius_kgm(with_mu(0.02)) / 1e-7, 15.90, 0.005);
  EXPECT_NEAR(abuopt::lock_radius_kgm(with_mu(0.03)) / 1e-7, 23.62, 0.005);
  const AbuParameters p = with_mu(0.02);
  double least = INFINITY;
  for (int k = 0; k <= 20000; ++k) least = std::min(least, abuopt::inscribed_radius_kgm(p, 28 + 1e-4 * k));
  EXPECT_NEAR(least, abuopt::lock_radius_kgm(p), 1e-6 * least);
  // Six balls of the same total mass: the same M, so the same r_lock.
  EXPECT_NEAR(abuopt::lock_radius_kgm(six_balls()), abuopt::lock_radius_kgm(p), 1e-20);
}

// Both balls at beta = 0, at W = 1: G = -i / (2 bbar), so z = -i U / (2 bbar M L) is imaginary and
// w_1 = w_2 = z: g = |U| / (2 bbar M L mu) with U = m_I e + 2 m L = 2.072e-6 + 3.220e-6 = 5.292e-6 kg m;
// 5.292e-6 / (2 x 0.0108556 x 3.73566e-3 x 0.02) = 3.2624 (worked by hand).
TEST(FinalStates, GaugeWorkedByHand) {
  const AbuParameters p = with_mu(0.02);
  const double fn = p.natural_frequency_hz();
  EXPECT_NEAR(fn, 28.8853, 1e-4);
  EXPECT_NEAR(abuopt::equilibrium_gauge(p, fn, {0.0, 0.0}), 3.2624, 2e-4);
  // mu 0.03: the gauge scales with 1 / mu.
  EXPECT_NEAR(abuopt::equilibrium_gauge(with_mu(0.03), fn, {0.0, 0.0}), 3.2624 * 2 / 3, 2e-4);
  // At a balancing point (cos beta* = -m_I e / (2 m L), beta_2 = -beta_1) U = 0: the gauge is 0 at
  // every speed, and so is the lock gauge.
  const double b = std::acos(-p.imbalance_kgm() / (2 * 1.4e-4 * p.ball_track_radius_m));
  EXPECT_NEAR(b, 2.2698, 1e-4);  // 130.05 deg
  EXPECT_LT(abuopt::equilibrium_gauge(p, 29.0, {b, -b}), 1e-9);
  EXPECT_LT(abuopt::lock_gauge(p, {b, -b}), 1e-9);
}

// The gauge is <= 1 exactly where EquilibriumSet (the model's own stuck forces) says "in the set"
// (no contact), on random configurations and speeds.
TEST(FinalStates, GaugeAgreesWithTheEquilibriumSet) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> ang(0, 2 * M_PI), freq(20, 40);
  int inside = 0, checked = 0;
  for (double mu : {0.02, 0.03}) {
    const AbuParameters p = with_mu(mu);
    const abuopt::EquilibriumSet set(p);
    for (int k = 0; k < 4000; ++k) {
      const std::vector<double> beta{ang(rng), ang(rng)};
      const double f = freq(rng), g = abuopt::equilibrium_gauge(p, f, beta);
      if (std::abs(g - 1) < 1e-6) continue;  // on the boundary: rounding decides
      EXPECT_EQ(g <= 1, set.point(f, beta).in_set) << "f " << f << " beta " << beta[0] << ", " << beta[1];
      inside += g <= 1;
      ++checked;
    }
  }
  EXPECT_GT(inside, 1000);
  EXPECT_LT(inside, checked);
}

// The lemma: every configuration in the set at f has |U| >= g(f) r_in(f) (random configurations,
// speeds 20 - 40 Hz, mu 0.02 / 0.03 / 0.04; two balls and six).
TEST(FinalStates, DepthIsAtLeastTheGauge) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ang(0, 2 * M_PI), freq(20, 40);
  for (const AbuParameters& base : {with_mu(0.02), six_balls()}) {
    int inside = 0;
    double least = INFINITY;
    for (int k = 0; k < 20000; ++k) {
      AbuParameters p = base;
      p.friction_mu = std::vector<double>{0.02, 0.03, 0.04}[k % 3];
      std::vector<double> beta(p.balls.size());
      for (double& x : beta) x = ang(rng);
      const double f = freq(rng), g = abuopt::equilibrium_gauge(p, f, beta);
      if (g > 1 || g == 0) continue;
      ++inside;
      least = std::min(least, std::abs(abuopt::residual_complex_kgm(p, beta)) / (g * abuopt::inscribed_radius_kgm(p, f)));
    }
    EXPECT_GT(inside, 300);
    EXPECT_GE(least, 1 - 1e-12);
  }
}

// The lock band is where r_in <= 6 r_lock; the early / late edge where r_in = 2 r_lock below
// resonance: 28.36 Hz, the same at every mu (r_in / r_lock = max|G| / |G| does not depend on mu).
TEST(FinalStates, BandEdges) {
  for (double mu : {0.02, 0.03}) {
    const AbuParameters p = with_mu(mu);
    const double edge = abuopt::band_edge_hz(p);
    EXPECT_NEAR(edge, 28.36, 0.005);
    EXPECT_NEAR(abuopt::inscribed_radius_kgm(p, edge), 2 * abuopt::lock_radius_kgm(p), 1e-9 * edge);
    const auto [lo, hi] = abuopt::lock_band_hz(p);
    EXPECT_LT(lo, edge);
    EXPECT_GT(hi, p.natural_frequency_hz());
    EXPECT_NEAR(abuopt::inscribed_radius_kgm(p, lo), 6 * abuopt::lock_radius_kgm(p), 1e-9 * lo);
    EXPECT_NEAR(abuopt::inscribed_radius_kgm(p, hi), 6 * abuopt::lock_radius_kgm(p), 1e-9 * hi);
  }
}

// Uniform starts in the lock set (docs/equilibrium_sets.md section 6): it holds the disc |U| <= r_lock;
// on a 40 x 40 grid of the torus at mu 0.03 the lock set is 49.9 % and the disc 42.5 % (the Python
// runner's figures); the mean lock gauge of the locked starts is near 2/3 (uniform over a region
// measured by its own gauge: 0.653 on a 160^2 grid).
TEST(FinalStates, LockSetOfUniformStarts) {
  const AbuParameters p = with_mu(0.03);
  const double rl = abuopt::lock_radius_kgm(p);
  const int n = 40;
  int locked = 0, disc = 0;
  double gsum = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const std::vector<double> beta{2 * M_PI * (i + 0.5) / n, 2 * M_PI * (j + 0.5) / n};
      const double u = std::abs(abuopt::residual_complex_kgm(p, beta));
      const double g = abuopt::lock_gauge(p, beta);
      if (u <= rl) {
        ++disc;
        EXPECT_LE(g, 1.0) << "|U| <= r_lock must be locked";
      }
      if (g <= 1) {
        ++locked;
        gsum += g;
      }
    }
  EXPECT_NEAR(static_cast<double>(locked) / (n * n), 0.499, 0.006);
  EXPECT_NEAR(static_cast<double>(disc) / (n * n), 0.425, 0.006);
  EXPECT_NEAR(gsum / locked, 0.653, 0.03);
  const auto st = abuopt::lock_set_statistics(p, n);
  EXPECT_EQ(st.share, static_cast<double>(locked) / (n * n));
  EXPECT_NEAR(st.lock_gauge_mean, gsum / locked, 1e-12);
  EXPECT_EQ(st.reach, 0.0);
  EXPECT_EQ(st.unreached_share, st.share);
}

// The Euler term of a ramp at alpha = 314.16 rad/s^2 (the 2003 profile's peak) uses u = alpha / (mu omega_n^2)
// of the friction at resonance: 314.16 / (0.03 (2 pi 28.8853)^2) = 0.318 at mu 0.03, 0.477 at mu 0.02. On an
// 80 x 80 grid at mu 0.03 the lock set is 50.1 % of the torus at a mean depth of 0.739 r_lock, and the locked
// starts out of that reach (g_lock <= 1 - u) 24.8 % at 0.536 r_lock (the 160 x 160 figures of
// docs/equilibrium_sets.md section 6, within 0.01; the retired Python script's 26 .. 40 Hz band gave 50.2 %,
// 0.739, 24.9 %, 0.537).
TEST(FinalStates, LockSetOutOfTheRampsReach) {
  const AbuParameters p = with_mu(0.03);
  const auto st = abuopt::lock_set_statistics(p, 80, {}, 314.16);
  EXPECT_NEAR(st.reach, 0.318, 5e-4);
  EXPECT_NEAR(abuopt::lock_set_statistics(with_mu(0.02), 2, {}, 314.16).reach, 0.477, 5e-4);
  EXPECT_NEAR(st.share, 0.501, 0.01);
  EXPECT_NEAR(st.depth_mean, 0.739, 0.01);
  EXPECT_NEAR(st.lock_gauge_mean, 0.654, 0.01);
  EXPECT_NEAR(st.unreached_share, 0.248, 0.01);
  EXPECT_NEAR(st.unreached_depth_mean, 0.536, 0.01);
  EXPECT_LT(st.unreached_depth_mean, st.depth_mean);
  EXPECT_THROW(abuopt::lock_set_statistics(six_balls(), 8), std::invalid_argument);  // balls 3..6 need angles
}

// Two touching balls: s_c = 2 asin(d / 2L) = 0.2616 rad, floor |m_I e - 2 m L cos(s_c / 2)| = 11.20e-7;
// a close pair is within 0.04 rad of touching, across 2 pi too; apart, no floor.
TEST(FinalStates, PairFloorAndCloseness) {
  const AbuParameters p = with_mu(0.02);
  const double s = contact_separation(p, 0, 1);
  EXPECT_NEAR(s, 0.2616, 5e-5);
  EXPECT_NEAR(abuopt::cluster_floor_kgm(p, {1.0, 1.0 + s}) / 1e-7, 11.20, 0.005);
  EXPECT_EQ(abuopt::ball_clusters(p, {1.0, 1.0 + s + 0.039}).size(), 1u);
  EXPECT_EQ(abuopt::ball_clusters(p, {6.2, 6.2 + s - 2 * M_PI}).size(), 1u);
  EXPECT_EQ(abuopt::ball_clusters(p, {1.0, 1.0 + s + 0.05}).size(), 2u);
  EXPECT_EQ(abuopt::cluster_floor_kgm(p, {1.0, 1.0 + s + 0.05}), 0.0);
  // A close pair at separation s' leaves |m_I e - 2 m L cos(s'/2)|.
  const double s2 = s + 0.03;
  EXPECT_NEAR(abuopt::cluster_floor_kgm(p, {0.3, 0.3 + s2}),
              std::abs(p.imbalance_kgm() - 2 * 1.4e-4 * p.ball_track_radius_m * std::cos(s2 / 2)), 1e-18);
}

// Six balls of 2.08 mm (m = 4.6667e-5 kg): balancing pairs at pi -+ theta_k with sum cos theta_k =
// m_I e / (2 m L) = 1.9304 give U = 0 (gauge and lock gauge 0, six clusters, no floor); six touching
// (s_c = 0.18112 rad) have |U| = |m_I e - m L sin(3 s_c) / sin(s_c / 2)| = 9.96e-7, their floor; five
// touching and one apart: two clusters and no floor (2 max a < sum a).
TEST(FinalStates, SixBallClusters) {
  const AbuParameters p = six_balls();
  const double m = p.balls[0].mass_kg, L = p.ball_track_radius_m;
  EXPECT_NEAR(m, 4.6667e-5, 1e-9);
  EXPECT_NEAR(p.balls[0].diameter_m, 2.0801e-3, 1e-7);
  const double c = p.imbalance_kgm() / (2 * m * L);
  EXPECT_NEAR(c, 1.9304, 1e-4);
  std::vector<double> bal;
  for (double ck : {0.9, 0.65, c - 1.55}) {
    bal.push_back(M_PI - std::acos(ck));
    bal.push_back(M_PI + std::acos(ck));
  }
  EXPECT_LT(std::abs(abuopt::residual_complex_kgm(p, bal)), 1e-12 * p.imbalance_kgm());
  EXPECT_LT(abuopt::equilibrium_gauge(p, 28.9, bal), 1e-9);
  EXPECT_LT(abuopt::lock_gauge(p, bal), 1e-9);
  EXPECT_EQ(abuopt::ball_clusters(p, bal).size(), 6u);
  EXPECT_EQ(abuopt::cluster_floor_kgm(p, bal), 0.0);
  const double s = contact_separation(p, 0, 1);
  EXPECT_NEAR(s, 0.18112, 5e-5);
  std::vector<double> chain;
  for (int k = 0; k < 6; ++k) chain.push_back(M_PI + (k - 2.5) * s);
  const double closed = std::abs(p.imbalance_kgm() - m * L * std::sin(3 * s) / std::sin(s / 2));
  EXPECT_NEAR(closed / 1e-7, 9.96, 0.005);
  EXPECT_EQ(abuopt::ball_clusters(p, chain).size(), 1u);
  EXPECT_NEAR(std::abs(abuopt::residual_complex_kgm(p, chain)), closed, 1e-15);
  EXPECT_NEAR(abuopt::cluster_floor_kgm(p, chain), closed, 1e-15);
  std::vector<double> five = chain;
  five[5] += 0.5;
  EXPECT_EQ(abuopt::ball_clusters(p, five).size(), 2u);
  EXPECT_EQ(abuopt::cluster_floor_kgm(p, five), 0.0);
}

// The split on hand-made runs of six balls, profile 0 -> 25 Hz in 1 s, -> 29.5 Hz in 10 s, -> 100 Hz in 8 s:
// two runs settled in the first ramp (0.8 s and 0.9 s: 20.8 and 23.9 Hz, r_in > 2 r_lock), one at the
// balancing configuration (depth 0) and one the touching chain (depth 9.96e-7 / 15.90e-7 = 0.6264); two in
// the last ramp (12 s, 13 s), the chain and the balancing configuration; one not settled (left out).
// Early and late: 50 % each, both at a mean depth of 0.6264 / 2, half of each held by a cluster.
TEST(FinalStates, EarlyLateSplitOfHandMadeRuns) {
  const AbuParameters p = six_balls();
  const abuopt::StartupProfile prof = abuopt::StartupProfile::report_final();
  const double s = contact_separation(p, 0, 1), m = p.balls[0].mass_kg, L = p.ball_track_radius_m;
  std::vector<double> chain, bal;
  for (int k = 0; k < 6; ++k) chain.push_back(M_PI + (k - 2.5) * s);
  const double c = p.imbalance_kgm() / (2 * m * L);
  for (double ck : {0.9, 0.65, c - 1.55}) {
    bal.push_back(M_PI - std::acos(ck));
    bal.push_back(M_PI + std::acos(ck));
  }
  auto run = [](long i, std::vector<double> b, bool settled, double t) {
    abuopt::FinalStateInput r;
    r.index = i;
    r.beta_final = std::move(b);
    r.settled = settled;
    r.settling_time_s = t;
    r.friction_mu = 0.02;
    return r;
  };
  const std::vector<abuopt::FinalStateInput> runs{run(0, bal, true, 0.8), run(1, chain, true, 0.9),
                                                  run(2, chain, true, 12.0), run(3, bal, true, 13.0),
                                                  run(4, chain, false, 0.0)};
  const double depth = std::abs(p.imbalance_kgm() - m * L * std::sin(3 * s) / std::sin(s / 2)) / abuopt::lock_radius_kgm(p);
  EXPECT_NEAR(depth, 0.6264, 2e-4);
  const auto a = abuopt::analyse_final_states(p, prof, runs);
  EXPECT_EQ(a.settled, 4u);
  EXPECT_EQ(a.not_settled, 1u);
  EXPECT_EQ(a.early.count, 2u);
  EXPECT_EQ(a.late.count, 2u);
  EXPECT_NEAR(a.early.share, 0.5, 1e-15);
  EXPECT_NEAR(a.early.depth_mean, depth / 2, 1e-12);
  EXPECT_NEAR(a.late.depth_mean, depth / 2, 1e-12);
  EXPECT_NEAR(a.depth_mean, depth / 2, 1e-12);
  EXPECT_NEAR(a.early.held_share, 0.5, 1e-15);
  EXPECT_NEAR(a.records[0].settle_hz, 25 * (0.8 - std::sin(2 * M_PI * 0.8) / (2 * M_PI)), 1e-9);
  EXPECT_EQ(a.records[2].largest_cluster, 6u);
  // Wilson interval of 2 / 4: 0.5 -+ 1.96 sqrt(0.25 / 4 + 1.96^2 / 64) / (1 + 1.96^2 / 4) = [0.150, 0.850].
  EXPECT_NEAR(a.early.share_ci.lo, 0.150, 5e-4);
  EXPECT_NEAR(a.early.share_ci.hi, 0.850, 5e-4);
  // Passage split at 25 Hz: the profile first reaches it at t = 1 s (the end of the first ramp).
  const auto b = abuopt::analyse_final_states(p, prof, runs, abuopt::EarlySplit::passage, 25.0);
  ASSERT_TRUE(b.edge_time_s.has_value());
  EXPECT_NEAR(*b.edge_time_s, 1.0, 1e-12);
  EXPECT_EQ(b.early.count, 2u);
  // At 28.36 Hz (the default edge), in the second segment: f(t) = 25 + 4.5 (phi - sin phi) / (2 pi).
  const auto t = abuopt::first_passage_s(prof, 28.0);
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(prof.frequency_hz(*t), 28.0, 1e-9);
  EXPECT_FALSE(abuopt::first_passage_s(prof, 150.0).has_value());
  // A run with the wrong number of angles is refused, naming the runs.
  auto bad = runs;
  bad[1].beta_final.pop_back();
  EXPECT_THROW(abuopt::analyse_final_states(p, prof, bad), abuopt::ConfigError);
}

// Near a balancing point uniform starts are uniform in the U plane (docs/equilibrium_sets.md section 6):
// dU/dbeta has the columns i m L e^{i beta_k}, singular values sqrt(2) m L (cos(s/2), sin(s/2)) at separation
// s; at the balancing separation s* = 1.7435 rad 1.083 and 0.910 m L (ratio 1.190), checked by central
// differences; and the share of the torus with |U| <= 0.15 m L is r^2 / (2 pi (m L)^2 sin s*) = 0.00364.
TEST(FinalStates, UniformStartsNearTheBalancingPoints) {
  const AbuParameters p = with_mu(0.02);
  const double mL = 1.4e-4 * p.ball_track_radius_m;
  const double s = 2 * std::acos(p.imbalance_kgm() / (2 * mL));
  EXPECT_NEAR(s, 1.7435, 5e-5);
  const std::vector<double> b{M_PI - s / 2, M_PI + s / 2};
  EXPECT_LT(std::abs(abuopt::residual_complex_kgm(p, b)), 1e-12 * p.imbalance_kgm());
  const double h = 1e-6;
  std::complex<double> c[2];
  for (int k = 0; k < 2; ++k) {
    auto up = b, dn = b;
    up[k] += h;
    dn[k] -= h;
    c[k] = (abuopt::residual_complex_kgm(p, up) - abuopt::residual_complex_kgm(p, dn)) / (2 * h);
  }
  const double fro2 = std::norm(c[0]) + std::norm(c[1]);
  const double det = std::abs(c[0].real() * c[1].imag() - c[1].real() * c[0].imag());
  const double hi = std::sqrt((fro2 + std::sqrt(fro2 * fro2 - 4 * det * det)) / 2), lo = det / hi;
  EXPECT_NEAR(hi / mL, std::sqrt(2.0) * std::sin(s / 2), 1e-7);
  EXPECT_NEAR(lo / mL, std::sqrt(2.0) * std::abs(std::cos(s / 2)), 1e-7);
  EXPECT_NEAR(hi / mL, 1.083, 5e-4);
  EXPECT_NEAR(lo / mL, 0.910, 5e-4);
  EXPECT_NEAR(hi / lo, 1.190, 1e-3);
  const double r = 0.15 * mL;
  const int g = 1200;
  long hits = 0;
  for (int i = 0; i < g; ++i)
    for (int j = 0; j < g; ++j)
      hits += std::abs(abuopt::residual_complex_kgm(p, {2 * M_PI * (i + 0.5) / g, 2 * M_PI * (j + 0.5) / g})) <= r;
  const double expect = r * r / (2 * M_PI * mL * mL * std::sin(s));
  EXPECT_NEAR(expect, 0.00364, 5e-6);
  EXPECT_NEAR(static_cast<double>(hits) / (g * g), expect, 0.05 * expect);
}
