// Accuracy of the default integrator settings against a tight-tolerance reference, over many
// random initial conditions of the report's final profile (not a Google Benchmark: it prints a
// table). Usage: simulator_accuracy [runs=1024] [rtol=1e-6] [reference_rtol=1e-10] [table]
//   [stuck_integrator=default] [reference_stuck_integrator=default]   (rk or exact)
//   [ball_contact=none]   (none or hard: both settings with that ball contact)
// Reports: the largest final-angle difference, how many runs differ by more than 1e-3 rad,
// and the mean CPU time per run of both settings.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "abuopt/core/simulator.hpp"

using namespace abuopt;

namespace {
double angle_distance(double a, double b) {
  double d = std::fmod(std::fabs(a - b), 2 * M_PI);
  return std::min(d, 2 * M_PI - d);
}
}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::atoi(argv[1]) : 1024;
  const double rtol = argc > 2 ? std::atof(argv[2]) : 1e-6;
  const double ref_rtol = argc > 3 ? std::atof(argv[3]) : 1e-10;
  SimulationSetup fast, ref;
  if (argc > 4 && std::string(argv[4]) != "default") fast.options.erk_table = ref.options.erk_table = argv[4];
  auto stuck = [](const std::string& v) {
    if (v == "rk") return StuckIntegrator::RungeKutta;
    if (v == "exact") return StuckIntegrator::Exact;
    std::fprintf(stderr, "stuck integrator must be rk or exact, not '%s'\n", v.c_str());
    std::exit(2);
  };
  if (argc > 5 && std::string(argv[5]) != "default") fast.options.stuck_integrator = stuck(argv[5]);
  if (argc > 6 && std::string(argv[6]) != "default") ref.options.stuck_integrator = stuck(argv[6]);
  if (argc > 7) {
    const std::string c = argv[7];
    if (c != "none" && c != "hard") {
      std::fprintf(stderr, "ball contact must be none or hard, not '%s'\n", c.c_str());
      return 2;
    }
    fast.abu.ball_contact = ref.abu.ball_contact = c == "hard" ? BallContact::Hard : BallContact::None;
  }
  fast.options.rtol = rtol;
  fast.options.atol = rtol * 1e-3;
  ref.options.rtol = ref_rtol;
  ref.options.atol = ref_rtol * 1e-3;
  Simulator sf(fast), sr(ref);
  std::mt19937_64 rng(20031);
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  std::vector<std::vector<double>> ics(static_cast<std::size_t>(runs));
  for (auto& ic : ics) ic = {u(rng), u(rng)};
  std::vector<double> dev(ics.size()), tf(ics.size()), tr(ics.size()), rhs(ics.size());
  std::vector<int> ok(ics.size());
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i; (i = next++) < ics.size();) {
      const RunOutcome a = sf.run(ics[i]);
      const RunOutcome b = sr.run(ics[i]);
      tf[i] = a.wall_time_s;
      tr[i] = b.wall_time_s;
      rhs[i] = static_cast<double>(a.rhs_evaluations);
      ok[i] = a.ok() && b.ok();
      dev[i] = std::max(angle_distance(a.beta_final[0], b.beta_final[0]), angle_distance(a.beta_final[1], b.beta_final[1]));
    }
  };
  std::vector<std::thread> pool;
  const unsigned nt = std::max(1u, std::thread::hardware_concurrency());
  for (unsigned t = 0; t < nt; ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  int over = 0, failed = 0;
  double worst = 0, mean_f = 0, mean_r = 0, mean_rhs = 0;
  for (std::size_t i = 0; i < ics.size(); ++i) {
    over += dev[i] > 1e-3;
    failed += !ok[i];
    worst = std::max(worst, dev[i]);
    mean_f += tf[i] / runs;
    mean_r += tr[i] / runs;
    mean_rhs += rhs[i] / runs;
  }
  std::printf("runs %d  rtol %.1e (stuck %s) vs reference %.1e (stuck %s)  table %s\n", runs, rtol,
              to_string(fast.options.stuck_integrator).c_str(), ref_rtol, to_string(ref.options.stuck_integrator).c_str(),
              fast.options.erk_table.c_str());
  std::printf("max |delta beta| %.3e rad, runs over 1e-3 rad: %d, failed: %d\n", worst, over, failed);
  std::printf("mean wall per run: %.3f ms (reference %.3f ms), mean RHS evaluations %.0f\n", mean_f * 1e3, mean_r * 1e3, mean_rhs);
  return over == 0 && failed == 0 ? 0 : 1;
}
