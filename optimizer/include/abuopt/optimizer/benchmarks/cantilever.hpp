#pragma once
// Svanberg's cantilever beam (MMA paper, 1987): five hollow square segments of widths x1..x5,
//   minimise   0.0624 (x1 + x2 + x3 + x4 + x5)                           (weight)
//   subject to 61/x1^3 + 37/x2^3 + 19/x3^3 + 7/x4^3 + 1/x5^3 - 1 <= 0     ("tip_deflection")
//              1 <= x_i <= 10,   start x_i = 5
// Closed-form optimum (Lagrange: x_i proportional to a_i^(1/4), the constraint active):
//   S = sum a_i^(1/4) = 9.975382..., x_i = S^(1/3) a_i^(1/4), f = 0.0624 S^(4/3) = 1.3399564
//   x = (6.016016, 5.309174, 4.494330, 3.501475, 2.152665).
#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt::benchmarks {

class Cantilever : public opt::Problem {
 public:
  std::string name() const override { return "cantilever"; }
  std::vector<opt::Variable> variables() const override;
  std::vector<std::string> inequality_names() const override { return {"tip_deflection"}; }
  opt::Evaluation evaluate(const std::vector<double>& x) override;
  std::vector<double> initial_point() const override { return std::vector<double>(5, 5.0); }
  std::optional<opt::BestKnown> best_known() const override;
};

}  // namespace abuopt::opt::benchmarks
