#include "abuopt/optimizer/benchmarks/rosenbrock.hpp"

#include "abuopt/common/config_error.hpp"

namespace abuopt::opt::benchmarks {

Rosenbrock::Rosenbrock(int dimension, double bound) : n_(dimension), bound_(bound) {
  if (dimension < 2 || dimension > 10)
    throw ConfigError("rosenbrock dimension", std::to_string(dimension), "must be in [2, 10]");
  if (!(bound > 1.0)) throw ConfigError("rosenbrock bound", opt::format_number(bound), "must be > 1");
}

std::string Rosenbrock::name() const { return "rosenbrock" + std::to_string(n_); }

std::vector<opt::Variable> Rosenbrock::variables() const {
  std::vector<opt::Variable> v;
  for (int i = 0; i < n_; ++i) {
    std::string name = "x";
    name += std::to_string(i + 1);  // (not "x" + ...: GCC 12 -Wrestrict false positive)
    v.push_back({name, -bound_, bound_, 1.0});
  }
  return v;
}

opt::Evaluation Rosenbrock::evaluate(const std::vector<double>& x) {
  opt::check_design_vector(variables(), x);
  opt::Evaluation e;
  double f = 0;
  for (int i = 0; i + 1 < n_; ++i) {
    const double a = x[i + 1] - x[i] * x[i];
    const double b = 1.0 - x[i];
    f += 100.0 * a * a + b * b;
  }
  e.objective = f;
  return e;
}

std::vector<double> Rosenbrock::gradient(const std::vector<double>& x) const {
  std::vector<double> g(n_, 0.0);
  for (int i = 0; i + 1 < n_; ++i) {
    const double a = x[i + 1] - x[i] * x[i];
    g[i] += -400.0 * a * x[i] - 2.0 * (1.0 - x[i]);
    g[i + 1] += 200.0 * a;
  }
  return g;
}

std::vector<double> Rosenbrock::initial_point() const {
  std::vector<double> x0(n_);
  for (int i = 0; i < n_; ++i) x0[i] = i % 2 == 0 ? -1.2 : 1.0;
  return x0;
}

std::optional<opt::BestKnown> Rosenbrock::best_known() const {
  return opt::BestKnown{std::vector<double>(n_, 1.0), 0.0};
}

}  // namespace abuopt::opt::benchmarks
