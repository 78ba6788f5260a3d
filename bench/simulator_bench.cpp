// Cost of one simulation of the report's final profile (end time 38 s) and of one right-hand-side
// evaluation. Run: build/bench/simulator_bench [--benchmark_filter=...]
// Figures: docs/performance.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "abuopt/core/abu_model.hpp"
#include "abuopt/core/simulator.hpp"

namespace {

abuopt::SimulationSetup final_profile(abuopt::IntegratorBackend backend, double rtol) {
  abuopt::SimulationSetup s;  // defaults: report table 3.2, mu = 0.02, the report's final profile
  s.options.backend = backend;
  s.options.rtol = rtol;
  s.options.atol = rtol * 1e-3;  // the default pair is rtol 1e-6, atol 1e-9
  return s;
}

// Fixed initial conditions, cycled: 16 angle pairs from a fixed seed.
std::vector<std::vector<double>> fixed_initial_conditions() {
  std::mt19937_64 rng(2003);
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  std::vector<std::vector<double>> v;
  for (int i = 0; i < 16; ++i) v.push_back({u(rng), u(rng)});
  return v;
}

void run_profile(benchmark::State& state, abuopt::IntegratorBackend backend) {
  const double rtol = std::pow(10.0, -static_cast<double>(state.range(0)));
  abuopt::Simulator sim(final_profile(backend, rtol));
  const auto ics = fixed_initial_conditions();
  std::size_t k = 0;
  double rhs = 0, steps = 0, events = 0, runs = 0;
  for (auto _ : state) {
    const auto o = sim.run(ics[k++ % ics.size()]);
    benchmark::DoNotOptimize(o.residual_imbalance_kgm);
    rhs += static_cast<double>(o.rhs_evaluations);
    steps += static_cast<double>(o.steps);
    events += static_cast<double>(o.events);
    runs += 1;
  }
  state.counters["rhs_per_run"] = rhs / runs;
  state.counters["steps_per_run"] = steps / runs;
  state.counters["events_per_run"] = events / runs;
}

void BM_FinalProfileRun_Native(benchmark::State& state) { run_profile(state, abuopt::IntegratorBackend::Native); }
void BM_FinalProfileRun_Arkode(benchmark::State& state) { run_profile(state, abuopt::IntegratorBackend::ArkodeErk); }
BENCHMARK(BM_FinalProfileRun_Native)->Arg(6)->Arg(8)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FinalProfileRun_Arkode)->Arg(6)->Unit(benchmark::kMillisecond)->Iterations(32);

// Ball contact: the same 16 starts (mapped onto the feasible set by the simulator when they
// overlap), contact none vs hard, in one program run so the ratio is measured under one load.
void run_contact(benchmark::State& state, abuopt::BallContact contact) {
  abuopt::SimulationSetup s = final_profile(abuopt::IntegratorBackend::Native, 1e-6);
  s.abu.ball_contact = contact;
  abuopt::Simulator sim(s);
  const auto ics = fixed_initial_conditions();
  std::size_t k = 0;
  double events = 0, impacts = 0, runs = 0;
  for (auto _ : state) {
    const auto o = sim.run(ics[k++ % ics.size()]);
    benchmark::DoNotOptimize(o.residual_imbalance_kgm);
    events += static_cast<double>(o.events);
    impacts += static_cast<double>(o.impacts);
    runs += 1;
  }
  state.counters["events_per_run"] = events / runs;
  state.counters["impacts_per_run"] = impacts / runs;
}
void BM_FinalProfileRun_ContactNone(benchmark::State& state) { run_contact(state, abuopt::BallContact::None); }
void BM_FinalProfileRun_ContactHard(benchmark::State& state) { run_contact(state, abuopt::BallContact::Hard); }
BENCHMARK(BM_FinalProfileRun_ContactNone)->Unit(benchmark::kMillisecond)->Iterations(160);
BENCHMARK(BM_FinalProfileRun_ContactHard)->Unit(benchmark::kMillisecond)->Iterations(160);

void BM_RhsEvaluation(benchmark::State& state) {
  abuopt::AbuParameters p;
  abuopt::AbuModel model(abuopt::NondimParameters::from(p));
  std::vector<double> y = {0.01, -0.02, 0.001, 0.002, 1.0, 4.0, -0.1, 0.05};
  std::vector<abuopt::BallMode> modes = {abuopt::BallMode::SlipBackward, abuopt::BallMode::SlipForward};
  abuopt::ModelForces f(2);
  double W = 0.9;
  for (auto _ : state) {
    model.evaluate(y.data(), W, 0.01, modes.data(), 0.02, f);
    benchmark::DoNotOptimize(f.xdd);
    W += 1e-9;
  }
}
BENCHMARK(BM_RhsEvaluation);

}  // namespace

BENCHMARK_MAIN();
