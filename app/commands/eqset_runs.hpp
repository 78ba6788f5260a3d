#pragma once
// abuopt eqset CONFIG --runs RUNS_CSV: where the runs of a Monte Carlo stopped, against the
// equilibrium sets (core/final_states.hpp; docs/equilibrium_sets.md section 6).
#include <optional>
#include <string>
#include <vector>

#include "abuopt/core/simulator.hpp"

namespace abuopt::app {

struct EqsetRunsArgs {
  std::string runs_csv;
  std::string split = "speed";     // speed | passage
  std::optional<double> edge_hz;   // the split's band edge (default: r_in = 2 r_lock)
  std::string out;                 // writes OUT/final_states.csv when given
  bool json = false;
};

// Reads RUNS_CSV (the runs.csv of `abuopt montecarlo --out`), measures every settled run with the
// ABU and profile of `setup` and the run's own mu / imbalance mass / stiffness, prints the
// distribution. Returns the exit status (0; 3 when no run settled). ConfigError on bad input.
int run_eqset_runs(const SimulationSetup& setup, const EqsetRunsArgs& a);

// abuopt eqset CONFIG --lock-set [--grid N] [--alpha RAD_S2] [--mu MU]: uniform starts in the lock set
// (core lock_set_statistics) over the n x n grid of the first two balls, the others at other_beta.
int run_eqset_lock_set(const AbuParameters& abu, const std::vector<double>& other_beta, std::size_t grid,
                       double alpha_rad_s2, bool json);

}  // namespace abuopt::app
