#include "abuopt/optimizer/benchmarks/noisy_problem.hpp"

#include <cmath>
#include <cstring>

#include "abuopt/common/config_error.hpp"

namespace abuopt::opt::benchmarks {

namespace {
std::uint64_t splitmix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
}  // namespace

NoisyProblem::NoisyProblem(std::unique_ptr<opt::Problem> inner, double amplitude, std::uint64_t seed)
    : inner_(std::move(inner)), amplitude_(amplitude), seed_(seed) {
  if (!(amplitude >= 0.0 && amplitude < 1.0))
    throw ConfigError("noise_amplitude", opt::format_number(amplitude), "must be in [0, 1)");
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
  opt::Evaluation e = inner_->evaluate(x);
  if (!e.ok || amplitude_ == 0.0) return e;
  auto noisy = [&](double v, std::uint64_t k) { return v + amplitude_ * (1.0 + std::fabs(v)) * unit_noise(x, seed_, k); };
  e.metrics["noise_free_objective"] = e.objective;
  e.objective = noisy(e.objective, 0);
  std::uint64_t k = 1;
  for (double& g : e.inequality) g = noisy(g, k++);
  for (double& h : e.equality) h = noisy(h, k++);
  return e;
}

}  // namespace abuopt::opt::benchmarks
