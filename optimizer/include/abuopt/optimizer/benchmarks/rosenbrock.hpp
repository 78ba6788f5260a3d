#pragma once
// Generalised Rosenbrock function (box-constrained, smooth, a curved narrow valley):
//   f(x) = sum_{i=0}^{n-2} [ 100 (x_{i+1} - x_i^2)^2 + (1 - x_i)^2 ],  n = 2..10
// Global minimum f = 0 at x = (1, ..., 1). For n >= 4 there is also a local minimum near
// x = (-1, 1, ..., 1). Bounds [-bound, bound] (default 2); start (-1.2, 1, -1.2, 1, ...).
#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt::benchmarks {

class Rosenbrock : public opt::Problem {
 public:
  // Throws abuopt::ConfigError unless 2 <= dimension <= 10 and bound > 1.
  explicit Rosenbrock(int dimension = 2, double bound = 2.0);
  std::string name() const override;
  std::vector<opt::Variable> variables() const override;
  opt::Evaluation evaluate(const std::vector<double>& x) override;
  std::vector<double> initial_point() const override;
  std::optional<opt::BestKnown> best_known() const override;
  // Exact gradient (for tests of the finite differences).
  std::vector<double> gradient(const std::vector<double>& x) const;

 private:
  int n_;
  double bound_;
};

}  // namespace abuopt::opt::benchmarks
