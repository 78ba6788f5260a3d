#pragma once
// A problem with deterministic pseudo-noise added to its objective and constraints, like a Monte
// Carlo estimate with common random numbers: the noise is a hash of the bits of x, the seed and
// the output index, so the same x always gives the same values.
//   f~(x) = f(x) + a (1 + |f(x)|) u_0(x),   g~_i = g_i + a (1 + |g_i|) u_{1+i}(x),  same for h,
// u_k(x) uniform in [-1, 1), a = relative amplitude. best_known() is the noise-free one.
#include <cstdint>
#include <memory>

#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt::benchmarks {

class NoisyProblem : public opt::Problem {
 public:
  // Throws abuopt::ConfigError unless 0 <= amplitude < 1.
  NoisyProblem(std::unique_ptr<opt::Problem> inner, double amplitude, std::uint64_t seed = 1);
  std::string name() const override { return "noisy_" + inner_->name(); }
  std::vector<opt::Variable> variables() const override { return inner_->variables(); }
  std::vector<std::string> inequality_names() const override { return inner_->inequality_names(); }
  std::vector<std::string> equality_names() const override { return inner_->equality_names(); }
  opt::Evaluation evaluate(const std::vector<double>& x) override;
  std::vector<double> initial_point() const override { return inner_->initial_point(); }
  std::optional<opt::BestKnown> best_known() const override { return inner_->best_known(); }

  double amplitude() const { return amplitude_; }
  // The noise factor u_k(x) in [-1, 1).
  static double unit_noise(const std::vector<double>& x, std::uint64_t seed, std::uint64_t k);

 private:
  std::unique_ptr<opt::Problem> inner_;
  double amplitude_;
  std::uint64_t seed_;
};

}  // namespace abuopt::opt::benchmarks
