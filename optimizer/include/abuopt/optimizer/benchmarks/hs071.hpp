#pragma once
// Hock & Schittkowski problem 71 (the Ipopt tutorial problem):
//   minimise   x1 x4 (x1 + x2 + x3) + x3
//   subject to x1 x2 x3 x4 >= 25                 (g: 25 - x1 x2 x3 x4 <= 0, "product")
//              x1^2 + x2^2 + x3^2 + x4^2 = 40     (h: ... - 40 = 0, "sum_of_squares")
//              1 <= x_i <= 5,   start (1, 5, 5, 1)
// Optimum f = 17.0140173 at (1, 4.7429996, 3.8211500, 1.3794083): both constraints and the
// lower bound of x1 active (checked by the KKT test in tests/problems).
#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt::benchmarks {

class Hs071 : public opt::Problem {
 public:
  std::string name() const override { return "hs071"; }
  std::vector<opt::Variable> variables() const override;
  std::vector<std::string> inequality_names() const override { return {"product"}; }
  std::vector<std::string> equality_names() const override { return {"sum_of_squares"}; }
  opt::Evaluation evaluate(const std::vector<double>& x) override;
  std::vector<double> initial_point() const override { return {1, 5, 5, 1}; }
  std::optional<opt::BestKnown> best_known() const override;
};

}  // namespace abuopt::opt::benchmarks
