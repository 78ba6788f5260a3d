#include "abuopt/optimizer/benchmarks/hs071.hpp"

namespace abuopt::opt::benchmarks {

std::vector<opt::Variable> Hs071::variables() const {
  return {{"x1", 1, 5, 1}, {"x2", 1, 5, 1}, {"x3", 1, 5, 1}, {"x4", 1, 5, 1}};
}

opt::Evaluation Hs071::evaluate(const std::vector<double>& x) {
  opt::check_design_vector(variables(), x);
  opt::Evaluation e;
  e.objective = x[0] * x[3] * (x[0] + x[1] + x[2]) + x[2];
  const double product = x[0] * x[1] * x[2] * x[3];
  e.inequality = {25.0 - product};
  e.equality = {x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3] - 40.0};
  e.metrics["product"] = product;
  return e;
}

std::optional<opt::BestKnown> Hs071::best_known() const {
  // The KKT point with x1 = 1 on its bound and both constraints active, solved by Newton's method
  // on the 5 stationarity/feasibility equations (multipliers: product 0.5523, sum of squares
  // -0.1615, bound 1.0879); checked again in tests/problems/benchmarks_test.cpp.
  return opt::BestKnown{{1.0, 4.742999637264417, 3.821149984184874, 1.3794082931726723}, 17.014017289156303};
}

}  // namespace abuopt::opt::benchmarks
