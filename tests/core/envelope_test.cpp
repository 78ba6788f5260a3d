// The `envelope` section: reading and its errors, the per-run draws (in range, uniform in mean and
// variance, independent streams, the same streams as the old montecarlo keys), replay of one run,
// thread independence, and that each drawn parameter reaches the simulator (stiffness moves the
// resonance, an override equals a nominal run with that value).
#include "abuopt/core/envelope.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/ball_contact.hpp"
#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"
#include "abuopt/core/simulator.hpp"

namespace abuopt {
namespace {

const SimulationSetup& default_setup() {
  static const SimulationSetup s;
  return s;
}

MonteCarloConfig read(const std::string& yaml, const SimulationSetup& setup = default_setup()) {
  YamlReader root = YamlReader::load_string(yaml);
  MonteCarloConfig c = read_monte_carlo_config(root, setup);
  root.finish();
  return c;
}

std::string error_of(const std::string& yaml) {
  SimulationSetup setup;
  setup.abu.ball_contact = BallContact::Hard;
  try {
    read(yaml, setup);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

SimulationSetup contact_setup() {
  SimulationSetup s;
  s.abu.ball_contact = BallContact::Hard;
  return s;
}

TEST(EnvelopeConfig, ReadsUniformFixedAndPlainNumbers) {
  const MonteCarloConfig c = read(
      "montecarlo: {design: random, runs: 8}\n"
      "envelope:\n"
      "  friction_mu: {uniform: [0.02, 0.04]}\n"
      "  imbalance_mass_factor: 1.5\n"
      "  stiffness_factor: {fixed: 0.95}\n"
      "  restitution: {uniform: [0.5, 0.95]}\n",
      contact_setup());
  const Envelope& e = c.study.uncertain.envelope;
  EXPECT_EQ(e.friction_mu, ParameterDistribution::uniform(0.02, 0.04));
  EXPECT_EQ(e.imbalance_mass_factor, ParameterDistribution::fixed(1.5));
  EXPECT_EQ(e.stiffness_factor, ParameterDistribution::fixed(0.95));
  EXPECT_EQ(e.restitution, ParameterDistribution::uniform(0.5, 0.95));
  // written and read back: the same envelope
  Envelope back;
  YamlReader r = YamlReader::load_string(write_fields(e));
  read_fields(r, back);
  EXPECT_EQ(back, e);
  // absent: nominal, no override
  const MonteCarloConfig none = read("montecarlo: {design: random, runs: 8}\n");
  EXPECT_TRUE(none.study.uncertain.envelope.empty());
}

TEST(EnvelopeConfig, BadValuesNameKeyValueAndRule) {
  const std::string mc = "montecarlo: {design: random, runs: 8}\n";
  EXPECT_NE(error_of(mc + "envelope: {friction_mu: {uniform: [0.04, 0.02]}}").find("envelope.friction_mu.uniform"),
            std::string::npos);
  EXPECT_NE(error_of(mc + "envelope: {friction_mu: {uniform: [0.04, 0.02]}}").find("lo <= hi"), std::string::npos);
  EXPECT_NE(error_of(mc + "envelope: {restitution: {uniform: [0.5, 1.2]}}").find("[0, 1]"), std::string::npos);
  EXPECT_NE(error_of(mc + "envelope: {stiffness_factor: 0}").find("envelope.stiffness_factor"), std::string::npos);
  EXPECT_NE(error_of(mc + "envelope: {stiffness_factor: {uniform: [1]}}").find("[lo, hi]"), std::string::npos);
  EXPECT_NE(error_of(mc + "envelope: {stiffness: 1.0}").find("stiffness"), std::string::npos);  // unknown key
  EXPECT_NE(error_of(mc + "envelope: {friction_mu: {fixed: 0.02, uniform: [0.02, 0.03]}}").find("exactly one"),
            std::string::npos);
  EXPECT_NE(error_of(mc + "envelope: {friction_mu: {normal: [0.03, 0.01]}}").find("exactly one"), std::string::npos);
  // a parameter given twice
  const std::string both_mu = error_of(
      "montecarlo: {design: random, runs: 8, friction: {range: [0.02, 0.04]}}\n"
      "envelope: {friction_mu: {uniform: [0.02, 0.04]}}");
  EXPECT_NE(both_mu.find("envelope.friction_mu"), std::string::npos) << both_mu;
  EXPECT_NE(both_mu.find("montecarlo.friction"), std::string::npos) << both_mu;
  const std::string both_mass = error_of(
      "montecarlo: {design: random, runs: 8, imbalance: {mass_relative_range: [-0.5, 0.5]}}\n"
      "envelope: {imbalance_mass_factor: {uniform: [0.5, 1.5]}}");
  EXPECT_NE(both_mass.find("mass_relative_range"), std::string::npos) << both_mass;
  // restitution without contact means nothing
  EXPECT_THROW(read(mc + "envelope: {restitution: 0.5}"), ConfigError);
}

MonteCarloStudy envelope_study(std::size_t runs) {
  MonteCarloStudy s;
  s.setup = contact_setup();
  s.design.kind = InitialConditionKind::Random;
  s.design.seed = 7;
  s.seed = 7;
  s.runs = runs;
  s.uncertain.envelope = Envelope::report();
  return s;
}

TEST(EnvelopeDraws, LieInRangeAndMatchUniformMeanAndVariance) {
  // n draws of U[lo, hi]: mean within 4.5 standard errors ((hi - lo) / sqrt(12 n)); variance
  // (hi - lo)^2 / 12 within 4.5 of its standard errors (0.894 / sqrt(n) relative for a uniform);
  // independent streams: |correlation| within 4.5 / sqrt(n).
  const std::size_t n = 20000;
  const MonteCarloStudy s = envelope_study(n);
  const AbuParameters& p = s.setup.abu;
  std::vector<std::vector<double>> v(Envelope::kParameters);
  for (std::size_t i = 0; i < n; ++i) {
    const RunOverrides o = sample_overrides(s.uncertain, p, s.seed, i);
    ASSERT_TRUE(o.friction_mu && o.imbalance_mass_kg && o.stiffness_N_per_m && o.ball_restitution);
    v[0].push_back(*o.friction_mu);
    v[1].push_back(*o.imbalance_mass_kg / p.imbalance_mass_kg);
    v[2].push_back(*o.stiffness_N_per_m / p.stiffness_N_per_m);
    v[3].push_back(*o.ball_restitution);
  }
  const double sn = std::sqrt(static_cast<double>(n));
  std::vector<double> mean(Envelope::kParameters), sd(Envelope::kParameters);
  for (std::size_t k = 0; k < Envelope::kParameters; ++k) {
    const ParameterDistribution& d = s.uncertain.envelope.parameter(k);
    double m = 0, m2 = 0;
    for (double x : v[k]) {
      EXPECT_GE(x, d.lo * (1 - 1e-15)) << Envelope::key(k);
      EXPECT_LE(x, d.hi * (1 + 1e-15)) << Envelope::key(k);
      m += x;
    }
    m /= static_cast<double>(n);
    for (double x : v[k]) m2 += (x - m) * (x - m);
    m2 /= static_cast<double>(n - 1);
    const double w = d.hi - d.lo, var = w * w / 12;
    EXPECT_NEAR(m, 0.5 * (d.lo + d.hi), 4.5 * w / std::sqrt(12.0) / sn) << Envelope::key(k);
    EXPECT_NEAR(m2 / var, 1.0, 4.5 * 0.894 / sn) << Envelope::key(k);
    mean[k] = m;
    sd[k] = std::sqrt(m2);
  }
  for (std::size_t a = 0; a < Envelope::kParameters; ++a)
    for (std::size_t b = a + 1; b < Envelope::kParameters; ++b) {
      double c = 0;
      for (std::size_t i = 0; i < n; ++i) c += (v[a][i] - mean[a]) * (v[b][i] - mean[b]);
      c /= static_cast<double>(n - 1) * sd[a] * sd[b];
      EXPECT_LT(std::fabs(c), 4.5 / sn) << Envelope::key(a) << " vs " << Envelope::key(b);
    }
}

TEST(EnvelopeDraws, UseTheStreamsOfTheOldKeys) {
  // sampling random: envelope friction U[a, b] == montecarlo.friction.range [a, b]; imbalance factor U[1 + lo, 1 + hi]
  // == mass_relative_range [lo, hi] (to rounding): shipped configs keep their draws.
  MonteCarloStudy old_keys = envelope_study(64), env = envelope_study(64);
  env.uncertain.envelope.sampling = EnvelopeSampling::Random;
  old_keys.uncertain.envelope = Envelope{};
  old_keys.uncertain.friction.sampling = FrictionSampling::Range;
  old_keys.uncertain.friction.lo = 0.02;
  old_keys.uncertain.friction.hi = 0.04;
  old_keys.uncertain.imbalance_mass.sampling = ImbalanceMassSampling::RelativeRange;
  old_keys.uncertain.imbalance_mass.relative_lo = -0.5;
  old_keys.uncertain.imbalance_mass.relative_hi = 0.5;
  for (std::size_t i = 0; i < 64; ++i) {
    const RunOverrides a = sample_overrides(old_keys.uncertain, old_keys.setup.abu, 7, i);
    const RunOverrides b = sample_overrides(env.uncertain, env.setup.abu, 7, i);
    EXPECT_EQ(*a.friction_mu, *b.friction_mu);
    EXPECT_NEAR(*a.imbalance_mass_kg, *b.imbalance_mass_kg, 1e-15 * *a.imbalance_mass_kg);
    EXPECT_FALSE(a.stiffness_N_per_m.has_value());
  }
  // The default sampling, stratified, moves run i's draw into its cell ((bit + u) / 2): the same
  // distribution, other draws (envelope.hpp says so; about half the runs change, none may stay all).
  MonteCarloStudy stratified = envelope_study(64);
  ASSERT_EQ(stratified.uncertain.envelope.sampling, EnvelopeSampling::Stratified);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < 64; ++i) {
    const RunOverrides a = sample_overrides(old_keys.uncertain, old_keys.setup.abu, 7, i);
    const RunOverrides b = sample_overrides(stratified.uncertain, stratified.setup.abu, 7, i);
    if (*a.friction_mu != *b.friction_mu) ++differ;
  }
  EXPECT_GT(differ, 16u);
}

TEST(EnvelopeDraws, SobolSamplingStratifiesEveryReplicateAndGivesTheAngles) {
  // Each of the 16 scramblings is a (t, m, s)-net in base 2 before and after Owen scrambling: its
  // first 16 points put every coordinate (4 parameters, 6 angles) once into each sixteenth.
  for (std::size_t r = 0; r < Envelope::kReplicates; ++r)
    for (std::size_t dim = 0; dim < 10; ++dim) {
      std::vector<int> hits(16, 0);
      for (std::size_t k = 0; k < 16; ++k) {
        const double u = joint_sobol_coordinate(7, k * Envelope::kReplicates + r, dim);
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        ++hits[static_cast<std::size_t>(u * 16)];
      }
      EXPECT_EQ(*std::min_element(hits.begin(), hits.end()), 1) << "replicate " << r << " dim " << dim;
    }
  // Design random: the start angles are the joint point's (coordinates 4, 5), mapped onto the
  // contact-feasible set; design lhs: the design's, and the parameters stay joint.
  MonteCarloStudy s = envelope_study(64);
  s.uncertain.envelope.sampling = EnvelopeSampling::Sobol;
  EXPECT_TRUE(joint_sampling(s));
  const MonteCarloSample smp = prepare_sample(s, 5);
  std::vector<double> raw = {2 * M_PI * joint_sobol_coordinate(7, 5, 4), 2 * M_PI * joint_sobol_coordinate(7, 5, 5)};
  EXPECT_EQ(smp.beta0, map_onto_contact_feasible_set(s.setup.abu, raw));
  EXPECT_NEAR(*smp.overrides.stiffness_N_per_m,
              s.setup.abu.stiffness_N_per_m * (0.95 + 0.1 * joint_sobol_coordinate(7, 5, 2)), 1e-9);
  s.design.kind = InitialConditionKind::LatinHypercube;
  EXPECT_FALSE(joint_sampling(s));
  EXPECT_NE(prepare_sample(s, 5).beta0, smp.beta0);
  s.design.kind = InitialConditionKind::Random;
  s.uncertain.envelope.sampling = EnvelopeSampling::Random;
  EXPECT_FALSE(joint_sampling(s));
}

TEST(EnvelopeDraws, StratifiedSamplingPutsEveryRunInItsCell) {
  // The default: 4 varying parameters, 16 cells; run i lies in cell i mod 16, i.e. parameter q in
  // the upper half of its range exactly when bit q of (i mod 16) is set; and it is the random
  // stream's draw folded into that half.
  const MonteCarloStudy s = envelope_study(256);
  ASSERT_EQ(s.uncertain.envelope.sampling, EnvelopeSampling::Stratified);
  EXPECT_EQ(s.uncertain.envelope.strata(), 16u);
  MonteCarloStudy random = s;
  random.uncertain.envelope.sampling = EnvelopeSampling::Random;
  for (std::size_t i = 0; i < 256; ++i) {
    const RunOverrides o = sample_overrides(s.uncertain, s.setup.abu, s.seed, i);
    const RunOverrides r = sample_overrides(random.uncertain, s.setup.abu, s.seed, i);
    const double mu_u = (*o.friction_mu - 0.02) / 0.02, k_u = (*o.stiffness_N_per_m / s.setup.abu.stiffness_N_per_m - 0.95) / 0.1;
    EXPECT_EQ(mu_u >= 0.5, ((i % 16) & 1u) != 0) << i;
    EXPECT_EQ(k_u >= 0.5, ((i % 16) & 4u) != 0) << i;
    EXPECT_NEAR(mu_u, 0.5 * (static_cast<double>(i & 1u) + (*r.friction_mu - 0.02) / 0.02), 1e-12);
  }
  // only two varying parameters: 4 cells
  MonteCarloStudy two = s;
  two.uncertain.envelope.imbalance_mass_factor = ParameterDistribution::fixed(1.0);
  two.uncertain.envelope.restitution = ParameterDistribution{};
  EXPECT_EQ(two.uncertain.envelope.strata(), 4u);
  EXPECT_EQ(interval_layout(two).kind, IntervalKind::Strata);
  EXPECT_EQ(interval_layout(two).groups, 4u);
}

TEST(EnvelopeDraws, ReplicateIntervalComesFromTheReplicateMeans) {
  // 32 runs, run i has |I_r| = (i mod 16) 1e-7: the 16 replicate means are 0..15 (sample
  // variance 340 / 15), half-width t_15 sqrt(340 / 15 / 16) = 2.131 x 1.1902 = 2.536e-7; as
  // independent runs, 1.96 sqrt(s^2 / 32) with the 32 values' sample variance.
  std::vector<MonteCarloSample> v(32);
  for (std::size_t i = 0; i < 32; ++i) {
    v[i].index = i;
    v[i].outcome.residual_imbalance_kgm = 1e-7 * static_cast<double>(i % 16);
  }
  EXPECT_NEAR(mean_half_width95(v, {IntervalKind::Replicates, 16}) * 1e7, 2.536, 3e-3);
  double var = 0;
  for (std::size_t i = 0; i < 32; ++i) var += std::pow(static_cast<double>(i % 16) - 7.5, 2);
  var /= 31;
  EXPECT_NEAR(mean_half_width95(v, {}) * 1e7, 1.96 * std::sqrt(var / 32), 1e-9);
  // as 16 strata: every cell holds one value twice, s_h = 0: no spread left
  EXPECT_EQ(mean_half_width95(v, {IntervalKind::Strata, 16}), 0.0);
}

// Cheap stand-in for the simulator that depends on every overridden value.
RunOutcome fake_run(const std::vector<double>& beta0, const RunOverrides& o) {
  RunOutcome r;
  r.beta_final = beta0;
  r.residual_imbalance_kgm = o.friction_mu.value_or(0) + 3 * o.imbalance_mass_kg.value_or(0) +
                             5 * o.stiffness_N_per_m.value_or(0) + 7 * o.ball_restitution.value_or(0) + beta0[0];
  r.residual_imbalance_x_kgm = r.residual_imbalance_kgm / 2;
  return r;
}

TEST(EnvelopeDraws, RunOneReplaysAnyRunAndThreadsDoNotMatter) {
  const MonteCarloStudy s = envelope_study(200);
  ThreadPoolRunner one(1), three(3);
  const MonteCarloResult r1 = run_monte_carlo(s, fake_run, one);
  const MonteCarloResult r3 = run_monte_carlo(s, fake_run, three);
  ASSERT_EQ(r1.samples.size(), 200u);
  for (std::size_t i = 0; i < 200; ++i) {
    EXPECT_EQ(r1.samples[i].outcome.residual_imbalance_kgm, r3.samples[i].outcome.residual_imbalance_kgm);
    EXPECT_EQ(r1.samples[i].stiffness_N_per_m, r3.samples[i].stiffness_N_per_m);
  }
  for (std::size_t i : {0u, 17u, 199u}) {
    const MonteCarloSample one_run = run_one(s, i, fake_run);
    EXPECT_EQ(one_run.outcome.residual_imbalance_kgm, r1.samples[i].outcome.residual_imbalance_kgm);
    EXPECT_EQ(one_run.friction_mu, r1.samples[i].friction_mu);
    EXPECT_EQ(one_run.restitution, r1.samples[i].restitution);
    EXPECT_EQ(one_run.stiffness_N_per_m, *one_run.overrides.stiffness_N_per_m);
  }
  // the run count does not change run i's draws (a study of 50 runs is a prefix)
  MonteCarloStudy shorter = s;
  shorter.runs = 50;
  EXPECT_EQ(prepare_sample(shorter, 42).overrides.stiffness_N_per_m, r1.samples[42].overrides.stiffness_N_per_m);
}

TEST(EnvelopeSimulator, AnOverrideEqualsTheNominalRunWithThatValue) {
  // Each drawn parameter reaches the simulator: run i with its overrides gives what a setup with
  // those values as nominal gives (same path: the Runge-Kutta stuck phases for both).
  MonteCarloStudy s = envelope_study(3);
  s.setup.options.stuck_integrator = StuckIntegrator::RungeKutta;
  s.setup.profile = StartupProfile({{60.0, 4.0}});
  s.setup.options.end_time_s = 6.0;
  const Simulator sim(s.setup);
  for (std::size_t i = 0; i < 3; ++i) {
    const MonteCarloSample smp = prepare_sample(s, i);
    SimulationSetup at = s.setup;
    at.abu.friction_mu = smp.friction_mu;
    at.abu.imbalance_mass_kg = *smp.overrides.imbalance_mass_kg;
    at.abu.stiffness_N_per_m = smp.stiffness_N_per_m;
    at.abu.ball_restitution = smp.restitution;
    const RunOutcome a = sim.run(smp.beta0, smp.overrides);
    const RunOutcome b = Simulator(at).run(smp.beta0);
    EXPECT_EQ(a.beta_final, b.beta_final) << "run " << i;
    EXPECT_EQ(a.max_amplitude_mm, b.max_amplitude_mm) << "run " << i;
  }
}

TEST(EnvelopeSimulator, RunsWithTheirOwnOscillatorStayOnTheExactPath) {
  // A stiffness or imbalance-mass override gives the run another omega_n and bbar than the
  // Simulator's table: it takes the per-run view of the shared profile samples
  // (run_forcing_table.hpp), not the Runge-Kutta stuck phases. Against a Simulator built with those
  // values (its own exact table on a slightly different grid): the same final angles to 1e-9 and about
  // the same work (steps: grid intervals + stepper steps, within 5 %; the Runge-Kutta path takes
  // several times the right-hand-side evaluations).
  MonteCarloStudy s = envelope_study(6);
  s.setup.profile = StartupProfile({{25.0, 1.0}, {29.5, 3.0}, {60.0, 2.0}});
  const Simulator sim(s.setup);
  SimulationSetup rk_setup = s.setup;
  rk_setup.options.stuck_integrator = StuckIntegrator::RungeKutta;
  const Simulator rk(rk_setup);
  long steps_view = 0, steps_nominal = 0, rhs_view = 0, rhs_rk = 0;
  for (std::size_t i = 0; i < 6; ++i) {
    const MonteCarloSample smp = prepare_sample(s, i);
    SimulationSetup at = s.setup;
    at.abu.friction_mu = smp.friction_mu;
    at.abu.imbalance_mass_kg = *smp.overrides.imbalance_mass_kg;
    at.abu.stiffness_N_per_m = smp.stiffness_N_per_m;
    at.abu.ball_restitution = smp.restitution;
    const RunOutcome a = sim.run(smp.beta0, smp.overrides);
    const RunOutcome b = Simulator(at).run(smp.beta0);
    ASSERT_TRUE(a.ok() && b.ok()) << a.message << b.message;
    for (std::size_t k = 0; k < 2; ++k)
      EXPECT_NEAR(std::remainder(a.beta_final[k] - b.beta_final[k], 2 * M_PI), 0.0, 1e-9) << "run " << i;
    // the peak amplitude is taken at the grid points passed, and the grids differ
    EXPECT_NEAR(a.max_amplitude_mm, b.max_amplitude_mm, 1e-4 * b.max_amplitude_mm) << "run " << i;
    EXPECT_EQ(a.events, b.events) << "run " << i;
    steps_view += a.steps;
    steps_nominal += b.steps;
    rhs_view += a.rhs_evaluations;
    rhs_rk += rk.run(smp.beta0, smp.overrides).rhs_evaluations;
  }
  EXPECT_NEAR(static_cast<double>(steps_view) / static_cast<double>(steps_nominal), 1.0, 0.05);
  EXPECT_LT(2 * rhs_view, rhs_rk);
}

TEST(EnvelopeSimulator, AZeroImbalanceMassRunsUnderBothMassKeys) {
  // abu.imbalance_mass_kg may be 0 (the abu rule is >= 0): m_I x factor and m_I (1 + u) are then 0,
  // an override the simulator must accept as it accepts the nominal 0 (it threw
  // std::invalid_argument, aborting the study). A balanced rotor with balls at 0 and pi stays
  // balanced to 1e-9 kg m.
  for (bool old_key : {false, true}) {
    MonteCarloStudy s = envelope_study(4);
    s.setup.abu.imbalance_mass_kg = 0.0;
    s.setup.profile = StartupProfile({{60.0, 2.0}});
    s.setup.options.end_time_s = 3.0;
    if (old_key) {
      s.uncertain.envelope.imbalance_mass_factor = {};
      s.uncertain.imbalance_mass.sampling = ImbalanceMassSampling::RelativeRange;
      s.uncertain.imbalance_mass.relative_lo = -0.5;
      s.uncertain.imbalance_mass.relative_hi = 0.5;
    }
    ThreadPoolRunner one(1);
    MonteCarloResult r;
    ASSERT_NO_THROW(r = run_monte_carlo(s, one)) << (old_key ? "mass_relative_range" : "imbalance_mass_factor");
    ASSERT_EQ(r.samples.size(), 4u);
    for (const auto& smp : r.samples) {
      EXPECT_EQ(*smp.overrides.imbalance_mass_kg, 0.0);
      EXPECT_TRUE(smp.outcome.ok()) << smp.outcome.message;
    }
    RunOverrides zero;
    zero.imbalance_mass_kg = 0.0;
    const RunOutcome balanced = Simulator(s.setup).run({0.0, M_PI}, zero);
    EXPECT_NEAR(balanced.residual_imbalance_kgm, 0.0, 1e-9);
  }
}

TEST(EnvelopeConfig, FactorsMustKeepTheAbuRules) {
  // nominal x [lo, hi] must obey the abu section's rules (stiffness <= 1e9 N/m, imbalance mass <=
  // 1e4 kg): a ConfigError naming the key, not an exception from the simulator mid-study.
  auto error = [](MonteCarloStudy s) -> std::string {
    try {
      validate(s);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "no error";
  };
  MonteCarloStudy s = envelope_study(8);
  EXPECT_EQ(error(s), "no error");
  s.setup.abu.stiffness_N_per_m = 5e8;
  s.uncertain.envelope.stiffness_factor = ParameterDistribution::uniform(1.0, 3.0);
  const std::string k = error(s);
  EXPECT_NE(k.find("envelope.stiffness_factor"), std::string::npos) << k;
  EXPECT_NE(k.find("1.5e+09"), std::string::npos) << k;
  s = envelope_study(8);
  s.setup.abu.imbalance_mass_kg = 5e3;
  s.uncertain.envelope.imbalance_mass_factor = ParameterDistribution::fixed(4.0);
  const std::string m = error(s);
  EXPECT_NE(m.find("envelope.imbalance_mass_factor"), std::string::npos) << m;
  s = envelope_study(8);
  s.setup.abu.imbalance_mass_kg = 5e3;
  s.uncertain.envelope.imbalance_mass_factor = {};
  s.uncertain.imbalance_mass.sampling = ImbalanceMassSampling::RelativeRange;
  s.uncertain.imbalance_mass.relative_lo = 0.0;
  s.uncertain.imbalance_mass.relative_hi = 2.0;
  const std::string r = error(s);
  EXPECT_NE(r.find("montecarlo.imbalance.mass_relative_range"), std::string::npos) << r;
  s.uncertain.imbalance_mass.relative_hi = 0.5;  // 7500 kg: inside the rule
  EXPECT_EQ(error(s), "no error");
}

TEST(EnvelopeSimulator, RealRunsDoNotDependOnThreadsOrOrder) {
  // The same check as RunOneReplaysAnyRunAndThreadsDoNotMatter with the real Simulator: a stiffness
  // envelope (+-5 %, so the runs spread over about 3 rungs of the forcing samples' 3 % ladder, built
  // by whichever run needs a rung first), a short profile, 24 runs on 1 and 3 threads and alone
  // (run_one: a fresh Simulator per run): every outcome bit-identical.
  MonteCarloStudy s = envelope_study(24);
  s.setup.profile = StartupProfile({{25.0, 0.3}, {40.0, 0.3}});
  s.uncertain.envelope = Envelope{};
  s.uncertain.envelope.stiffness_factor = Envelope::report().stiffness_factor;
  ASSERT_FALSE(s.uncertain.envelope.deterministic());
  ThreadPoolRunner one(1), three(3);
  const MonteCarloResult r1 = run_monte_carlo(s, one);
  const MonteCarloResult r3 = run_monte_carlo(s, three);
  ASSERT_EQ(r1.samples.size(), 24u);
  ASSERT_EQ(r3.samples.size(), 24u);
  double k_lo = 1e300, k_hi = 0;
  auto same = [](const RunOutcome& a, const RunOutcome& b) {
    return a.ok() && a.beta_final == b.beta_final && a.residual_imbalance_kgm == b.residual_imbalance_kgm &&
           a.max_amplitude_mm == b.max_amplitude_mm && a.events == b.events && a.steps == b.steps;
  };
  for (std::size_t i = 0; i < 24; ++i) {
    EXPECT_TRUE(same(r1.samples[i].outcome, r3.samples[i].outcome)) << "run " << i;
    k_lo = std::min(k_lo, r1.samples[i].stiffness_N_per_m);
    k_hi = std::max(k_hi, r1.samples[i].stiffness_N_per_m);
  }
  // the draws span more than one rung (omega_d ~ sqrt(k): a 3 % step is 6 % in k)
  EXPECT_GT(k_hi / k_lo, 1.06);
  for (std::size_t i : {0u, 11u, 23u})
    EXPECT_TRUE(same(run_one(s, i).outcome, r1.samples[i].outcome)) << "run_one " << i;
}

TEST(EnvelopeSimulator, StiffnessMovesTheResonance) {
  // Balls held by friction (mu 0.9): the table is a forced oscillator. On a slow ramp (25 -> 35 Hz
  // in 40 s, at most 0.5 Hz/s) its amplitude peaks just after the natural frequency (within
  // 0.5 Hz); k x 1.05 moves f_n by sqrt(1.05) - 1 = 2.47 % (28.89 -> 29.60 Hz for the report's
  // ABU), and the peak's frequency by the same to within 0.1 Hz (the ramp's lag is common).
  SimulationSetup s;
  s.profile = StartupProfile({{35.0, 40.0}}, 25.0);
  s.options.end_time_s = 40.0;
  s.options.trajectory_interval_s = 2e-3;
  const Simulator sim(s);
  auto peak_hz = [&](double k_factor) {
    RunOverrides o;
    o.friction_mu = 0.9;
    o.stiffness_N_per_m = s.abu.stiffness_N_per_m * k_factor;
    std::vector<TrajectoryPoint> tr;
    (void)sim.run({0.0, 2.0}, o, &tr);
    double best = 0, f = 0;
    for (const auto& q : tr)
      if (std::hypot(q.x_m, q.y_m) > best) {
        best = std::hypot(q.x_m, q.y_m);
        f = q.frequency_hz;
      }
    return f;
  };
  const double f0 = peak_hz(1.0), f1 = peak_hz(1.05);
  const double fn = s.abu.natural_frequency_hz();
  EXPECT_GE(f0, fn);
  EXPECT_NEAR(f0, fn, 0.5);
  EXPECT_NEAR(f1 - f0, fn * (std::sqrt(1.05) - 1), 0.1);
}

}  // namespace
}  // namespace abuopt
