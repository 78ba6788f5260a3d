// Cost of one simulation of the report's final profile (end time 38 s) and of one right-hand-side
// evaluation. Run: build/bench/simulator_bench [--benchmark_filter=...]
// Figures: docs/performance.md.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <random>

#include "abuopt/core/abu_model.hpp"
#include "abuopt/core/sim_counters.hpp"
#include "abuopt/core/simulator.hpp"

namespace {

abuopt::SimulationSetup final_profile(abuopt::IntegratorBackend backend, double rtol,
                                      abuopt::StuckIntegrator stuck) {
  abuopt::SimulationSetup s;  // defaults: report table 3.2, mu = 0.02, the report's final profile
  s.options.backend = backend;
  s.options.rtol = rtol;
  s.options.atol = rtol * 1e-3;  // the default pair is rtol 1e-6, atol 1e-9
  s.options.stuck_integrator = stuck;
  return s;
}

abuopt::StuckIntegrator stuck_arg(std::int64_t a) {
  return a ? abuopt::StuckIntegrator::Exact : abuopt::StuckIntegrator::RungeKutta;
}

// Fixed initial conditions, cycled: 16 angle tuples from a fixed seed.
std::vector<std::vector<double>> fixed_initial_conditions(std::size_t balls = 2) {
  std::mt19937_64 rng(2003);
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  std::vector<std::vector<double>> v;
  for (int i = 0; i < 16; ++i) {
    std::vector<double> b;
    for (std::size_t k = 0; k < balls; ++k) b.push_back(u(rng));
    v.push_back(b);
  }
  return v;
}

// Runs the simulator over the fixed starts; counters per run. With `detail`, also the events by
// kind (root functions that crossed) and the right-hand sides by purpose (sim_counters.hpp).
void run_cycle(benchmark::State& state, const abuopt::Simulator& sim, bool detail = false) {
  const auto ics = fixed_initial_conditions(sim.ball_count());
  std::size_t k = 0;
  double rhs = 0, steps = 0, events = 0, impacts = 0, failed = 0, runs = 0;
  abuopt::sim_counters() = {};
  for (auto _ : state) {
    const auto o = sim.run(ics[k++ % ics.size()]);
    benchmark::DoNotOptimize(o.residual_imbalance_kgm);
    rhs += static_cast<double>(o.rhs_evaluations);
    steps += static_cast<double>(o.steps);
    events += static_cast<double>(o.events);
    impacts += static_cast<double>(o.impacts);
    failed += o.ok() ? 0 : 1;
    runs += 1;
  }
  state.counters["rhs_per_run"] = rhs / runs;
  state.counters["steps_per_run"] = steps / runs;
  state.counters["events_per_run"] = events / runs;
  if (!detail) return;
  const abuopt::SimCounters& c = abuopt::sim_counters();
  const auto per_run = [&](long v) { return static_cast<double>(v) / runs; };
  state.counters["impacts_per_run"] = impacts / runs;
  state.counters["failed_share"] = failed / runs;  // runs that ended early (chatter limit, ...)
  state.counters["ev_stick_slip"] = per_run(c.stick_to_slip);
  state.counters["ev_slip_stop"] = per_run(c.slip_stop);
  state.counters["ev_gap"] = per_run(c.gap_closed);
  state.counters["ev_contact_open"] = per_run(c.contact_open);
  state.counters["resets"] = per_run(c.resets);
  state.counters["rhs_acc"] = per_run(c.rhs_accepted);
  state.counters["rhs_rej"] = per_run(c.rhs_rejected);
  state.counters["rhs_root"] = per_run(c.rhs_root);
  state.counters["rhs_after_reset"] = per_run(c.rhs_after_reset);
  state.counters["root_evals"] = per_run(c.root_evaluations);
  state.counters["polishes"] = per_run(c.polishes);
  state.counters["polish_steps"] = per_run(c.polish_steps);
  state.counters["dips"] = per_run(c.dips);
}

// Args: -log10(rtol), stuck integrator (0 rk, 1 exact).
void run_profile(benchmark::State& state, abuopt::IntegratorBackend backend) {
  const double rtol = std::pow(10.0, -static_cast<double>(state.range(0)));
  abuopt::Simulator sim(final_profile(backend, rtol, stuck_arg(state.range(1))));
  run_cycle(state, sim);
}

void BM_FinalProfileRun_Native(benchmark::State& state) { run_profile(state, abuopt::IntegratorBackend::Native); }
void BM_FinalProfileRun_Arkode(benchmark::State& state) { run_profile(state, abuopt::IntegratorBackend::ArkodeErk); }
BENCHMARK(BM_FinalProfileRun_Native)
    ->ArgsProduct({{6, 8}, {0, 1}})
    ->ArgNames({"rtol_exp", "exact"})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FinalProfileRun_Arkode)->Args({6, 0})->Unit(benchmark::kMillisecond)->Iterations(32);

// The report's final profile under the PI drive (friction feedback on), with and without the
// closed-form tail after the profile (docs/model.md 6.1). Args: tail (0/1), 1 Hz setpoints (0/1),
// balls (2: the report's; 6: equal total mass in hard contact, the study's mean-goal ABU).
void BM_PiDriveRun(benchmark::State& state) {
  abuopt::SimulationSetup s = final_profile(abuopt::IntegratorBackend::Native, 1e-6, abuopt::StuckIntegrator::Exact);
  s.motor.kind = abuopt::MotorKind::PI;
  s.options.closed_form_tail = state.range(0) != 0;
  s.motor.quantize_setpoint_1hz = state.range(1) != 0;
  if (state.range(2) == 6) {
    s.abu.balls.assign(6, abuopt::Ball{2.8e-4 / 6, 3.0e-3 * std::cbrt(2.0 / 6)});
    s.abu.ball_contact = abuopt::BallContact::Hard;
  }
  abuopt::Simulator sim(s);
  run_cycle(state, sim);
}
BENCHMARK(BM_PiDriveRun)
    ->ArgsProduct({{0, 1}, {0, 1}, {2, 6}})
    ->ArgNames({"tail", "pi1hz", "balls"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(32);

// Cost against the tolerance (-log10 rtol 4..10), both stuck integrators.
void BM_Tolerance(benchmark::State& state) { run_profile(state, abuopt::IntegratorBackend::Native); }
BENCHMARK(BM_Tolerance)
    ->ArgsProduct({{4, 5, 6, 7, 8, 9, 10}, {0, 1}})
    ->ArgNames({"rtol_exp", "exact"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(64);

// Cost against the number of balls N, final profile, in four configurations (arg `cfg`):
//   0  identical balls of the report (1.4e-4 kg, 3 mm), no contact
//   1  identical balls, hard contact
//   2  equal total ball mass (2.8e-4 kg, two report balls; the study's formulation 4): m = 2.8e-4 / N,
//      same material, d = 3 mm (2 / N)^(1/3); no contact
//   3  equal total ball mass, hard contact
void BM_BallCount(benchmark::State& state) {
  abuopt::SimulationSetup s = final_profile(abuopt::IntegratorBackend::Native, 1e-6, stuck_arg(state.range(1)));
  const auto n = static_cast<std::size_t>(state.range(0));
  const std::int64_t cfg = state.range(2);
  abuopt::Ball b;
  if (cfg >= 2) {
    b.mass_kg = 2.8e-4 / static_cast<double>(n);
    b.diameter_m = 3.0e-3 * std::cbrt(2.0 / static_cast<double>(n));
  }
  s.abu.balls.assign(n, b);
  if (cfg == 1 || cfg == 3) s.abu.ball_contact = abuopt::BallContact::Hard;
  abuopt::Simulator sim(s);
  run_cycle(state, sim, true);
}
BENCHMARK(BM_BallCount)
    ->ArgsProduct({{2, 3, 4, 6, 9}, {0, 1}, {0}})
    ->ArgsProduct({{2, 3, 4, 6, 9}, {1}, {1, 2, 3}})
    ->ArgNames({"balls", "exact", "cfg"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(64);

// Cost against the profile's length: the final profile with every duration scaled so that it
// lasts T s (end time 2T, the report's rule).
void BM_ProfileLength(benchmark::State& state) {
  abuopt::SimulationSetup s = final_profile(abuopt::IntegratorBackend::Native, 1e-6, stuck_arg(state.range(1)));
  const double scale = static_cast<double>(state.range(0)) / 19.0;
  s.profile = abuopt::StartupProfile({{25.0, 1.0 * scale}, {29.5, 10.0 * scale}, {100.0, 8.0 * scale}});
  abuopt::Simulator sim(s);
  run_cycle(state, sim);
}
BENCHMARK(BM_ProfileLength)
    ->ArgsProduct({{10, 19, 30, 45, 60}, {0, 1}})
    ->ArgNames({"seconds", "exact"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(64);

// Building a Simulator and its first run: with the exact stuck integrator the first run computes
// the forcing table, or takes it from the process-wide cache of recent tables
// (StuckForcingTable::shared). cached:0 makes every iteration's profile new (the last duration
// moves by 1 ns), so the table is built each time.
void BM_SimulatorSetup(benchmark::State& state) {
  auto s = final_profile(abuopt::IntegratorBackend::Native, 1e-6, stuck_arg(state.range(0)));
  std::vector<abuopt::InclinedSineSegment> seg = s.profile.segments();
  long k = 0;
  for (auto _ : state) {
    if (state.range(1) == 0) {
      seg.back().duration_s = 8.0 + 1e-9 * static_cast<double>(++k);
      s.profile = abuopt::StartupProfile(seg);
    }
    abuopt::Simulator sim(s);
    benchmark::DoNotOptimize(sim.run(fixed_initial_conditions().front()));
  }
}
BENCHMARK(BM_SimulatorSetup)
    ->Args({0, 1})
    ->Args({1, 0})
    ->Args({1, 1})
    ->ArgNames({"exact", "cached"})
    ->Unit(benchmark::kMillisecond);

// Ball contact: the same 16 starts (mapped onto the feasible set by the simulator when they
// overlap), contact none vs hard, in one program run so the ratio is measured under one load.
void run_contact(benchmark::State& state, abuopt::BallContact contact) {
  abuopt::SimulationSetup s = final_profile(abuopt::IntegratorBackend::Native, 1e-6, abuopt::StuckIntegrator::Exact);
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
