// pagmo2 adapter: CMA-ES, xNES, self-adaptive DE and generational PSO of pagmo (Debian
// libpagmo-dev) on the same EvaluationDriver as every other method, so the budget, the archive
// (resume replays finished evaluations), the history and the best point are the driver's.
//
// pagmo searches the unit box u in [0, 1]^n; the driver's scaled point is y = lo + u (hi - lo).
// Constraints: Deb's feasibility rules encoded in one fitness value, which is all these
// rank-based methods compare (CMA-ES and xNES sort, DE and PSO compare pairs):
//   feasible (violation <= constraint_tolerance):  f(x)
//   infeasible:                                     kInfeasible * (1 + violation)
//   failed evaluation:                              kFailed
// so any feasible point beats any infeasible one, infeasible points are ranked by violation, and
// the objective decides among feasible ones (pagmo's cstrs_self_adaptive idea without its
// population-dependent penalty, which a resumed run could not replay point by point).
// The initial population (x0 and seeded uniform points) is one batch; PSO's generations go
// through pagmo's batch evaluator (pso_gen + member_bfe) and so through Problem::evaluate_batch.
// pagmo 2.18's CMA-ES, xNES and SADE evaluate one point at a time (no batch evaluator there).
#include <pagmo/algorithm.hpp>
#include <pagmo/algorithms/cmaes.hpp>
#include <pagmo/algorithms/pso_gen.hpp>
#include <pagmo/algorithms/sade.hpp>
#include <pagmo/algorithms/xnes.hpp>
#include <pagmo/batch_evaluators/member_bfe.hpp>
#include <pagmo/bfe.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "adapters.hpp"
#include "pagmo_common.hpp"

namespace abuopt::opt::detail {

namespace {

using namespace pagmo_common;

struct PagmoContext {
  EvaluationDriver* driver = nullptr;
  double constraint_tolerance = 0.0;
};

double fitness_value(const EvaluatedPoint& p, double tolerance) {
  if (!p.e.ok || !std::isfinite(p.e.objective)) return kFailed;
  if (p.violation > tolerance) return infeasible_fitness(p.violation);
  return p.e.objective;
}

// The user-defined problem pagmo sees: one objective, no constraints (they are in the fitness).
struct DriverUdp {
  PagmoContext* ctx = nullptr;
  std::size_t n = 0;

  pagmo::vector_double fitness(const pagmo::vector_double& u) const {
    const EvaluatedPoint* p = ctx->driver->evaluate(to_scaled(*ctx->driver, u.data()).data());
    if (!p) throw RunStopped{};
    return {fitness_value(*p, ctx->constraint_tolerance)};
  }
  // pagmo's member_bfe: the decision vectors one after another in `dvs` -> the fitness vectors.
  pagmo::vector_double batch_fitness(const pagmo::vector_double& dvs) const {
    const std::size_t k = dvs.size() / n;
    std::vector<std::vector<double>> ys;
    ys.reserve(k);
    for (std::size_t i = 0; i < k; ++i) ys.push_back(to_scaled(*ctx->driver, dvs.data() + i * n));
    const std::vector<const EvaluatedPoint*> ps = ctx->driver->evaluate_batch(ys);
    pagmo::vector_double f(k);
    for (std::size_t i = 0; i < k; ++i) {
      if (!ps[i]) throw RunStopped{};
      f[i] = fitness_value(*ps[i], ctx->constraint_tolerance);
    }
    return f;
  }
  std::pair<pagmo::vector_double, pagmo::vector_double> get_bounds() const { return unit_bounds(n); }
  std::string get_name() const { return "abuopt problem"; }
};

unsigned seed32(unsigned long seed) { return static_cast<unsigned>(seed & 0xffffffffUL); }

double sigma0(const OptimizerOptions& o) { return o.initial_step > 0 ? std::min(o.initial_step, 1.0) : 0.3; }

pagmo::algorithm make_algorithm(const std::string& name, const OptimizerOptions& o, unsigned generations) {
  const unsigned s = seed32(o.seed);
  const double xtol = o.xtol_rel > 0 ? o.xtol_rel : 1e-6;
  const double ftol = o.ftol_abs > 0 ? o.ftol_abs : 1e-8;
  if (name == "PAGMO_CMAES")
    return pagmo::algorithm(pagmo::cmaes(generations, -1, -1, -1, -1, sigma0(o), ftol, xtol, false, true, s));
  if (name == "PAGMO_XNES")
    return pagmo::algorithm(pagmo::xnes(generations, -1, -1, -1, sigma0(o), ftol, xtol, false, true, s));
  if (name == "PAGMO_SADE") return pagmo::algorithm(pagmo::sade(generations, 2u, 1u, ftol, xtol, false, s));
  if (name == "PAGMO_PSO") {
    pagmo::pso_gen pso(generations, 0.7298, 2.05, 2.05, 0.5, 5u, 2u, 4u, false, s);
    pso.set_bfe(pagmo::bfe(pagmo::member_bfe{}));
    return pagmo::algorithm(std::move(pso));
  }
  throw std::logic_error("no pagmo algorithm for " + name);
}

// Smallest population pagmo accepts for each algorithm.
std::size_t min_population(const std::string& name) { return name == "PAGMO_SADE" ? 7 : name == "PAGMO_PSO" ? 2 : 5; }

}  // namespace

bool is_pagmo_algorithm(const std::string& name) { return name.rfind("PAGMO_", 0) == 0; }

std::size_t pagmo_population(const std::string& name, std::size_t n, long requested) {
  if (requested > 0) return static_cast<std::size_t>(requested);
  // CMA-ES's rule 4 + 3 ln n, at least 8 so that DE and PSO have a population to work with
  const auto rule = static_cast<std::size_t>(4.0 + std::floor(3.0 * std::log(static_cast<double>(std::max<std::size_t>(n, 1)))));
  return std::max({rule, std::size_t{8}, min_population(name)});
}

void check_pagmo(const std::string& name, std::size_t n, const OptimizerOptions& options) {
  if (options.population > 0 && static_cast<std::size_t>(options.population) < min_population(name))
    throw ConfigError("optimizer.population", std::to_string(options.population),
                      name + " needs a population of at least " + std::to_string(min_population(name)));
  if (pagmo_population(name, n, options.population) > static_cast<std::size_t>(options.max_evaluations))
    throw ConfigError("optimizer.max_evaluations", std::to_string(options.max_evaluations),
                      name + " needs at least one population (" +
                          std::to_string(pagmo_population(name, n, options.population)) + " evaluations)");
}

AdapterOutcome run_pagmo(EvaluationDriver& d, const AlgorithmInfo& algorithm, const OptimizerOptions& options,
                         const std::vector<double>& x0) {
  const std::size_t n = d.n();
  const std::size_t size = pagmo_population(algorithm.name, n, options.population);
  PagmoContext ctx{&d, options.constraint_tolerance};
  pagmo::problem prob{DriverUdp{&ctx, n}};
  AdapterOutcome out;
  out.algorithm_label = algorithm.name;

  try {
    // the initial population: x0 and size - 1 seeded uniform points of the unit box, one batch
    const std::vector<double> flat = initial_population(d, x0, size, options.seed);
    const pagmo::vector_double f = prob.extract<DriverUdp>()->batch_fitness(flat);
    pagmo::population pop(prob, 0u, seed32(options.seed) + 1u);
    for (std::size_t i = 0; i < size; ++i)
      pop.push_back(pagmo::vector_double(flat.begin() + static_cast<long>(i * n), flat.begin() + static_cast<long>((i + 1) * n)),
                    {f[i]});
    const unsigned generations = pagmo_common::generations(options.max_evaluations);
    pagmo::algorithm algo = make_algorithm(algorithm.name, options, generations);
    algo.evolve(pop);
    out.reason = TerminationReason::Converged;
    out.message = "pagmo: " + algo.get_name() + " met its own tolerances (xtol " +
                  format_number(options.xtol_rel) + ") or ran its generations";
  } catch (const RunStopped&) {
    out.reason = TerminationReason::MaxEvaluations;  // the driver's own stop reason replaces it
    out.message = "stopped by the evaluation driver";
  }
  return out;
}

}  // namespace abuopt::opt::detail
