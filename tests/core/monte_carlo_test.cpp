// The Monte Carlo engine with injected, deterministic per-sample functions: bit-identical results
// for 1, 2 and 3 threads and for another batch backend, replay of one run, progress reporting,
// error propagation, and reading the `montecarlo` config section.
#include "abuopt/core/monte_carlo.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"

namespace abuopt {
namespace {

// A made-up "simulation": a deterministic function of its inputs, with uneven run times so that
// the workers finish out of order, and a few failures.
RunOutcome fake_run(const std::vector<double>& beta0, const RunOverrides& o) {
  RunOutcome r;
  double s = 0, c = 0;
  for (double b : beta0) {
    s += std::sin(b);
    c += std::cos(b);
  }
  const double mu = o.friction_mu.value_or(0.02);
  r.beta_final = beta0;
  for (auto& b : r.beta_final) b = std::fmod(b + mu * 10.0, 2 * M_PI);
  r.residual_imbalance_kgm = 1e-7 * (std::hypot(s, c) + 1.0 + o.imbalance_angle_rad);
  r.residual_imbalance_x_kgm = 1e-7 * (std::fabs(c) + 0.5);
  r.settled = std::sin(3 * beta0[0]) < 0.8;
  r.settling_time_s = r.settled ? 5.0 + s : 0.0;
  r.max_amplitude_mm = 0.1 + 0.01 * c;
  r.events = static_cast<long>(10 * (s + 3));
  r.rhs_evaluations = 1000 + r.events;
  if (std::cos(5 * beta0[0] + beta0[1]) > 0.97) r.status = RunStatus::ChatterLimit;
  // uneven work: some runs take longer
  if (static_cast<int>(beta0[0] * 10) % 5 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));
  return r;
}

MonteCarloStudy make_study(InitialConditionKind kind, std::size_t runs) {
  MonteCarloStudy s;
  s.design.kind = kind;
  s.design.seed = 3;
  s.runs = runs;
  s.seed = 11;
  s.uncertain.friction.sampling = FrictionSampling::Range;
  s.uncertain.friction.lo = 0.02;
  s.uncertain.friction.hi = 0.04;
  s.uncertain.imbalance_angle.sampling = ImbalanceAngleSampling::Uniform;
  return s;
}

std::string csv_of(const MonteCarloResult& r) {
  std::ostringstream os;
  write_runs_csv(os, r.samples);
  return os.str();
}

// Everything except the wall time and concurrency.
std::string stats_of(const MonteCarloResult& r) { return to_json(compute_statistics(r.samples)).dump(); }

// A second backend: serial, highest index first. Stands in for MPI-like backends that run the
// indices in another order and place.
class ReverseRunner final : public BatchRunner {
 public:
  void run(std::size_t count, const std::function<void(std::size_t)>& task, const ProgressCallback& progress) override {
    for (std::size_t k = 0; k < count; ++k) {
      task(count - 1 - k);
      if (progress) progress(k + 1, count, 0.0);
    }
  }
  std::size_t concurrency() const override { return 1; }
};

TEST(MonteCarlo, ResultsAreBitIdenticalForOneTwoAndThreeThreads) {
  for (auto kind : {InitialConditionKind::Grid, InitialConditionKind::LatinHypercube, InitialConditionKind::Sobol}) {
    MonteCarloStudy s = make_study(kind, 0);
    s.design.grid_points_per_axis = 16;
    s.runs = kind == InitialConditionKind::Grid ? 256 : 300;
    ThreadPoolRunner one(1), two(2), three(3);
    ReverseRunner reverse;
    const MonteCarloResult r1 = run_monte_carlo(s, fake_run, one);
    const MonteCarloResult r2 = run_monte_carlo(s, fake_run, two);
    const MonteCarloResult r3 = run_monte_carlo(s, fake_run, three);
    const MonteCarloResult rr = run_monte_carlo(s, fake_run, reverse);
    ASSERT_EQ(r1.samples.size(), s.runs);
    EXPECT_EQ(r2.concurrency, 2u);
    EXPECT_EQ(r3.concurrency, 3u);
    EXPECT_EQ(csv_of(r1), csv_of(r2)) << to_string(kind);
    EXPECT_EQ(csv_of(r1), csv_of(r3)) << to_string(kind);
    EXPECT_EQ(csv_of(r1), csv_of(rr)) << to_string(kind);
    EXPECT_EQ(stats_of(r1), stats_of(r2));
    EXPECT_EQ(stats_of(r1), stats_of(r3));
    for (std::size_t i = 0; i < s.runs; ++i) {
      ASSERT_EQ(r3.samples[i].index, i);
      ASSERT_EQ(r1.samples[i].outcome.residual_imbalance_kgm, r3.samples[i].outcome.residual_imbalance_kgm);
    }
  }
}

TEST(MonteCarlo, RunOneReplaysAnySampleAlone) {
  const MonteCarloStudy s = make_study(InitialConditionKind::LatinHypercube, 97);
  ThreadPoolRunner three(3);
  const MonteCarloResult all = run_monte_carlo(s, fake_run, three);
  for (std::size_t i : {0u, 1u, 50u, 96u}) {
    const MonteCarloSample one = run_one(s, i, fake_run);
    const MonteCarloSample& ref = all.samples[i];
    EXPECT_EQ(one.index, i);
    EXPECT_EQ(one.beta0, ref.beta0);
    EXPECT_EQ(one.overrides.friction_mu, ref.overrides.friction_mu);
    EXPECT_EQ(one.overrides.imbalance_angle_rad, ref.overrides.imbalance_angle_rad);
    EXPECT_EQ(one.friction_mu, ref.friction_mu);
    EXPECT_EQ(one.outcome.residual_imbalance_kgm, ref.outcome.residual_imbalance_kgm);
    EXPECT_EQ(one.outcome.beta_final, ref.outcome.beta_final);
  }
  EXPECT_THROW(run_one(s, 97, fake_run), ConfigError);
}

TEST(MonteCarlo, SamplesCarryTheEffectiveParameters) {
  MonteCarloStudy s = make_study(InitialConditionKind::Random, 20);
  s.uncertain.imbalance_mass.sampling = ImbalanceMassSampling::RelativeRange;
  s.uncertain.imbalance_mass.relative_lo = -0.1;
  s.uncertain.imbalance_mass.relative_hi = 0.1;
  ThreadPoolRunner two(2);
  const auto r = run_monte_carlo(s, fake_run, two);
  for (const auto& smp : r.samples) {
    EXPECT_EQ(smp.friction_mu, *smp.overrides.friction_mu);
    EXPECT_DOUBLE_EQ(smp.imbalance_kgm, *smp.overrides.imbalance_mass_kg * s.setup.abu.eccentricity_m);
    ASSERT_EQ(smp.beta0.size(), 2u);
  }
  // Nominal parameters: the %MI threshold is m_I e of the setup.
  MonteCarloStudy n = make_study(InitialConditionKind::Random, 5);
  n.uncertain = UncertainParameters{};
  const auto rn = run_monte_carlo(n, fake_run, two);
  EXPECT_DOUBLE_EQ(rn.samples[0].imbalance_kgm, n.setup.abu.imbalance_kgm());
  EXPECT_EQ(rn.samples[0].friction_mu, n.setup.abu.friction_mu);
}

TEST(MonteCarlo, BallCountComesFromTheSetup) {
  MonteCarloStudy s = make_study(InitialConditionKind::Grid, 64);
  s.setup.abu.balls.resize(3);
  s.design.grid_points_per_axis = 4;
  s.design.balls = 2;  // ignored: the setup has 3 balls
  ThreadPoolRunner two(2);
  const auto r = run_monte_carlo(s, fake_run, two);
  ASSERT_EQ(r.samples.size(), 64u);
  EXPECT_EQ(r.samples[63].beta0.size(), 3u);
}

TEST(MonteCarlo, EveryIndexRunsExactlyOnceAndProgressEndsAtTotal) {
  for (std::size_t threads : {1u, 2u, 3u, 8u}) {
    ThreadPoolRunner runner(threads);
    const std::size_t n = 1000;
    std::vector<std::atomic<int>> hits(n);
    std::vector<std::size_t> seen;
    std::mutex m;
    runner.run(
        n, [&](std::size_t i) { hits[i].fetch_add(1); },
        [&](std::size_t done, std::size_t total, double elapsed) {
          std::lock_guard<std::mutex> lock(m);  // the runner promises serial calls; check anyway
          EXPECT_EQ(total, n);
          EXPECT_GE(elapsed, 0.0);
          seen.push_back(done);
        });
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(hits[i].load(), 1) << i;
    ASSERT_EQ(seen.size(), n);
    for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(seen[k], k + 1);
  }
}

TEST(MonteCarlo, ZeroThreadsMeansAllCores) {
  EXPECT_EQ(ThreadPoolRunner(0).concurrency(), hardware_threads());
  EXPECT_GE(hardware_threads(), 1u);
}

TEST(MonteCarlo, AnExceptionInARunAbortsTheStudy) {
  MonteCarloStudy s = make_study(InitialConditionKind::Random, 200);
  std::atomic<int> calls{0};
  SampleFunction bad = [&](const std::vector<double>& b, const RunOverrides& o) {
    if (++calls == 17) throw std::runtime_error("boom");
    return fake_run(b, o);
  };
  ThreadPoolRunner three(3);
  EXPECT_THROW(run_monte_carlo(s, bad, three), std::runtime_error);
  EXPECT_LT(calls.load(), 200);
}

TEST(MonteCarlo, InvalidStudiesAreConfigErrors) {
  MonteCarloStudy s = make_study(InitialConditionKind::Grid, 1000);  // 32^2 = 1024
  try {
    validate(s);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("montecarlo.runs = 1000: must equal grid^balls = 32^2 = 1024"),
              std::string::npos)
        << e.what();
  }
  s = make_study(InitialConditionKind::Random, 0);
  EXPECT_THROW(validate(s), ConfigError);
  s = make_study(InitialConditionKind::Random, 10);
  s.setup.abu.balls.clear();
  EXPECT_THROW(validate(s), ConfigError);
}

// --- end to end with the real simulator ------------------------------------------------------

// A handful of runs of the report's final profile through Simulator::run (well under a second): the
// engine's guarantees hold with the real model, and the outcomes are physically plausible.
TEST(MonteCarloSimulator, FewRunsOfTheFinalProfileAreThreadCountIndependent) {
  MonteCarloStudy s;  // default setup: report table 3.2, mu 0.02, the report's final profile
  s.design.kind = InitialConditionKind::Halton;
  s.design.seed = 5;
  s.runs = 12;
  ThreadPoolRunner one(1), three(3);
  const MonteCarloResult r1 = run_monte_carlo(s, one);
  const MonteCarloResult r3 = run_monte_carlo(s, three);
  EXPECT_EQ(csv_of(r1), csv_of(r3));
  const MonteCarloSample replay = run_one(s, 4);
  EXPECT_EQ(replay.outcome.residual_imbalance_kgm, r1.samples[4].outcome.residual_imbalance_kgm);
  EXPECT_EQ(replay.outcome.beta_final, r1.samples[4].outcome.beta_final);

  const AbuParameters& p = s.setup.abu;
  // |I_r| <= m_I e + sum m_i L; I_r,x <= |I_r|
  const double bound = p.imbalance_kgm() + 2 * p.balls[0].mass_kg * p.ball_track_radius_m;
  std::size_t ok = 0;
  for (const auto& smp : r1.samples) {
    if (!smp.outcome.ok()) continue;
    ++ok;
    EXPECT_EQ(smp.outcome.beta_final.size(), 2u);
    EXPECT_GE(smp.outcome.residual_imbalance_x_kgm, 0.0);
    EXPECT_LE(smp.outcome.residual_imbalance_x_kgm, smp.outcome.residual_imbalance_kgm * (1 + 1e-12));
    EXPECT_LE(smp.outcome.residual_imbalance_kgm, bound * (1 + 1e-12));
    EXPECT_GT(smp.outcome.max_amplitude_mm, 0.0);
  }
  EXPECT_GE(ok, 10u);
  const MonteCarloStats st = compute_statistics(r1);
  EXPECT_EQ(st.ok, ok);
  EXPECT_DOUBLE_EQ(s.setup.abu.imbalance_kgm(), r1.samples[0].imbalance_kgm);
}

// --- configuration ----------------------------------------------------------------------------

MonteCarloConfig read(const std::string& yaml) {
  YamlReader root = YamlReader::load_string(yaml);
  const SimulationSetup setup;
  MonteCarloConfig c = read_monte_carlo_config(root, setup);
  root.finish();
  return c;
}

std::string error_of(const std::string& yaml) {
  try {
    read(yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(MonteCarloSimulator, ExchangedIdenticalBallsReuseOneSimulation) {
  // On an 8 x 8 grid of two identical balls, (b1, b2) and (b2, b1) are the same start with the
  // balls relabelled: 36 distinct starts of 64. Reusing them must give what simulating all 64
  // gives (to rounding: the relabelled simulation sums in another order), and run_one must replay
  // a reused run as the study computed it.
  MonteCarloStudy s;
  s.design.kind = InitialConditionKind::Grid;
  s.design.grid_points_per_axis = 8;
  s.runs = 64;
  ThreadPoolRunner two(2);
  std::size_t calls = 0;
  std::mutex m;
  const SampleFunction sim = simulator_sample_function(s.setup);
  const SampleFunction counting = [&](const std::vector<double>& b, const RunOverrides& o) {
    {
      std::lock_guard<std::mutex> lock(m);
      ++calls;
    }
    return sim(b, o);
  };
  const auto reused = run_monte_carlo(s, counting, two);
  EXPECT_EQ(calls, 36u);
  s.reuse_exchangeable = false;
  const auto all = run_monte_carlo(s, sim, two);
  for (std::size_t i = 0; i < 64; ++i) {
    for (int k = 0; k < 2; ++k) {
      double d = std::fabs(reused.samples[i].outcome.beta_final[k] - all.samples[i].outcome.beta_final[k]);
      d = std::min(d, 2 * M_PI - d);
      EXPECT_LT(d, 1e-8) << "run " << i;
    }
  }
  const MonteCarloStats st = compute_statistics(reused);
  EXPECT_EQ(st.distinct, 36u);
  // the %MI interval is the Wilson interval of the same proportion on 36 runs, not 64
  const auto ci = wilson_interval_p(st.report_x.pct_mi / 100.0, 36.0);
  EXPECT_NEAR(st.report_x.pct_mi_ci95[0], 100 * ci.first, 1e-12);
  EXPECT_NEAR(st.report_x.pct_mi_ci95[1], 100 * ci.second, 1e-12);
  // replay of a reused run (grid point (k1, k2) = (1, 0) reuses (0, 1))
  s.reuse_exchangeable = true;
  const MonteCarloSample one = run_one(s, 8);
  EXPECT_TRUE(one.reused);
  EXPECT_EQ(one.reused_from, 1u);
  EXPECT_EQ(one.outcome.beta_final, reused.samples[8].outcome.beta_final);
}

TEST(MonteCarloConfig, DefaultsAreTheReportGrid) {
  const MonteCarloConfig c = read("{}");
  EXPECT_EQ(c.study.design.kind, InitialConditionKind::Grid);
  EXPECT_EQ(c.study.design.grid_points_per_axis, 32u);
  EXPECT_EQ(c.study.runs, 1024u);
  EXPECT_EQ(c.threads, 0u);
  EXPECT_EQ(c.study.uncertain.friction.sampling, FrictionSampling::Nominal);
}

TEST(MonteCarloConfig, ReadsEveryKey) {
  const MonteCarloConfig c = read(
      "montecarlo:\n"
      "  design: sobol\n  runs: 256\n  seed: 12345\n  shift: false\n  threads: 2\n"
      "  friction: {list: [0.02, 0.03]}\n"
      "  imbalance: {angle: fixed, angle_rad: 0.5}\n");
  EXPECT_EQ(c.study.design.kind, InitialConditionKind::Sobol);
  EXPECT_EQ(c.study.runs, 256u);
  EXPECT_EQ(c.study.seed, 12345u);
  EXPECT_EQ(c.study.design.seed, 12345u);
  EXPECT_FALSE(c.study.design.random_shift);
  EXPECT_EQ(c.threads, 2u);
  EXPECT_EQ(c.study.uncertain.friction.values, (std::vector<double>{0.02, 0.03}));
  EXPECT_DOUBLE_EQ(c.study.uncertain.imbalance_angle.angle_rad, 0.5);
  EXPECT_EQ(read("montecarlo: {design: grid, grid: 8}").study.runs, 64u);
}

TEST(MonteCarloConfig, BadValuesNameKeyValueAndRule) {
  EXPECT_EQ(error_of("montecarlo: {design: random, runs: 0}"), "montecarlo.runs = 0: must be >= 1");
  EXPECT_EQ(error_of("montecarlo: {threads: -1}"), "montecarlo.threads = -1: must be >= 0");
  EXPECT_EQ(error_of("montecarlo: {design: montecarlo}"),
            "montecarlo.design = montecarlo: must be one of: grid, random, lhs, halton, sobol");
  EXPECT_NE(error_of("montecarlo: {grid: 16, runs: 100}").find("montecarlo.runs = 100: must equal grid^balls"),
            std::string::npos);
  EXPECT_EQ(error_of("montecarlo: {runz: 5}"), "montecarlo.runz = 5: unknown key (misspelt, or not valid here); did you mean 'runs'?");
}

}  // namespace
}  // namespace abuopt
