#pragma once
// Internal: what the pagmo2 adapters share (pagmo_adapter.cpp: CMA-ES, xNES, SADE, PSO;
// pagmo_nsga2.cpp: NSGA-II). pagmo searches the unit box u in [0, 1]^n; the driver's scaled point is
// y = lo + u (hi - lo). Constraints are Deb's feasibility rules in the fitness: a feasible point's
// own value, an infeasible one kInfeasible (1 + violation), a failed evaluation kFailed.
#include <algorithm>
#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "evaluation_driver.hpp"

namespace abuopt::opt::detail::pagmo_common {

constexpr double kInfeasible = 1e30;
constexpr double kFailed = 1e300;

// Thrown through pagmo when the driver stops the run (budget, time, target, interrupt, error).
struct RunStopped {};

// The fitness of an infeasible point: ranked by its violation, behind every feasible one.
inline double infeasible_fitness(double violation) { return kInfeasible * (1.0 + std::min(violation, 1e250)); }

// The driver's scaled point of unit-box point u (n = d.n() values, clamped into [0, 1]).
inline std::vector<double> to_scaled(const EvaluationDriver& d, const double* u) {
  std::vector<double> y(d.n());
  for (std::size_t i = 0; i < d.n(); ++i)
    y[i] = d.lower_scaled()[i] + std::min(std::max(u[i], 0.0), 1.0) * (d.upper_scaled()[i] - d.lower_scaled()[i]);
  return y;
}

// pagmo's bounds of the unit box.
inline std::pair<std::vector<double>, std::vector<double>> unit_bounds(std::size_t n) {
  return {std::vector<double>(n, 0.0), std::vector<double>(n, 1.0)};
}

// The initial population, flat (size points of n values, one after another): x0 in the unit box,
// then size - 1 uniform points seeded by `seed` (evaluated as one batch by the callers).
inline std::vector<double> initial_population(const EvaluationDriver& d, const std::vector<double>& x0,
                                              std::size_t size, std::uint64_t seed) {
  const std::size_t n = d.n();
  std::vector<double> flat;
  flat.reserve(size * n);
  const std::vector<double> y0 = d.to_scaled(x0);
  for (std::size_t i = 0; i < n; ++i) {
    const double range = d.upper_scaled()[i] - d.lower_scaled()[i];
    flat.push_back(std::min(std::max((y0[i] - d.lower_scaled()[i]) / range, 0.0), 1.0));
  }
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  while (flat.size() < size * n) flat.push_back(uniform(rng));
  return flat;
}

// Generations: as many as evaluations (repeats of known points are answered from memory and do not
// count), so the budget or the algorithm's own tolerances end the run.
inline unsigned generations(long max_evaluations) {
  return static_cast<unsigned>(std::min<long>(max_evaluations, 100000000L));
}

}  // namespace abuopt::opt::detail::pagmo_common
