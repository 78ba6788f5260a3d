// Whole runs with hard contact from random starts: how many end early (chatter limit), their
// events, and the contact mode choices (pivots, enumeration fallbacks), for the simulator's
// pivoting choice or the enumeration it replaced (docs/model.md 11.8, docs/performance.md).
// Usage: contact_runs BALLS SEED RUNS [cfg: identical|equal_mass] [auto|enumerate|compare]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <random>
#include <string>

#include "abuopt/core/ball_contact.hpp"
#include "abuopt/core/sim_counters.hpp"
#include "abuopt/core/simulator.hpp"
#include "sim_run_state.hpp"

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s BALLS SEED RUNS [identical|equal_mass] [auto|enumerate|compare]\n", argv[0]);
    return 2;
  }
  const auto n = static_cast<std::size_t>(std::atoi(argv[1]));
  const auto seed = static_cast<std::uint64_t>(std::atoll(argv[2]));
  const int runs = std::atoi(argv[3]);
  const std::string cfg = argc > 4 ? argv[4] : "identical";
  const std::string method = argc > 5 ? argv[5] : "auto";
  if (n < 2 || runs < 1 || (cfg != "identical" && cfg != "equal_mass") || (method != "auto" && method != "enumerate" && method != "compare")) {
    std::fprintf(stderr, "bad arguments\n");
    return 2;
  }
  using abuopt::detail::ContactChoiceMethod;
  abuopt::detail::run_contact_choice() = method == "auto"        ? ContactChoiceMethod::Auto
                                         : method == "enumerate" ? ContactChoiceMethod::Enumerate
                                                                 : ContactChoiceMethod::Compare;
  abuopt::SimulationSetup s;  // the report's ABU and final profile
  abuopt::Ball b;
  if (cfg == "equal_mass") {  // as BM_BallCount cfg 3: 2.8e-4 kg in all, same material
    b.mass_kg = 2.8e-4 / static_cast<double>(n);
    b.diameter_m = 3.0e-3 * std::cbrt(2.0 / static_cast<double>(n));
  }
  s.abu.balls.assign(n, b);
  s.abu.ball_contact = abuopt::BallContact::Hard;
  abuopt::Simulator sim(s);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 2 * M_PI);
  abuopt::sim_counters() = {};
  int failed = 0, overlaps = 0;
  double events = 0, min_clearance = 1e300;
  const std::clock_t c0 = std::clock();
  for (int k = 0; k < runs; ++k) {
    std::vector<double> beta(n);
    for (double& x : beta) x = u(rng);
    const double corr_before = abuopt::sim_counters().max_gap_correction;
    abuopt::sim_counters().max_gap_correction = 0;
    const abuopt::RunOutcome o = sim.run(beta);
    const double corr = abuopt::sim_counters().max_gap_correction;
    if (corr > 1e-9) std::printf("run %d: an overlap of %.2g rad projected at an event\n", k, corr);
    abuopt::sim_counters().max_gap_correction = std::max(corr_before, corr);
    if (!o.ok()) {
      ++failed;
      std::printf("run %d: %s\n", k, o.message.c_str());
    }
    const double clearance = abuopt::min_contact_clearance(s.abu, o.beta_final);
    overlaps += clearance < -1e-12;
    min_clearance = std::min(min_clearance, clearance);
    events += static_cast<double>(o.events);
  }
  const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  const abuopt::SimCounters& c = abuopt::sim_counters();
  std::printf("%zu balls %s, %s, seed %llu: %d runs, %d failed, %d overlapping (final clearance >= %.2g rad), %.1f events/run, CPU %.3f ms/run, "
              "mode choices %ld (%.2f pivots each, %ld enumerated)",
              n, cfg.c_str(), method.c_str(), static_cast<unsigned long long>(seed), runs, failed, overlaps,
              min_clearance, events / runs, 1e3 * cpu / runs, c.mode_choices,
              c.mode_choices ? static_cast<double>(c.mode_pivots) / static_cast<double>(c.mode_choices) : 0.0,
              c.mode_fallbacks);
  // the largest overlap projected at any event (docs/model.md 11.11: ~1e-12 when every event is
  // located) and the roots found inside a step from their rates (gaps and stops)
  std::printf(", largest overlap projected %.2g rad, %ld dips", c.max_gap_correction, c.dips);
  if (method == "compare")
    std::printf(", the enumeration's choice differs in %ld (it is consistent in %ld)", c.mode_differs,
                c.mode_enum_consistent);
  std::printf("\n");
  return 0;
}
