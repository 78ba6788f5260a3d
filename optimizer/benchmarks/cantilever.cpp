#include "abuopt/optimizer/benchmarks/cantilever.hpp"

#include <cmath>

namespace abuopt::opt::benchmarks {

namespace {
constexpr double kWeight = 0.0624;
constexpr double kA[5] = {61.0, 37.0, 19.0, 7.0, 1.0};
}  // namespace

std::vector<opt::Variable> Cantilever::variables() const {
  std::vector<opt::Variable> v;
  for (int i = 0; i < 5; ++i) {
    std::string name = "x";
    name += std::to_string(i + 1);  // (not "x" + ...: GCC 12 -Wrestrict false positive)
    v.push_back({name, 1.0, 10.0, 5.0});
  }
  return v;
}

opt::Evaluation Cantilever::evaluate(const std::vector<double>& x) {
  opt::check_design_vector(variables(), x);
  opt::Evaluation e;
  double sum = 0, deflection = 0;
  for (int i = 0; i < 5; ++i) {
    sum += x[i];
    deflection += kA[i] / (x[i] * x[i] * x[i]);
  }
  e.objective = kWeight * sum;
  e.inequality = {deflection - 1.0};
  e.metrics["deflection"] = deflection;
  return e;
}

std::optional<opt::BestKnown> Cantilever::best_known() const {
  // Closed form (see the header): x_i = S^(1/3) a_i^(1/4), f = 0.0624 S^(4/3).
  double s = 0;
  for (double a : kA) s += std::pow(a, 0.25);
  opt::BestKnown best;
  for (double a : kA) best.x.push_back(std::cbrt(s) * std::pow(a, 0.25));
  best.objective = kWeight * s * std::cbrt(s);
  return best;
}

}  // namespace abuopt::opt::benchmarks
