#pragma once
// Designs of initial ball angles: points on the N-torus [0, 2 pi)^N, one point per Monte Carlo run.
//
// A design is a pure function of (kind, size, number of balls, seed): the same points are reused
// for every startup profile a study compares (common random numbers), and they do not depend on
// the thread count or on anything else. Random numbers are portable: a std::mt19937_64 (its output
// is fixed by the C++ standard) seeded through splitmix64, with our own integer->double conversion
// (53 bits) and bounded integers (rejection), never the implementation-defined std distributions.
//
// Kinds (docs/montecarlo.md has the details):
//   Grid:   the report's n x n grid, generalised to n^N points: beta_j = 2 pi k_j / n,
//           k_j = 0..n-1. Point index i = sum_j k_j n^(N-1-j): the LAST ball varies fastest
//           (row-major, like an array beta[k_1][k_2]). Includes beta = 0 (ball at the imbalance).
//   Random: independent uniform points; point i comes from its own stream hash(seed, i), so the
//           first m points of a larger design equal the m points of a smaller one.
//   LatinHypercube: on each axis the count strata [2 pi s/count, 2 pi (s+1)/count) hold exactly
//           one point; independent random permutation per axis and a uniform jitter inside the
//           stratum (all from the seed).
//   Halton: radical inverses in the first N prime bases, point i = index i (starts with 0).
//   Sobol:  base-2 Sobol' sequence (Joe-Kuo direction numbers, up to 10 balls), point i = index i
//           (starts with 0), Gray-code order.
//   Halton and Sobol take a Cranley-Patterson random shift by default: every coordinate is
//   u -> frac(u + s_j) with s_j uniform from the seed (random_shift = true). That keeps the
//   low-discrepancy structure, makes the seed meaningful and moves the degenerate point 0 (all
//   balls on the imbalance). random_shift = false gives the plain sequence (the seed is unused).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace abuopt {

enum class InitialConditionKind { Grid, Random, LatinHypercube, Halton, Sobol };

// "grid", "random", "lhs", "halton", "sobol".
std::string to_string(InitialConditionKind k);
// Inverse of to_string; throws ConfigError("<path> = <text>: must be one of: ...").
InitialConditionKind initial_condition_kind_from_string(const std::string& text,
                                                        const std::string& path = "montecarlo.design");

struct InitialConditionDesign {
  InitialConditionKind kind = InitialConditionKind::Grid;
  std::size_t balls = 2;                  // N: dimension of the torus
  std::size_t grid_points_per_axis = 32;  // Grid: n (the design has n^N points)
  std::size_t count = 1024;               // other kinds: number of points (Grid ignores it)
  std::uint64_t seed = 0;                 // Random, LatinHypercube, shifted Halton/Sobol
  bool random_shift = true;               // Halton/Sobol: Cranley-Patterson shift from the seed

  // Number of points: n^N for the grid, count otherwise.
  std::size_t size() const;
};

// Largest number of balls the Sobol design supports (direction numbers shipped).
inline constexpr std::size_t kSobolMaxDimension = 10;
// Upper bound on the number of points of any design (guards n^N against overflow and typos).
inline constexpr std::size_t kMaxDesignPoints = std::size_t{1} << 32;

// Throws ConfigError (keys below `path`, e.g. "montecarlo.grid = 0: must be >= 1") when the design
// is empty, too large, or has no balls.
void validate(const InitialConditionDesign& d, const std::string& path = "montecarlo");

// All points, each of size N with values in [0, 2 pi). Validates first.
std::vector<std::vector<double>> generate_initial_conditions(const InitialConditionDesign& d);

// Point `index` alone (index < d.size()); equal to generate_initial_conditions(d)[index].
// O(N) for grid/random/Halton/Sobol; O(count N) for the Latin hypercube.
std::vector<double> initial_condition_at(const InitialConditionDesign& d, std::size_t index);

// Point `index` of the plain (unshifted) Sobol' sequence in [0, 1)^dims, dims <= kSobolMaxDimension
// (std::invalid_argument otherwise): the same numbers as the Sobol design before scaling to angles.
// Used for designs in other boxes (studies/sweep).
std::vector<double> sobol_unit_point(std::uint64_t index, std::size_t dims);

// --- Portable randomness shared by the Monte Carlo code -------------------------------------
// splitmix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mixer.
std::uint64_t splitmix64(std::uint64_t x);
// Hash of (seed, a, b) into a 64-bit stream seed; distinct inputs give unrelated outputs.
std::uint64_t hash_seed(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0);
// Uniform double in [0, 1) from the top 53 bits of x.
double unit_double(std::uint64_t x);

}  // namespace abuopt
