#pragma once
// Benchmark problems by name: "rosenbrock", "hs071", "cantilever", "two_bar_truss", and
// "noisy_<name>" for each (see noisy_problem.hpp).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt::benchmarks {

struct BenchmarkSettings {
  int dimension = 2;              // Rosenbrock only (2..10); the others have a fixed size
  double noise_amplitude = 1e-3;  // noisy_* only: relative amplitude
  std::uint64_t noise_seed = 1;   // noisy_* only
  // noisy_* only: 0, the plain pseudo-noise; N > 0, the sampled form (a mean of N runs whose first
  // n an optimiser may take: noisy_problem.hpp; noise_amplitude is then one run's sd, relative)
  std::size_t noise_samples = 0;
};

std::vector<std::string> benchmark_names();
// Throws abuopt::ConfigError for an unknown name, listing the valid ones.
std::unique_ptr<opt::Problem> make_benchmark(const std::string& name, const BenchmarkSettings& settings = {});

}  // namespace abuopt::opt::benchmarks
