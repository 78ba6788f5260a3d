// Hard ball-ball contact (docs/model.md section 11) against closed forms.
#include "abuopt/core/ball_contact.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/abu_model.hpp"
#include "abuopt/core/sim_counters.hpp"
#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/core/simulator.hpp"

using namespace abuopt;

namespace {

AbuParameters three_balls() {
  AbuParameters p;
  p.balls = {Ball{1.4e-4, 3.0e-3}, Ball{2.0e-4, 3.5e-3}, Ball{1.0e-4, 2.5e-3}};
  p.ball_contact = BallContact::Hard;
  return p;
}

Eigen::MatrixXd mass(const NondimParameters& nd, const std::vector<double>& beta) {
  const std::size_t m = 2 + beta.size();
  const std::vector<double> M = mass_matrix(nd, beta.data());
  Eigen::MatrixXd E(m, m);
  for (std::size_t a = 0; a < m; ++a)
    for (std::size_t b = 0; b < m; ++b) E(a, b) = M[a * m + b];
  return E;
}

}  // namespace

TEST(BallContact, SpacingIsTwoArcsinesOfTheDiameters) {
  const AbuParameters p;  // report: 3 mm balls on L = 11.5 mm: 0.262 rad
  EXPECT_NEAR(contact_spacing(p, 0, 1), 2 * std::asin(3e-3 / (2 * 1.15e-2)), 1e-15);
  EXPECT_NEAR(contact_spacing(p, 0, 1), 0.2617, 1e-4);
}

TEST(BallContact, FreeFlightImpactConservesMomentumAndLosesOneMinusESquaredOfTheRelativeEnergy) {
  // Impact of balls 0 and 1 (three balls, all free, table free): the impulse acts along the gap
  // gradient G = e_1 - e_0 only, so the generalised momenta p = M qdot of the table (x, y), of the
  // third ball and p_0 + p_1 are conserved; the kinetic energy drops by (1 - e^2) m_eff v_rel^2 / 2
  // with m_eff = 1 / (G M^-1 G^T), and the relative speed reverses times e.
  const AbuParameters p = three_balls();
  const NondimParameters nd = NondimParameters::from(p);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double e : {0.0, 0.5, 0.8, 1.0}) {
    for (int trial = 0; trial < 20; ++trial) {
      const std::vector<double> beta = {0.3 + u(rng), 0.3 + u(rng) + 0.5, 4.0 + u(rng)};
      std::vector<double> q = {0.01 * u(rng), 0.01 * u(rng), 0.5, -0.5 + 0.1 * u(rng), u(rng)};  // 0 runs into 1
      const Eigen::MatrixXd M = mass(nd, beta);
      Eigen::VectorXd G = Eigen::VectorXd::Zero(5);
      G(3) = 1;
      G(2) = -1;
      const double m_eff = 1.0 / G.dot(M.ldlt().solve(G));
      const double vrel = q[3] - q[2];
      const Eigen::VectorXd p0 = M * Eigen::Map<Eigen::VectorXd>(q.data(), 5);
      const double T0 = kinetic_energy(nd, beta.data(), q);
      const double P = apply_impact(nd, beta.data(), q, {0, 1, 2}, {0, 0, 0}, 0, 1, e);
      const Eigen::VectorXd p1 = M * Eigen::Map<Eigen::VectorXd>(q.data(), 5);
      const double T1 = kinetic_energy(nd, beta.data(), q);
      EXPECT_NEAR(P, (1 + e) * m_eff * -vrel, 1e-14);
      EXPECT_NEAR(p1(0), p0(0), 1e-15);
      EXPECT_NEAR(p1(1), p0(1), 1e-15);
      EXPECT_NEAR(p1(4), p0(4), 1e-15);
      EXPECT_NEAR(p1(2) + p1(3), p0(2) + p0(3), 1e-15);
      EXPECT_NEAR(q[3] - q[2], -e * vrel, 1e-12);
      EXPECT_NEAR(T0 - T1, (1 - e * e) * 0.5 * m_eff * vrel * vrel, 1e-12 * T0);
    }
  }
}

TEST(BallContact, AStuckBystanderIsHeldAndAClusterIsHitAsOneBody) {
  const AbuParameters p = three_balls();
  const NondimParameters nd = NondimParameters::from(p);
  const std::vector<double> beta = {1.0, 1.0 + contact_spacing(p, 0, 1), 1.0 + contact_spacing(p, 0, 1) + 0.5};
  std::vector<double> q = {0, 0, 0.4, 0.0, 0.0};
  // balls 1 and 2 are one cluster (stuck, but struck: not held); none held
  apply_impact(nd, beta.data(), q, {0, 1, 1}, {0, 1, 1}, 0, 1, 0.0);
  EXPECT_DOUBLE_EQ(q[3], q[4]);          // the cluster moves as one
  EXPECT_NEAR(q[2], q[3], 1e-15);        // plastic: no relative speed left
  std::vector<double> r = {0, 0, 0.4, 0.0, 0.0};
  apply_impact(nd, beta.data(), r, {0, 1, 2}, {0, 0, 1}, 0, 1, 0.5);
  EXPECT_EQ(r[4], 0.0);  // a stuck bystander keeps its (zero) speed
}

TEST(BallContact, ClusterOnARotorAtConstantSpeedIsOneBallOfTheSummedMass) {
  // No table motion (a table so heavy that xbar'' ~ 1e-12): a slipping cluster of two touching
  // equal balls accelerates like one ball of twice the mass, and with x = y = 0, W' = 0 both obey
  // beta'' = mu sigma h_l / D with h_l = -(beta' + W)^2 + 2 Jbar beta' (dbar W - 2 beta').
  AbuParameters two;
  two.table_mass_kg = 1e6;
  two.ball_contact = BallContact::Hard;
  AbuParameters one = two;
  one.balls = {Ball{2 * two.balls[0].mass_kg, two.balls[0].diameter_m}};
  const NondimParameters nd2 = NondimParameters::from(two), nd1 = NondimParameters::from(one);
  const AbuModel m2(nd2), m1(nd1);
  const double W = 1.3, v = -0.2, mu = 0.02;
  const double d = contact_spacing(two, 0, 1);
  std::vector<double> y2 = {0, 0, 0, 0, 2.0, 2.0 + d, v, v}, y1 = {0, 0, 0, 0, 2.0, v};
  const BallMode slip[2] = {BallMode::SlipBackward, BallMode::SlipBackward};
  ModelForces f2(2), f1(1);
  Clusters cl;
  cl.groups = {{0, 1}};
  m2.evaluate_clusters(y2.data(), W, 0.0, slip, cl, mu, f2);
  m1.evaluate(y1.data(), W, 0.0, slip, mu, f1);
  const double J = NondimParameters::Jbar, dbar = nd2.dbar[0];
  const double hl = -(v + W) * (v + W) + 2 * J * v * (dbar * W - 2 * v);
  const double closed = mu * -1.0 * hl / nd2.D[0];
  // (the 1e6 kg table still couples at mbar ~ 3e-10: ~1e-8 relative)
  EXPECT_NEAR(f2.betadd[0], closed, 1e-7 * std::fabs(closed));
  EXPECT_EQ(f2.betadd[0], f2.betadd[1]);
  EXPECT_NEAR(f1.betadd[0], closed, 1e-7 * std::fabs(closed));
  EXPECT_NEAR(f2.betadd[0], f1.betadd[0], 1e-9 * std::fabs(closed));
  // the rim friction of the cluster is that of the one ball: sum m_i fw_i = (m_1 + m_2) fw
  EXPECT_NEAR(nd2.mbar[0] * f2.fw[0] + nd2.mbar[1] * f2.fw[1], nd1.mbar[0] * f1.fw[0], 1e-9 * std::fabs(nd1.mbar[0] * f1.fw[0]));
  // equal balls with equal forces push each other with nothing: the contact force is ~0
  EXPECT_NEAR(f2.contact[0], 0.0, 1e-12);
}

TEST(BallContact, MapOntoTheFeasibleSetKeepsBallZeroAndLeavesNoOverlap) {
  const AbuParameters p = three_balls();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  for (int k = 0; k < 1000; ++k) {
    const std::vector<double> b = {u(rng), u(rng), u(rng)};
    const std::vector<double> m = map_onto_contact_feasible_set(p, b);
    EXPECT_GE(min_contact_clearance(p, m), -1e-12);
    EXPECT_DOUBLE_EQ(m[0], b[0]);
    EXPECT_EQ(m, map_onto_contact_feasible_set(p, b));  // deterministic: replayable
  }
  // the same angle for all: spaced at exactly the least spacings
  const std::vector<double> m = map_onto_contact_feasible_set(p, {1.0, 1.0, 1.0});
  EXPECT_NEAR(min_contact_clearance(p, m), 0.0, 1e-12);
}

TEST(BallContact, BallsThatDoNotFitAreAConfigError) {
  AbuParameters p;
  p.ball_contact = BallContact::Hard;
  p.balls.assign(30, Ball{});  // 30 x 0.262 rad > 2 pi
  EXPECT_THROW(validate(p), ConfigError);
  // the switch model has contact too (docs/model.md 8.1; tests/core/switch_contact_test.cpp)
  SimulationSetup s;
  s.abu.ball_contact = BallContact::Hard;
  s.options.method = FrictionMethod::SwitchModel;
  EXPECT_NO_THROW(Simulator{s});
}

namespace {
// Final states of n random starts of the report's final profile with hard contact: every run
// ends ok, no final state overlaps (clearance >= -1e-12 rad: rounding).
void no_final_overlap(std::uint64_t seed, int n, int balls) {
  SimulationSetup s;
  s.abu.ball_contact = BallContact::Hard;
  s.abu.balls.assign(static_cast<std::size_t>(balls), Ball{});
  Simulator sim(s);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  int failed = 0, overlaps = 0;
  for (int k = 0; k < n; ++k) {
    std::vector<double> b(static_cast<std::size_t>(balls));
    for (double& x : b) x = u(rng);
    const RunOutcome o = sim.run(b);
    failed += !o.ok();
    overlaps += min_contact_clearance(s.abu, o.beta_final) < -1e-12;
    EXPECT_GE(o.min_contact_clearance_rad, -1e-12);
  }
  EXPECT_EQ(failed, 0) << "seed " << seed;
  EXPECT_EQ(overlaps, 0) << "seed " << seed;
}
}  // namespace

TEST(BallContact, NoFinalStateOverlapsTwoBalls) { no_final_overlap(101, 96, 2); }
TEST(BallContact, NoFinalStateOverlapsFourBalls) { no_final_overlap(202, 48, 4); }

namespace {

// 16 random starts of setup s (the balls' count from s, angles from seed): every run ends ok, and no
// two balls overlap at the end by more than -min_clearance rad.
void expect_random_starts_end_ok(const SimulationSetup& s, std::uint64_t seed, double min_clearance) {
  Simulator sim(s);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  for (int k = 0; k < 16; ++k) {
    std::vector<double> beta(s.abu.balls.size());
    for (double& x : beta) x = u(rng);
    const RunOutcome o = sim.run(beta);
    EXPECT_TRUE(o.ok()) << "start " << k << ": " << o.message;
    EXPECT_GE(min_contact_clearance(s.abu, o.beta_final), min_clearance) << "start " << k;
  }
}

}  // namespace

// Nine balls of equal total mass (2.8e-4 kg, the study's formulation 4; d ~ m^(1/3)): chains of
// touching balls give more joint cluster/mode options than the enumeration takes (20 000). The
// reduced choice (touching balls together) must still let a chain whose margin crossed zero slip:
// before it kept every ball stuck and 6 of these 16 starts ended at the chatter limit.
TEST(BallContact, NineBallsOfEqualTotalMassEndOkWithoutOverlap) {
  SimulationSetup s;
  s.abu.ball_contact = BallContact::Hard;
  Ball b;
  b.mass_kg = 2.8e-4 / 9;
  b.diameter_m = 3e-3 * std::cbrt(2.0 / 9);
  s.abu.balls.assign(9, b);
  expect_random_starts_end_ok(s, 2003, -1e-12);
}

// Chains of identical report balls (9 balls, 4.5x the report's ball mass): before forced blocks
// were released only in the direction whose margin crossed (docs/model.md 11.8), a chain stopped
// and re-started at speeds ~1e-11 until the chatter limit: 54 of 64 starts of this seed failed.
// Final clearances: rounding over ~900 events, at most 3.8e-12 rad measured (docs/performance.md).
TEST(BallContact, NineIdenticalBallsInChainsEndOk) {
  SimulationSetup s;
  s.abu.ball_contact = BallContact::Hard;
  s.abu.balls.assign(9, Ball{});
  expect_random_starts_end_ok(s, 4242, -1e-11);
}

// The chatter_limit runs of contact_best_mu03_shake_6balls at mu 0.02 and the imbalance +20 %
// (seed 9001: 7 of 1024; docs/model.md 11.10). Run 150 of them: a ball stopped behind a chain
// slipping away from it at |v| ~ 1e-11 (non-dim.) was joined to the chain at every stop and given
// the chain's mean speed (the choice's speed tolerance was 1e-9 absolute), so the chain lost a
// fixed share (1/4) of its speed per event and the stops accumulated at t = 9.4776 s (Zeno): more
// than 200 events within 1 ms. Now the run ends ok, settled, with all six balls in one chain at the
// imbalance's side, like the other six such runs (26.45 - 26.51e-7 kg m; tolerance 0.2e-7).
TEST(BallContact, ABallStoppedBehindASlowChainIsNotRejoinedAtEveryStop) {
  SimulationSetup s;
  s.abu.ball_contact = BallContact::Hard;
  s.abu.friction_mu = 0.02;
  s.abu.imbalance_mass_kg = 1.2 * 5.6e-4;
  s.abu.balls.assign(6, Ball{4.66667e-05, 0.00208008});
  s.profile = StartupProfile({{23.9543212, 1.58616933}, {28.9232125, 3.8112098}, {28.9232125, 1.59569198},
                              {26.6328009, 0.181884869}, {28.9160371, 0.118197985}, {28.9160371, 1.5234897},
                              {25.8424305, 0.27905265}, {28.9109833, 0.264536147}, {28.9109833, 2.60978456},
                              {100, 5.06173836}});
  Simulator sim(s);
  abuopt::sim_counters().max_gap_correction = 0;
  const RunOutcome o = sim.run({1.0060754022589522, 6.023192734492402, 4.151546585959592, 2.391286076859859,
                                0.3655088592267681, 5.618821214035274});
  ASSERT_EQ(o.status, RunStatus::Ok) << o.message;
  EXPECT_TRUE(o.settled);
  EXPECT_LT(o.events, 300);  // 249; the chatter guard tripped at 335
  EXPECT_NEAR(o.residual_imbalance_kgm * 1e7, 26.45, 0.2);
  // The missed stop before the chatter (docs/model.md 11.10 - 11.11): a two-ball cluster reversed
  // and back inside one step, slid ~2 ms the wrong way, and the gaps it left were projected at
  // the next event by up to 8.0e-6 rad (contact model version 4). With the stop functions' rates
  // in the dip check it is stopped, and every overlap projected during the run is the rounding
  // and the located events' tolerance (kEventGapTol atol = 1e-12 rad), far below 1e-9 rad.
  EXPECT_LT(abuopt::sim_counters().max_gap_correction, 1e-9);
}

// The three runs of the feed-forward PI + 1 Hz design that ended at the chatter limit (docs/model.md
// 11.12; contact model version 5, tests/core/data/deep_6balls_pi1hz_setpoints.yaml, mu 0.02:
// run 893 of seed 9001, runs 50 and 578 of seed 9002, random design, 1024 runs). A whole-Hz setpoint
// step released a stuck two-ball cluster backward; its stop inside the first step was missed and the
// choice, with the W' of the modes before the event, kept choosing an inconsistent mode: a 4-event
// cycle of period 2.1 - 2.4 us until the guard (376, 429 and 423 events). With the trials' W' from
// the motor equation and the stop found in the first step (version 6) each ends ok and settled, with
// 179 / 232 / 226 events and |I_r| 0.503 / 1.040 / 1.035e-7 kg m (as each fix alone gave in the
// scratch builds of 11.12; tolerance 0.05e-7).
TEST(BallContact, APiSetpointStepThatReleasesAClusterDoesNotChatter) {
  const std::string cfg =
      std::string(ABUOPT_SOURCE_DIR) + "/tests/core/data/deep_6balls_pi1hz_setpoints.yaml";
  YamlReader root = YamlReader::load_file(cfg);
  const Simulator sim(read_simulation_setup(root));
  ASSERT_EQ(sim.setup().motor.kind, MotorKind::PI);
  ASSERT_TRUE(sim.setup().motor.quantize_setpoint_1hz);
  struct Case {
    const char* name;
    std::vector<double> beta0;
    double ir;
  };
  const Case cases[] = {
      {"9001 run 893",
       {3.5587207133390577, 5.2939935814868075, 6.047691991207778, 2.37308259576273, 4.916899452503238, 5.794540682230526},
       0.503},
      {"9002 run 50",
       {5.533638488898895, 0.3234300720683114, 4.351806249634684, 4.041151374312307, 5.991613603648726, 1.0919233021346004},
       1.040},
      {"9002 run 578",
       {3.48479549886498, 5.112149462440565, 6.134051383437081, 0.6347378036173517, 0.21769630883962865, 2.975427097185296},
       1.035},
  };
  for (const Case& c : cases) {
    RunOverrides o;
    o.friction_mu = 0.02;
    const RunOutcome r = sim.run(c.beta0, o);
    ASSERT_EQ(r.status, RunStatus::Ok) << c.name << ": " << r.message;
    EXPECT_TRUE(r.settled) << c.name;
    EXPECT_LT(r.events, 300) << c.name;
    EXPECT_NEAR(r.residual_imbalance_kgm * 1e7, c.ir, 0.05) << c.name;
  }
}
