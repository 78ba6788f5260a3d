// Monte Carlo throughput on the report's final profile (0 -> 25 Hz in 1 s, 25 -> 29.5 Hz in 10 s,
// 29.5 -> 100 Hz in 8 s; mu = 0.02; end time 38 s) over the 32 x 32 grid (1024 runs).
//
//   build-mc/bench/monte_carlo_bench                       # all benchmarks, 1024 runs each
//   ABUOPT_BENCH_RUNS=256 build-mc/bench/monte_carlo_bench  # quicker: 256 random (LHS) runs
//
// BM_MonteCarloFinalProfile/threads:T/reuse:R  wall time of one study with T worker threads
//     (0 = all cores); R = 1: exchanged starts of the identical balls simulated once (the default
//     of every study: 528 simulations for the 1024-run grid), R = 0: every run simulated (1024
//     simulations); counters runs_per_s, s_per_run (wall time per run, all threads together) and
//     simulations.
// BM_UncertainParameterCost/param:P  the price of a parameter drawn per run (issue 32): the
//     2003 profile with hard contact, ABUOPT_BENCH_RUNS (default 256) random starts, one thread;
//     P = 0 friction_mu, 1 imbalance_mass_factor, 2 stiffness_factor, 3 restitution (each uniform
//     over configs/envelope.yaml's range), 4 all four, 5 imbalance_mass_factor U[1, 1 + 1e-6] (an
//     uncertain imbalance that is effectively constant, against the same Simulator's nominal
//     runs). Run i of the study (its overrides) and run i as a nominal run of a Simulator built
//     with run i's values run back to back; each
//     best of three in thread CPU time. Counters: ratio = sum of the study's run times / sum of the nominal runs'
//     (1.0: an uncertain parameter costs nothing), ms_per_run of both, and differ = runs whose
//     |I_r| differs by more than 1e-9 relative (expected 0: the same physics).
// BM_InterleavedDesigns  6 designs (the 2003 profile, its last segment 0, 1, ..., 5 % longer) with
//     the report's stiffness envelope (2-3 forcing-sample rungs each), ABUOPT_BENCH_RUNS (default
//     24) runs per design evaluated interleaved (design 0 run 0, design 1 run 0, ...), one thread,
//     thread CPU time, in one program run: before = the replaced process-wide LRU cache of 8
//     (profile, rung) entries replayed (a miss builds the rung: the run on a fresh Simulator; a hit:
//     on the design's Simulator), after = each design's Simulator keeping its rungs. Counters:
//     misses_before (of 6 x runs), ratio = before / after, ms_per_run of both, differ = runs whose
//     outcome differs (expected 0).
// BM_ParallelEfficiency  the study without reuse on 1 and then 2 threads; counters t1_s, t2_s,
//     speedup = t1/t2 and efficiency = speedup / 2 (1.0 = perfect scaling). On a machine shared
//     with other jobs the figures are lower bounds.
#include <benchmark/benchmark.h>

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"
#include "abuopt/core/simulator.hpp"
#include "run_forcing_table.hpp"

namespace {

using namespace abuopt;

std::size_t bench_runs() {
  if (const char* e = std::getenv("ABUOPT_BENCH_RUNS")) {
    const long n = std::strtol(e, nullptr, 10);
    if (n > 0) return static_cast<std::size_t>(n);
  }
  return 1024;
}

MonteCarloStudy final_profile_study(bool reuse = true) {
  MonteCarloStudy s;
  s.reuse_exchangeable = reuse;
  s.setup.profile = StartupProfile::report_final();
  s.setup.abu.friction_mu = 0.02;
  s.runs = bench_runs();
  if (s.runs == 1024) {
    s.design.kind = InitialConditionKind::Grid;
    s.design.grid_points_per_axis = 32;
  } else {
    s.design.kind = InitialConditionKind::LatinHypercube;
    s.design.seed = 1;
  }
  return s;
}

double run_study(const MonteCarloStudy& s, const SampleFunction& f, std::size_t threads) {
  ThreadPoolRunner runner(threads);
  const MonteCarloResult r = run_monte_carlo(s, f, runner);
  benchmark::DoNotOptimize(r.samples.data());
  return r.wall_time_s;
}

void BM_MonteCarloFinalProfile(benchmark::State& state) {
  const MonteCarloStudy s = final_profile_study(state.range(1) != 0);
  const SampleFunction f = simulator_sample_function(s.setup);
  const auto threads = static_cast<std::size_t>(state.range(0));
  double wall = 0;
  std::size_t failed = 0, simulations = 0;
  for (auto _ : state) {
    ThreadPoolRunner runner(threads);
    const MonteCarloResult r = run_monte_carlo(s, f, runner);
    wall = r.wall_time_s;
    const MonteCarloStats st = compute_statistics(r.samples);
    failed = st.failed;
    simulations = st.distinct + st.failed;
    state.SetIterationTime(wall);
    state.counters["workers"] = static_cast<double>(runner.concurrency());
  }
  state.counters["runs"] = static_cast<double>(s.runs);
  state.counters["failed"] = static_cast<double>(failed);
  state.counters["simulations"] = static_cast<double>(simulations);
  state.counters["runs_per_s"] = static_cast<double>(s.runs) / wall;
  state.counters["s_per_run"] = wall / static_cast<double>(s.runs);
}
BENCHMARK(BM_MonteCarloFinalProfile)
    ->ArgNames({"threads", "reuse"})
    ->Args({0, 1})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kSecond);

void BM_ParallelEfficiency(benchmark::State& state) {
  const MonteCarloStudy s = final_profile_study(false);
  const SampleFunction f = simulator_sample_function(s.setup);
  double t1 = 0, t2 = 0;
  for (auto _ : state) {
    t1 = run_study(s, f, 1);
    t2 = run_study(s, f, 2);
    state.SetIterationTime(t1 + t2);
  }
  state.counters["t1_s"] = t1;
  state.counters["t2_s"] = t2;
  state.counters["speedup"] = t1 / t2;
  state.counters["efficiency"] = t1 / (2.0 * t2);
}
BENCHMARK(BM_ParallelEfficiency)->Iterations(1)->UseManualTime()->Unit(benchmark::kSecond);

// CPU time of this thread [s]: on a machine shared with other jobs, wall time measures them too.
double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void BM_UncertainParameterCost(benchmark::State& state) {
  const long param = state.range(0);
  MonteCarloStudy s;
  s.reuse_exchangeable = false;
  s.setup.profile = StartupProfile::report_final();
  s.setup.abu.ball_contact = BallContact::Hard;
  s.design.kind = InitialConditionKind::Random;
  s.design.seed = 32;
  s.seed = 32;
  const char* e = std::getenv("ABUOPT_BENCH_RUNS");
  s.runs = e && std::strtol(e, nullptr, 10) > 0 ? static_cast<std::size_t>(std::strtol(e, nullptr, 10)) : 256;
  const Envelope full = Envelope::report();
  if (param == 4) {
    s.uncertain.envelope = full;
  } else if (param == 5) {
    s.uncertain.envelope.imbalance_mass_factor = ParameterDistribution::uniform(1.0, 1.0 + 1e-6);
  } else {
    s.uncertain.envelope.parameter(static_cast<std::size_t>(param)) = full.parameter(static_cast<std::size_t>(param));
  }
  const PreparedStudy p = prepare_study(s);
  const Simulator study_sim(s.setup);
  double t_study = 0, t_nominal = 0;
  std::size_t differ = 0;
  for (auto _ : state) {
    t_study = t_nominal = 0;
    differ = 0;
    for (const MonteCarloSample& smp : p.samples) {
      SimulationSetup at = s.setup;
      at.abu.friction_mu = smp.friction_mu;
      at.abu.imbalance_mass_kg = smp.overrides.imbalance_mass_kg.value_or(at.abu.imbalance_mass_kg);
      at.abu.stiffness_N_per_m = smp.stiffness_N_per_m;
      at.abu.ball_restitution = smp.restitution;
      // built outside the timing (its table: the nominal's price); P = 5 compares with the
      // study's own Simulator without the override (values equal to 1e-6: the measurement)
      const std::unique_ptr<const Simulator> own = param == 5 ? nullptr : std::make_unique<const Simulator>(at);
      const Simulator& nominal_sim = own ? *own : study_sim;
      RunOverrides angle_only;
      angle_only.imbalance_angle_rad = smp.overrides.imbalance_angle_rad;
      double a = 1e300, b = 1e300, ir_a = 0, ir_b = 0;
      for (int rep = 0; rep < 3; ++rep) {
        const double t0 = thread_cpu_s();
        const RunOutcome ou = study_sim.run(smp.beta0, smp.overrides);
        const double t1 = thread_cpu_s();
        const RunOutcome on = nominal_sim.run(smp.beta0, angle_only);
        const double t2 = thread_cpu_s();
        a = std::min(a, t1 - t0);
        b = std::min(b, t2 - t1);
        ir_a = ou.residual_imbalance_kgm;
        ir_b = on.residual_imbalance_kgm;
      }
      t_study += a;
      t_nominal += b;
      if (std::fabs(ir_a - ir_b) > 1e-9 * std::max(std::fabs(ir_b), 1e-12)) ++differ;
    }
    state.SetIterationTime(t_study + t_nominal);
  }
  state.counters["runs"] = static_cast<double>(s.runs);
  state.counters["ratio"] = t_study / t_nominal;
  state.counters["study_ms_per_run"] = 1e3 * t_study / static_cast<double>(s.runs);
  state.counters["nominal_ms_per_run"] = 1e3 * t_nominal / static_cast<double>(s.runs);
  state.counters["differ"] = static_cast<double>(differ);
}
void BM_InterleavedDesigns(benchmark::State& state) {
  constexpr std::size_t kDesigns = 6, kOldCache = 8;
  const char* e = std::getenv("ABUOPT_BENCH_RUNS");
  const std::size_t runs =
      e && std::strtol(e, nullptr, 10) > 0 ? static_cast<std::size_t>(std::strtol(e, nullptr, 10)) : 24;
  std::vector<MonteCarloStudy> studies;
  std::vector<PreparedStudy> prepared;
  for (std::size_t d = 0; d < kDesigns; ++d) {
    MonteCarloStudy s;
    s.reuse_exchangeable = false;
    std::vector<InclinedSineSegment> seg = StartupProfile::report_final().segments();
    seg.back().duration_s *= 1.0 + 0.01 * static_cast<double>(d);
    s.setup.profile = StartupProfile(seg);
    s.design.kind = InitialConditionKind::Random;
    s.design.seed = 40 + d;
    s.seed = 40 + d;
    s.runs = runs;
    s.uncertain.envelope.stiffness_factor = Envelope::report().stiffness_factor;
    studies.push_back(s);
    prepared.push_back(prepare_study(s));
  }
  // the old cache's key of a run: (design, ladder step of the run's damped frequency)
  auto rung = [&](std::size_t d, const MonteCarloSample& smp) {
    AbuParameters p = studies[d].setup.abu;
    p.stiffness_N_per_m = smp.stiffness_N_per_m;
    return detail::ForcingSamples::ladder(detail::RunForcingTable::damped_frequency(NondimParameters::from(p)));
  };
  double t_before = 0, t_after = 0;
  std::size_t misses = 0, differ = 0;
  for (auto _ : state) {
    t_before = t_after = 0;
    misses = differ = 0;
    std::vector<RunOutcome> before(kDesigns * runs);
    {
      std::vector<std::unique_ptr<Simulator>> sims;
      for (const auto& s : studies) sims.push_back(std::make_unique<Simulator>(s.setup));
      std::deque<std::pair<std::size_t, double>> lru;  // most recently used first
      for (std::size_t i = 0; i < runs; ++i)
        for (std::size_t d = 0; d < kDesigns; ++d) {
          const MonteCarloSample& smp = prepared[d].samples[i];
          const std::pair<std::size_t, double> key{d, rung(d, smp)};
          const auto it = std::find(lru.begin(), lru.end(), key);
          const bool hit = it != lru.end();
          if (hit) lru.erase(it);
          lru.push_front(key);
          if (lru.size() > kOldCache) lru.pop_back();
          std::unique_ptr<Simulator> fresh = hit ? nullptr : std::make_unique<Simulator>(studies[d].setup);
          misses += hit ? 0 : 1;
          const double t0 = thread_cpu_s();
          before[d * runs + i] = (hit ? *sims[d] : *fresh).run(smp.beta0, smp.overrides);
          t_before += thread_cpu_s() - t0;
        }
    }
    {
      std::vector<std::unique_ptr<Simulator>> sims;
      for (const auto& s : studies) sims.push_back(std::make_unique<Simulator>(s.setup));
      for (std::size_t i = 0; i < runs; ++i)
        for (std::size_t d = 0; d < kDesigns; ++d) {
          const MonteCarloSample& smp = prepared[d].samples[i];
          const double t0 = thread_cpu_s();
          const RunOutcome o = sims[d]->run(smp.beta0, smp.overrides);
          t_after += thread_cpu_s() - t0;
          const RunOutcome& b = before[d * runs + i];
          if (o.beta_final != b.beta_final || o.residual_imbalance_kgm != b.residual_imbalance_kgm) ++differ;
        }
    }
    state.SetIterationTime(t_before + t_after);
  }
  const double n = static_cast<double>(kDesigns * runs);
  state.counters["runs"] = n;
  state.counters["misses_before"] = static_cast<double>(misses);
  state.counters["ratio"] = t_before / t_after;
  state.counters["before_ms_per_run"] = 1e3 * t_before / n;
  state.counters["after_ms_per_run"] = 1e3 * t_after / n;
  state.counters["differ"] = static_cast<double>(differ);
}
BENCHMARK(BM_InterleavedDesigns)->Iterations(1)->UseManualTime()->Unit(benchmark::kSecond);

BENCHMARK(BM_UncertainParameterCost)
    ->ArgName("param")
    ->DenseRange(0, 5)
    ->Iterations(1)
    ->UseManualTime()
    ->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
