#include "abuopt/optimizer/algorithms.hpp"

#include <algorithm>
#include <cctype>

#include "abuopt/common/config_error.hpp"

namespace abuopt::opt {

const std::vector<AlgorithmInfo>& algorithms() {
  using F = AlgorithmFamily;
  static const std::vector<AlgorithmInfo> list = {
      {"COBYLA", F::LocalDerivativeFree, true, true, false,
       "linear models from simplex; constraints of both kinds; robust default for few variables"},
      {"BOBYQA", F::LocalDerivativeFree, false, false, false,
       "quadratic models in a trust region; bounds only (wrapped in AUGLAG for constraints); fast on smooth problems"},
      {"NEWUOA_BOUND", F::LocalDerivativeFree, false, false, false,
       "quadratic models (NEWUOA with bounds); bounds only (wrapped in AUGLAG for constraints)"},
      {"SBPLX", F::LocalDerivativeFree, false, false, false,
       "Nelder-Mead on subspaces (Subplex); bounds only; tolerant of mild noise"},
      {"NELDERMEAD", F::LocalDerivativeFree, false, false, false,
       "simplex method; bounds only; tolerant of noise, slow in many variables"},
      {"PRAXIS", F::LocalDerivativeFree, false, false, false,
       "Brent's principal-axis method; bounds only (NLopt rejects points outside them); smooth problems"},
      {"DIRECT_L", F::Global, false, false, false,
       "deterministic box subdivision (locally biased DIRECT); bounds only; a small box and many evaluations"},
      {"CRS2_LM", F::Global, false, false, false,
       "controlled random search with local mutation; bounds only; seeded"},
      {"ISRES", F::Global, true, true, false,
       "evolution strategy with stochastic ranking; constraints of both kinds; seeded, needs many evaluations"},
      {"ESCH", F::Global, false, false, false, "evolutionary algorithm; bounds only; seeded"},
      {"MLSL_LDS", F::Global, false, false, true,
       "multi-level single linkage: local searches (local_algorithm) from low-discrepancy starts; bounds only"},
      {"AUGLAG", F::Meta, true, true, true,
       "augmented Lagrangian: constraints moved into the objective, solved by local_algorithm"},
      {"MMA", F::LocalGradient, true, false, false,
       "Svanberg's method of moving asymptotes; inequality constraints; finite-difference gradients"},
      {"CCSAQ", F::LocalGradient, true, false, false,
       "conservative convex separable quadratic approximations (MMA family); inequality constraints"},
      {"SLSQP", F::LocalGradient, true, true, false,
       "sequential quadratic programming; constraints of both kinds; finite-difference gradients"},
      {"LBFGS", F::LocalGradient, false, false, false,
       "limited-memory BFGS; bounds only; finite-difference gradients"},
      {"IPOPT", F::LocalGradient, true, true, false,
       "interior-point method (Ipopt) with limited-memory Hessian; constraints of both kinds; "
       "finite-difference gradients and Jacobian"},
      {"SAO", F::LocalDerivativeFree, true, true, false,
       "sequential approximate optimisation: least-squares response surfaces in a trust region; constraints "
       "of both kinds; for expensive, noisy problems (options in the sao: section)"},
      {"PAGMO_CMAES", F::Global, true, true, false,
       "pagmo2's CMA-ES (covariance matrix adaptation evolution strategy); constraints by feasibility rules; "
       "seeded, population optimizer.population (default max(8, 4 + 3 ln n))"},
      {"PAGMO_XNES", F::Global, true, true, false,
       "pagmo2's exponential natural evolution strategy; constraints by feasibility rules; seeded"},
      {"PAGMO_SADE", F::Global, true, true, false,
       "pagmo2's self-adaptive differential evolution (jDE, rand/1/exp); constraints by feasibility rules; seeded"},
      {"PAGMO_PSO", F::Global, true, true, false,
       "pagmo2's generational particle swarm; every generation one batch of evaluations; constraints by "
       "feasibility rules; seeded"},
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
    case AlgorithmFamily::LocalDerivativeFree: return "local, derivative-free";
    case AlgorithmFamily::LocalGradient: return "local, gradient-based (finite differences)";
    case AlgorithmFamily::Global: return "global";
    case AlgorithmFamily::Meta: return "meta (uses a local algorithm)";
  }
  return "?";
}

}  // namespace abuopt::opt
