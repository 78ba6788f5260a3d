#include "abuopt/optimizer/algorithms.hpp"

#include <algorithm>
#include <cctype>

#include "abuopt/common/config_error.hpp"

namespace abuopt::opt {

const std::vector<AlgorithmInfo>& algorithms() {
  using F = AlgorithmFamily;
  static const std::vector<AlgorithmInfo> list = {
      {"COBYLA", F::local_derivative_free, true, true, false,
       "linear models from simplex; constraints of both kinds; robust default for few variables"},
      {"BOBYQA", F::local_derivative_free, false, false, false,
       "quadratic models in a trust region; bounds only (wrapped in AUGLAG for constraints); fast on smooth problems"},
      {"NEWUOA_BOUND", F::local_derivative_free, false, false, false,
       "quadratic models (NEWUOA with bounds); bounds only (wrapped in AUGLAG for constraints)"},
      {"SBPLX", F::local_derivative_free, false, false, false,
       "Nelder-Mead on subspaces (Subplex); bounds only; tolerant of mild noise"},
      {"NELDERMEAD", F::local_derivative_free, false, false, false,
       "simplex method; bounds only; tolerant of noise, slow in many variables"},
      {"PRAXIS", F::local_derivative_free, false, false, false,
       "Brent's principal-axis method; bounds only (NLopt rejects points outside them); smooth problems"},
      {"DIRECT_L", F::global, false, false, false,
       "deterministic box subdivision (locally biased DIRECT); bounds only; a small box and many evaluations"},
      {"CRS2_LM", F::global, false, false, false,
       "controlled random search with local mutation; bounds only; seeded"},
      {"ISRES", F::global, true, true, false,
       "evolution strategy with stochastic ranking; constraints of both kinds; seeded, needs many evaluations"},
      {"ESCH", F::global, false, false, false, "evolutionary algorithm; bounds only; seeded"},
      {"MLSL_LDS", F::global, false, false, true,
       "multi-level single linkage: local searches (local_algorithm) from low-discrepancy starts; bounds only"},
      {"AUGLAG", F::meta, true, true, true,
       "augmented Lagrangian: constraints moved into the objective, solved by local_algorithm"},
      {"MMA", F::local_gradient, true, false, false,
       "Svanberg's method of moving asymptotes; inequality constraints; finite-difference gradients"},
      {"CCSAQ", F::local_gradient, true, false, false,
       "conservative convex separable quadratic approximations (MMA family); inequality constraints"},
      {"SLSQP", F::local_gradient, true, true, false,
       "sequential quadratic programming; constraints of both kinds; finite-difference gradients"},
      {"LBFGS", F::local_gradient, false, false, false,
       "limited-memory BFGS; bounds only; finite-difference gradients"},
      {"IPOPT", F::local_gradient, true, true, false,
       "interior-point method (Ipopt) with limited-memory Hessian; constraints of both kinds; "
       "finite-difference gradients and Jacobian"},
      {"SAO", F::local_derivative_free, true, true, false,
       "sequential approximate optimisation: least-squares response surfaces in a trust region; constraints "
       "of both kinds; for expensive, noisy problems (options in the sao: section)"},
  };
  return list;
}

std::vector<std::string> algorithm_names() {
  std::vector<std::string> names;
  for (const auto& a : algorithms()) names.push_back(a.name);
  return names;
}

const AlgorithmInfo& find_algorithm(const std::string& name, const std::string& what) {
  std::string upper = name;
  std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return std::toupper(c); });
  for (const auto& a : algorithms())
    if (a.name == upper) return a;
  std::string valid;
  for (const auto& a : algorithms()) valid += (valid.empty() ? "" : ", ") + a.name;
  throw ConfigError(what, name.empty() ? "\"\"" : name, "unknown algorithm; valid (case-insensitive): " + valid);
}

std::string to_string(AlgorithmFamily family) {
  switch (family) {
    case AlgorithmFamily::local_derivative_free: return "local, derivative-free";
    case AlgorithmFamily::local_gradient: return "local, gradient-based (finite differences)";
    case AlgorithmFamily::global: return "global";
    case AlgorithmFamily::meta: return "meta (uses a local algorithm)";
  }
  return "?";
}

}  // namespace abuopt::opt
