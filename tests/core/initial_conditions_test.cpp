// Initial-condition designs and per-run uncertain parameters: sizes, ranges, stratification,
// reproducibility from the seed, replay of one point alone.
#include "abuopt/core/initial_conditions.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/uncertain_parameters.hpp"

namespace abuopt {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

InitialConditionDesign make(InitialConditionKind k, std::size_t count, std::size_t balls, std::uint64_t seed,
                            bool shift = true) {
  InitialConditionDesign d;
  d.kind = k;
  d.count = count;
  d.balls = balls;
  d.seed = seed;
  d.random_shift = shift;
  return d;
}

void expect_on_torus(const std::vector<std::vector<double>>& pts, std::size_t balls) {
  for (const auto& p : pts) {
    ASSERT_EQ(p.size(), balls);
    for (double b : p) {
      EXPECT_GE(b, 0.0);
      EXPECT_LT(b, kTwoPi);
    }
  }
}

// Number of points per stratum [2 pi s / m, 2 pi (s+1) / m) on axis j.
std::vector<int> strata(const std::vector<std::vector<double>>& pts, std::size_t j, std::size_t m) {
  std::vector<int> c(m, 0);
  // Points of grids and nets lie exactly on the left edges: a tiny epsilon absorbs the rounding
  // of 2 pi u / (2 pi).
  for (const auto& p : pts) ++c[std::min<std::size_t>(m - 1, static_cast<std::size_t>(p[j] / kTwoPi * m + 1e-9))];
  return c;
}

TEST(InitialConditions, GridIsTheReportGridRowMajor) {
  InitialConditionDesign d;
  d.kind = InitialConditionKind::Grid;
  d.grid_points_per_axis = 4;
  d.balls = 2;
  ASSERT_EQ(d.size(), 16u);
  const auto pts = generate_initial_conditions(d);
  ASSERT_EQ(pts.size(), 16u);
  // index = 4 k1 + k2, beta = 2 pi k / 4
  EXPECT_DOUBLE_EQ(pts[0][0], 0.0);
  EXPECT_DOUBLE_EQ(pts[0][1], 0.0);
  EXPECT_DOUBLE_EQ(pts[1][0], 0.0);
  EXPECT_DOUBLE_EQ(pts[1][1], M_PI / 2);
  EXPECT_DOUBLE_EQ(pts[6][0], M_PI / 2);
  EXPECT_DOUBLE_EQ(pts[6][1], M_PI);
  EXPECT_DOUBLE_EQ(pts[15][0], 3 * M_PI / 2);
  EXPECT_DOUBLE_EQ(pts[15][1], 3 * M_PI / 2);
  std::set<std::vector<double>> unique(pts.begin(), pts.end());
  EXPECT_EQ(unique.size(), 16u);
}

TEST(InitialConditions, GridGeneralisesToThreeBalls) {
  InitialConditionDesign d;
  d.grid_points_per_axis = 3;
  d.balls = 3;
  const auto pts = generate_initial_conditions(d);
  ASSERT_EQ(pts.size(), 27u);
  expect_on_torus(pts, 3);
  for (std::size_t j = 0; j < 3; ++j) EXPECT_EQ(strata(pts, j, 3), (std::vector<int>{9, 9, 9}));
  EXPECT_DOUBLE_EQ(pts[5][0], 0.0);              // 5 = 0*9 + 1*3 + 2
  EXPECT_DOUBLE_EQ(pts[5][1], kTwoPi / 3);
  EXPECT_DOUBLE_EQ(pts[5][2], 2 * kTwoPi / 3);
}

TEST(InitialConditions, RandomIsSeededAndPrefixStable) {
  const auto a = generate_initial_conditions(make(InitialConditionKind::Random, 200, 2, 7));
  const auto b = generate_initial_conditions(make(InitialConditionKind::Random, 200, 2, 7));
  const auto c = generate_initial_conditions(make(InitialConditionKind::Random, 200, 2, 8));
  const auto small = generate_initial_conditions(make(InitialConditionKind::Random, 50, 2, 7));
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  EXPECT_TRUE(std::equal(small.begin(), small.end(), a.begin()));
  expect_on_torus(a, 2);
  // Crude uniformity: mean of each coordinate near pi (sd of the mean ~ 1.81/sqrt(200) = 0.13).
  for (std::size_t j = 0; j < 2; ++j) {
    double m = 0;
    for (const auto& p : a) m += p[j];
    EXPECT_NEAR(m / a.size(), M_PI, 0.5);
  }
}

TEST(InitialConditions, LatinHypercubeHasOnePointPerStratum) {
  for (std::size_t n : {1u, 7u, 64u, 1000u}) {
    const auto pts = generate_initial_conditions(make(InitialConditionKind::LatinHypercube, n, 3, 11));
    ASSERT_EQ(pts.size(), n);
    expect_on_torus(pts, 3);
    for (std::size_t j = 0; j < 3; ++j) EXPECT_EQ(strata(pts, j, n), std::vector<int>(n, 1)) << "n " << n;
  }
  EXPECT_NE(generate_initial_conditions(make(InitialConditionKind::LatinHypercube, 64, 2, 1)),
            generate_initial_conditions(make(InitialConditionKind::LatinHypercube, 64, 2, 2)));
}

TEST(InitialConditions, UnshiftedSobolStartsWithTheKnownPoints) {
  const auto pts = generate_initial_conditions(make(InitialConditionKind::Sobol, 4, 2, 0, false));
  // Sobol' 2-D: (0,0), (1/2,1/2), (3/4,1/4), (1/4,3/4) (Gray-code order), scaled by 2 pi.
  const double expected[4][2] = {{0, 0}, {0.5, 0.5}, {0.75, 0.25}, {0.25, 0.75}};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 2; ++j) EXPECT_DOUBLE_EQ(pts[i][j], kTwoPi * expected[i][j]) << i << "," << j;
}

TEST(InitialConditions, SobolIsANetInTwoDimensions) {
  // The first 2^m points of a Sobol' sequence are a (0, m, 2)-net: each elementary box of area
  // 2^-m (2^a x 2^(m-a) strata) holds exactly one point. Holds for the shifted one as well, on the
  // torus, when the shift is a multiple of the grid (not in general), so test the plain sequence.
  const std::size_t m = 8, n = std::size_t{1} << m;
  const auto pts = generate_initial_conditions(make(InitialConditionKind::Sobol, n, 2, 0, false));
  for (std::size_t a = 0; a <= m; ++a) {
    const std::size_t nx = std::size_t{1} << a, ny = std::size_t{1} << (m - a);
    std::vector<int> count(n, 0);
    for (const auto& p : pts) {
      const auto ix = static_cast<std::size_t>(p[0] / kTwoPi * nx + 1e-9);
      const auto iy = static_cast<std::size_t>(p[1] / kTwoPi * ny + 1e-9);
      ++count[ix * ny + iy];
    }
    EXPECT_EQ(count, std::vector<int>(n, 1)) << "boxes " << nx << " x " << ny;
  }
}

TEST(InitialConditions, SobolAndHaltonStratifyEveryAxis) {
  // 1-D projections: the first 2^m Sobol' points (any dimension) and the first p^k Halton points
  // in base p hit every stratum once (unshifted).
  const auto sob = generate_initial_conditions(make(InitialConditionKind::Sobol, 64, kSobolMaxDimension, 0, false));
  for (std::size_t j = 0; j < kSobolMaxDimension; ++j) EXPECT_EQ(strata(sob, j, 64), std::vector<int>(64, 1)) << j;
  const auto hal = generate_initial_conditions(make(InitialConditionKind::Halton, 25, 3, 0, false));
  EXPECT_EQ(strata(hal, 1, 9), std::vector<int>({3, 3, 3, 3, 3, 2, 3, 3, 2}));  // base 3, 25 pts
  EXPECT_EQ(strata(hal, 2, 25), std::vector<int>(25, 1));                      // base 5
  EXPECT_DOUBLE_EQ(hal[1][0], M_PI);                                           // 1/2
  EXPECT_DOUBLE_EQ(hal[1][1], kTwoPi / 3);                                     // 1/3
  EXPECT_DOUBLE_EQ(hal[7][2], kTwoPi * (2.0 / 5 + 1.0 / 25));                  // 7 = (12)_5
}

TEST(InitialConditions, ShiftDependsOnSeedOnly) {
  auto d = make(InitialConditionKind::Halton, 32, 2, 3);
  const auto a = generate_initial_conditions(d);
  EXPECT_EQ(a, generate_initial_conditions(d));
  d.seed = 4;
  EXPECT_NE(a, generate_initial_conditions(d));
  expect_on_torus(a, 2);
  EXPECT_NE(a[0], (std::vector<double>{0.0, 0.0}));  // the shift moves the point 0
}

TEST(InitialConditions, PointAtIndexEqualsTheWholeDesign) {
  for (auto k : {InitialConditionKind::Grid, InitialConditionKind::Random, InitialConditionKind::LatinHypercube,
                 InitialConditionKind::Halton, InitialConditionKind::Sobol}) {
    auto d = make(k, 40, 2, 5);
    d.grid_points_per_axis = 6;
    const auto all = generate_initial_conditions(d);
    ASSERT_EQ(all.size(), d.size()) << to_string(k);
    for (std::size_t i = 0; i < all.size(); i += 7) EXPECT_EQ(initial_condition_at(d, i), all[i]) << to_string(k);
  }
}

TEST(InitialConditions, KindNamesRoundTripAndBadOnesAreConfigErrors) {
  for (auto k : {InitialConditionKind::Grid, InitialConditionKind::Random, InitialConditionKind::LatinHypercube,
                 InitialConditionKind::Halton, InitialConditionKind::Sobol})
    EXPECT_EQ(initial_condition_kind_from_string(to_string(k)), k);
  try {
    initial_condition_kind_from_string("latin", "montecarlo.design");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "montecarlo.design = latin: must be one of: grid, random, lhs, halton, sobol");
  }
}

TEST(InitialConditions, InvalidDesignsAreConfigErrors) {
  InitialConditionDesign d;
  d.grid_points_per_axis = 0;
  EXPECT_THROW(validate(d), ConfigError);
  d = make(InitialConditionKind::Random, 0, 2, 1);
  EXPECT_THROW(validate(d), ConfigError);
  d = make(InitialConditionKind::Sobol, 8, kSobolMaxDimension + 1, 1);
  EXPECT_THROW(validate(d), ConfigError);
  d = InitialConditionDesign{};
  d.grid_points_per_axis = 1000;
  d.balls = 4;  // 10^12 points
  EXPECT_THROW(validate(d), ConfigError);
}

// --- uncertain parameters ----------------------------------------------------------------------

TEST(UncertainParameters, NominalGivesNoOverrides) {
  UncertainParameters u;
  EXPECT_TRUE(u.deterministic());
  const RunOverrides o = sample_overrides(u, AbuParameters{}, 1, 5);
  EXPECT_FALSE(o.friction_mu.has_value());
  EXPECT_FALSE(o.imbalance_mass_kg.has_value());
  EXPECT_EQ(o.imbalance_angle_rad, 0.0);
}

TEST(UncertainParameters, ListIsCycledByRunIndex) {
  UncertainParameters u;
  u.friction.sampling = FrictionSampling::List;
  u.friction.values = {0.02, 0.03, 0.04};
  EXPECT_DOUBLE_EQ(*sample_overrides(u, {}, 9, 0).friction_mu, 0.02);
  EXPECT_DOUBLE_EQ(*sample_overrides(u, {}, 9, 4).friction_mu, 0.03);
  EXPECT_DOUBLE_EQ(*sample_overrides(u, {}, 9, 8).friction_mu, 0.04);
}

TEST(UncertainParameters, RangesAreReplayableFromSeedAndIndex) {
  UncertainParameters u;
  u.friction.sampling = FrictionSampling::Range;
  u.friction.lo = 0.02;
  u.friction.hi = 0.04;
  u.imbalance_mass.sampling = ImbalanceMassSampling::RelativeRange;
  u.imbalance_mass.relative_lo = -0.1;
  u.imbalance_mass.relative_hi = 0.1;
  u.imbalance_angle.sampling = ImbalanceAngleSampling::Uniform;
  EXPECT_FALSE(u.deterministic());
  AbuParameters abu;
  double mu_sum = 0;
  std::set<double> distinct;
  for (std::size_t i = 0; i < 500; ++i) {
    const RunOverrides o = sample_overrides(u, abu, 42, i);
    // same values when asked again, in any order
    const RunOverrides again = sample_overrides(u, abu, 42, i);
    EXPECT_EQ(*o.friction_mu, *again.friction_mu);
    EXPECT_EQ(*o.imbalance_mass_kg, *again.imbalance_mass_kg);
    EXPECT_EQ(o.imbalance_angle_rad, again.imbalance_angle_rad);
    EXPECT_GE(*o.friction_mu, 0.02);
    EXPECT_LE(*o.friction_mu, 0.04);
    EXPECT_GE(*o.imbalance_mass_kg, 0.9 * abu.imbalance_mass_kg);
    EXPECT_LE(*o.imbalance_mass_kg, 1.1 * abu.imbalance_mass_kg);
    EXPECT_GE(o.imbalance_angle_rad, 0.0);
    EXPECT_LT(o.imbalance_angle_rad, kTwoPi);
    mu_sum += *o.friction_mu;
    distinct.insert(*o.friction_mu);
  }
  EXPECT_NEAR(mu_sum / 500, 0.03, 0.0015);  // sd of the mean 0.0058/sqrt(500) = 0.00026
  EXPECT_EQ(distinct.size(), 500u);
  EXPECT_NE(*sample_overrides(u, abu, 42, 3).friction_mu, *sample_overrides(u, abu, 43, 3).friction_mu);
  // Parameters have independent streams: making the mass nominal leaves mu of each run unchanged.
  UncertainParameters v = u;
  v.imbalance_mass.sampling = ImbalanceMassSampling::Nominal;
  EXPECT_EQ(*sample_overrides(v, abu, 42, 17).friction_mu, *sample_overrides(u, abu, 42, 17).friction_mu);
}

TEST(UncertainParameters, ReadFromYaml) {
  auto root = YamlReader::load_string(
      "montecarlo:\n"
      "  friction: {range: [0.02, 0.04]}\n"
      "  imbalance: {mass_relative_range: [-0.05, 0.05], angle: uniform}\n");
  YamlReader mc = root.child("montecarlo");
  const UncertainParameters u = read_uncertain_parameters(mc);
  mc.finish();
  EXPECT_EQ(u.friction.sampling, FrictionSampling::Range);
  EXPECT_DOUBLE_EQ(u.friction.lo, 0.02);
  EXPECT_DOUBLE_EQ(u.friction.hi, 0.04);
  EXPECT_EQ(u.imbalance_mass.sampling, ImbalanceMassSampling::RelativeRange);
  EXPECT_DOUBLE_EQ(u.imbalance_mass.relative_lo, -0.05);
  EXPECT_EQ(u.imbalance_angle.sampling, ImbalanceAngleSampling::Uniform);
}

TEST(UncertainParameters, BadYamlNamesTheKey) {
  auto expect_error = [](const std::string& yaml, const std::string& text) {
    auto root = YamlReader::load_string(yaml);
    YamlReader mc = root.child("montecarlo");
    try {
      read_uncertain_parameters(mc);
      mc.finish();
      FAIL() << "no error for " << yaml;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  expect_error("montecarlo: {friction: {range: [0.04, 0.02]}}", "montecarlo.friction.range = [0.04, 0.02]");
  expect_error("montecarlo: {friction: {fixed: -1}}", "montecarlo.friction.fixed = -1: must be >= 0");
  expect_error("montecarlo: {friction: {fixed: 0.02, list: [0.1]}}", "exactly one of");
  expect_error("montecarlo: {friction: {list: []}}", "montecarlo.friction.list = []");
  expect_error("montecarlo: {imbalance: {mass_relative_range: [-1.5, 0]}}", "lo must be > -1");
  expect_error("montecarlo: {imbalance: {angle: random}}", "montecarlo.imbalance.angle = random");
  expect_error("montecarlo: {imbalance: {massrange: [0, 1]}}", "montecarlo.imbalance.massrange");
}

}  // namespace
}  // namespace abuopt
