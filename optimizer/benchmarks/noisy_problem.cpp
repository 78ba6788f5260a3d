#include "abuopt/optimizer/benchmarks/noisy_problem.hpp"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "abuopt/common/config_error.hpp"

namespace abuopt::opt::benchmarks {

namespace {
std::uint64_t splitmix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// The noise of both forms: v + amplitude (1 + |v|) u(k) on the objective (k = 0), then the
// inequality and the equality constraints (k = 1, 2, ...); the objective's noise-free value is kept
// as the metric noise_free_objective.
template <class UnitNoise>
void add_relative_noise(opt::Evaluation& e, double amplitude, const UnitNoise& u) {
  auto noisy = [&](double v, std::uint64_t k) { return v + amplitude * (1.0 + std::fabs(v)) * u(k); };
  e.metrics["noise_free_objective"] = e.objective;
  e.objective = noisy(e.objective, 0);
  std::uint64_t k = 1;
  for (double& g : e.inequality) g = noisy(g, k++);
  for (double& h : e.equality) h = noisy(h, k++);
}
}  // namespace

NoisyProblem::NoisyProblem(std::unique_ptr<opt::Problem> inner, double amplitude, std::uint64_t seed,
                           std::size_t samples)
    : inner_(std::move(inner)), amplitude_(amplitude), seed_(seed), samples_(samples) {
  if (!(amplitude >= 0.0 && amplitude < 1.0))
    throw ConfigError("noise_amplitude", opt::format_number(amplitude), "must be in [0, 1)");
  if (samples > (std::size_t{1} << 24))
    throw ConfigError("noise_samples", std::to_string(samples), "must be in [0, 2^24] (0: not sampled)");
}

double NoisyProblem::unit_noise(const std::vector<double>& x, std::uint64_t seed, std::uint64_t k) {
  std::uint64_t h = splitmix64(seed ^ splitmix64(k + 0x1234567ULL));
  for (double xi : x) {
    std::uint64_t bits;
    std::memcpy(&bits, &xi, sizeof bits);
    h = splitmix64(h ^ bits);
  }
  return static_cast<double>(h >> 11) * 0x1.0p-52 - 1.0;  // [0, 2) - 1
}

opt::Evaluation NoisyProblem::evaluate(const std::vector<double>& x) {
  if (samples_ > 0) return evaluate_sampled(x, samples_);
  opt::Evaluation e = inner_->evaluate(x);
  if (!e.ok || amplitude_ == 0.0) return e;
  add_relative_noise(e, amplitude_, [&](std::uint64_t k) { return unit_noise(x, seed_, k); });
  return e;
}

opt::Evaluation NoisyProblem::evaluate_sampled(const std::vector<double>& x, std::size_t n, std::size_t) {
  if (samples_ == 0) return opt::Problem::evaluate_sampled(x, n);  // not sampled: n must be 0
  if (n < 1 || n > samples_)
    throw std::invalid_argument("NoisyProblem::evaluate_sampled: n = " + std::to_string(n) + " is outside [1, " +
                                std::to_string(samples_) + "]");
  opt::Evaluation e = inner_->evaluate(x);
  e.metrics["runs"] = static_cast<double>(n);
  if (!e.ok || amplitude_ == 0.0) return e;
  // the mean of the first n runs' noise (variance 1 each): run i of output k has its own stream
  auto mean_noise = [&](std::uint64_t k) {
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) sum += unit_noise(x, splitmix64(seed_ ^ splitmix64(0xC0FFEEULL + i)), k);
    return std::sqrt(3.0) * sum / static_cast<double>(n);
  };
  add_relative_noise(e, amplitude_, mean_noise);
  return e;
}

}  // namespace abuopt::opt::benchmarks
