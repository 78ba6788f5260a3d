#pragma once
// A problem with deterministic pseudo-noise added to its objective and constraints, like a Monte
// Carlo estimate with common random numbers: the noise is a hash of the bits of x, the seed and
// the output index, so the same x always gives the same values.
//   f~(x) = f(x) + a (1 + |f(x)|) u_0(x),   g~_i = g_i + a (1 + |g_i|) u_{1+i}(x),  same for h,
// u_k(x) uniform in [-1, 1), a = relative amplitude. best_known() is the noise-free one.
//
// Sampled form (samples = N > 0): a Monte Carlo mean of N runs, each run i with its own noise
// v_{k,i}(x) = sqrt(3) u_{k,i}(x) (mean 0, variance 1), and the value at sample size n the mean of
// the first n runs (common random numbers: the value at 2n shares its first n runs):
//   f~_n(x) = f(x) + a (1 + |f(x)|) (1/n) sum_{i<n} v_{0,i}(x),  likewise g and h,
// so the noise's standard deviation is a (1 + |f|) / sqrt(n). sample_size() = max_sample_size() = N;
// evaluate(x) is the value at N. The metric `runs` is n.
#include <cstddef>
#include <cstdint>
#include <memory>

#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt::benchmarks {

class NoisyProblem : public opt::Problem {
 public:
  // Throws abuopt::ConfigError unless 0 <= amplitude < 1.
  // samples 0: the plain form above; N > 0: the sampled form.
  NoisyProblem(std::unique_ptr<opt::Problem> inner, double amplitude, std::uint64_t seed = 1,
               std::size_t samples = 0);
  std::string name() const override { return "noisy_" + inner_->name(); }
  std::vector<opt::Variable> variables() const override { return inner_->variables(); }
  std::vector<std::string> inequality_names() const override { return inner_->inequality_names(); }
  std::vector<std::string> equality_names() const override { return inner_->equality_names(); }
  opt::Evaluation evaluate(const std::vector<double>& x) override;
  std::size_t sample_size() const override { return samples_; }
  std::size_t max_sample_size() const override { return samples_; }
  bool stochastic() const override { return amplitude_ > 0; }  // noise in every value
  opt::Evaluation evaluate_sampled(const std::vector<double>& x, std::size_t n, std::size_t concurrent = 1) override;
  std::vector<double> initial_point() const override { return inner_->initial_point(); }
  std::optional<opt::BestKnown> best_known() const override { return inner_->best_known(); }

  double amplitude() const { return amplitude_; }
  // The noise factor u_k(x) in [-1, 1).
  static double unit_noise(const std::vector<double>& x, std::uint64_t seed, std::uint64_t k);

 private:
  std::unique_ptr<opt::Problem> inner_;
  double amplitude_;
  std::uint64_t seed_;
  std::size_t samples_ = 0;
};

}  // namespace abuopt::opt::benchmarks
