#include "abuopt/optimizer/benchmarks/two_bar_truss.hpp"

#include <cmath>

namespace abuopt::opt::benchmarks {

std::vector<opt::Variable> TwoBarTruss::variables() const {
  return {{"area", 0.2, 4.0, 1.0}, {"span_ratio", 0.1, 1.6, 0.5}};
}

opt::Evaluation TwoBarTruss::evaluate(const std::vector<double>& x) {
  opt::check_design_vector(variables(), x);
  const double r = std::sqrt(1.0 + x[1] * x[1]);
  opt::Evaluation e;
  e.objective = x[0] * r;
  e.inequality = {0.124 * r * (8.0 / x[0] + 1.0 / (x[0] * x[1])) - 1.0,
                  0.124 * r * (8.0 / x[0] - 1.0 / (x[0] * x[1])) - 1.0};
  return e;
}

std::optional<opt::BestKnown> TwoBarTruss::best_known() const {
  // x2: the root of 16 x2^3 + x2^2 - 1 = 0 (Newton from 0.4), then x1 from the active stress_1.
  double x2 = 0.4;
  for (int i = 0; i < 50; ++i) x2 -= (16 * x2 * x2 * x2 + x2 * x2 - 1) / (48 * x2 * x2 + 2 * x2);
  const double r = std::sqrt(1.0 + x2 * x2);
  const double x1 = 0.124 * r * (8.0 + 1.0 / x2);
  return opt::BestKnown{{x1, x2}, x1 * r};
}

}  // namespace abuopt::opt::benchmarks
