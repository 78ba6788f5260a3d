#pragma once
// Svanberg's two-bar truss (x1: cross-section area, x2: half-span over height):
//   minimise   x1 sqrt(1 + x2^2)                                        (weight)
//   subject to 0.124 sqrt(1 + x2^2) (8/x1 + 1/(x1 x2)) - 1 <= 0          ("stress_1")
//              0.124 sqrt(1 + x2^2) (8/x1 - 1/(x1 x2)) - 1 <= 0          ("stress_2")
//              0.2 <= x1 <= 4,  0.1 <= x2 <= 1.6,   start (1.5, 0.5)
// With stress_1 active, x1 = 0.124 sqrt(1+x2^2)(8 + 1/x2) and f = 0.124 (1+x2^2)(8 + 1/x2),
// whose minimum is at the root of 16 x2^3 + x2^2 - 1 = 0:
//   x = (1.4116311, 0.3770724), f = 1.5086524 (stress_2 = -0.498, inactive).
#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt::benchmarks {

class TwoBarTruss : public opt::Problem {
 public:
  std::string name() const override { return "two_bar_truss"; }
  std::vector<opt::Variable> variables() const override;
  std::vector<std::string> inequality_names() const override { return {"stress_1", "stress_2"}; }
  opt::Evaluation evaluate(const std::vector<double>& x) override;
  std::vector<double> initial_point() const override { return {1.5, 0.5}; }
  std::optional<opt::BestKnown> best_known() const override;
};

}  // namespace abuopt::opt::benchmarks
