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
// BM_ParallelEfficiency  the study without reuse on 1 and then 2 threads; counters t1_s, t2_s,
//     speedup = t1/t2 and efficiency = speedup / 2 (1.0 = perfect scaling). On a machine shared
//     with other jobs the figures are lower bounds.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>

#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"

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

}  // namespace

BENCHMARK_MAIN();
