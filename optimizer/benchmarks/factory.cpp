#include "abuopt/optimizer/benchmarks/benchmark_factory.hpp"

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/benchmarks/cantilever.hpp"
#include "abuopt/optimizer/benchmarks/hs071.hpp"
#include "abuopt/optimizer/benchmarks/noisy_problem.hpp"
#include "abuopt/optimizer/benchmarks/rosenbrock.hpp"
#include "abuopt/optimizer/benchmarks/two_bar_truss.hpp"

namespace abuopt::opt::benchmarks {

namespace {
const std::vector<std::string> kBase = {"rosenbrock", "hs071", "cantilever", "two_bar_truss"};

std::unique_ptr<opt::Problem> make_base(const std::string& name, const BenchmarkSettings& s) {
  if (name == "rosenbrock") return std::make_unique<Rosenbrock>(s.dimension);
  if (name == "hs071") return std::make_unique<Hs071>();
  if (name == "cantilever") return std::make_unique<Cantilever>();
  if (name == "two_bar_truss") return std::make_unique<TwoBarTruss>();
  return nullptr;
}
}  // namespace

std::vector<std::string> benchmark_names() {
  std::vector<std::string> names = kBase;
  for (const auto& b : kBase) names.push_back("noisy_" + b);
  return names;
}

std::unique_ptr<opt::Problem> make_benchmark(const std::string& name, const BenchmarkSettings& settings) {
  const std::string prefix = "noisy_";
  const bool noisy = name.rfind(prefix, 0) == 0;
  std::unique_ptr<opt::Problem> base = make_base(noisy ? name.substr(prefix.size()) : name, settings);
  if (!base) {
    std::string valid;
    for (const auto& n : benchmark_names()) valid += (valid.empty() ? "" : ", ") + n;
    throw ConfigError("benchmark", name, "unknown benchmark problem; valid: " + valid);
  }
  if (!noisy) return base;
  return std::make_unique<NoisyProblem>(std::move(base), settings.noise_amplitude, settings.noise_seed,
                                        settings.noise_samples);
}

}  // namespace abuopt::opt::benchmarks
