// NSGA-II and MOEA/D of pagmo2 on two objectives (multi_objective.hpp): the problem's objective and
// one metric.
#include <pagmo/algorithm.hpp>
#include <pagmo/algorithms/moead.hpp>
#include <pagmo/algorithms/nsga2.hpp>
#include <pagmo/batch_evaluators/member_bfe.hpp>
#include <pagmo/bfe.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/multi_objective.hpp"
#include "evaluation_driver.hpp"
#include "pagmo_common.hpp"

namespace abuopt::opt {

namespace {

using namespace detail::pagmo_common;

struct Context {
  detail::EvaluationDriver* driver = nullptr;
  std::string metric;
  double tolerance = 0.0;
};

std::pair<double, double> objectives(const detail::EvaluatedPoint& p, const Context& c) {
  const auto m = p.e.metrics.find(c.metric);
  if (!p.e.ok || !std::isfinite(p.e.objective) || m == p.e.metrics.end() || !std::isfinite(m->second))
    return {kFailed, kFailed};
  if (p.violation > c.tolerance) return {infeasible_fitness(p.violation), infeasible_fitness(p.violation)};
  return {p.e.objective, m->second};
}

struct TwoObjectiveUdp {
  Context* ctx = nullptr;
  std::size_t n = 0;
  pagmo::vector_double fitness(const pagmo::vector_double& u) const { return batch_fitness(u); }
  pagmo::vector_double batch_fitness(const pagmo::vector_double& dvs) const {
    const std::size_t k = dvs.size() / n;
    std::vector<std::vector<double>> ys;
    for (std::size_t i = 0; i < k; ++i) ys.push_back(to_scaled(*ctx->driver, dvs.data() + i * n));
    const auto ps = ctx->driver->evaluate_batch(ys);
    pagmo::vector_double f;
    for (const auto* p : ps) {
      if (!p) throw RunStopped{};
      const auto o = objectives(*p, *ctx);
      f.push_back(o.first);
      f.push_back(o.second);
    }
    return f;
  }
  pagmo::vector_double::size_type get_nobj() const { return 2; }
  std::pair<pagmo::vector_double, pagmo::vector_double> get_bounds() const { return unit_bounds(n); }
};

}  // namespace

std::vector<std::pair<double, double>> TwoObjectiveResult::front_objectives() const {
  std::vector<std::pair<double, double>> out;
  for (std::size_t i : front) {
    const EvaluationRecord& h = run.history[i];
    out.emplace_back(h.objective, h.metrics.at(second_objective));
  }
  return out;
}

std::vector<std::pair<double, double>> non_dominated_2d(std::vector<std::pair<double, double>> points) {
  std::sort(points.begin(), points.end());
  std::vector<std::pair<double, double>> front;
  for (const auto& p : points)
    if (front.empty() || p.second < front.back().second) front.push_back(p);  // sorted: same first, larger second
  return front;
}

double hypervolume_2d(const std::vector<std::pair<double, double>>& points, std::pair<double, double> reference) {
  double area = 0.0, last_y = reference.second;
  for (const auto& p : non_dominated_2d(points)) {
    if (!(p.first < reference.first) || !(p.second < last_y)) continue;
    area += (reference.first - p.first) * (last_y - p.second);
    last_y = p.second;
  }
  return area;
}

std::string to_string(TwoObjectiveMethod m) { return m == TwoObjectiveMethod::Moead ? "pagmo_moead" : "pagmo_nsga2"; }

TwoObjectiveMethod two_objective_method_from_string(const std::string& text, const std::string& key) {
  if (text == "pagmo_nsga2" || text == "nsga2") return TwoObjectiveMethod::Nsga2;
  if (text == "pagmo_moead" || text == "moead") return TwoObjectiveMethod::Moead;
  throw ConfigError(key, text, "a two-objective pagmo method is pagmo_nsga2 or pagmo_moead");
}

void check_two_objective_population(TwoObjectiveMethod method, long population, long max_evaluations,
                                    const std::string& population_key, const std::string& budget_key) {
  const long size = population > 0 ? population : 20;
  if (method == TwoObjectiveMethod::Nsga2 && (size < 8 || size % 4 != 0))
    throw ConfigError(population_key, std::to_string(size), "NSGA-II needs a multiple of 4, at least 8");
  if (method == TwoObjectiveMethod::Moead && size < 4)
    throw ConfigError(population_key, std::to_string(size),
                      "MOEA/D needs at least 4 (one weight vector per member, neighbourhoods of >= 2)");
  if (max_evaluations < size)
    throw ConfigError(budget_key, std::to_string(max_evaluations),
                      std::string(method == TwoObjectiveMethod::Moead ? "MOEA/D" : "NSGA-II") +
                          " needs at least one population (" + std::to_string(size) + " evaluations)");
}

TwoObjectiveResult minimize_two_objectives(Problem& problem, const std::string& second_objective,
                                           const OptimizerOptions& options, std::vector<double> x0,
                                           TwoObjectiveMethod method, const EvaluationCallback& callback) {
  options.validate();
  check_problem(problem);
  if (second_objective.empty())
    throw ConfigError("second_objective", "\"\"", "must name a metric of the problem's evaluations");
  const long size = options.population > 0 ? options.population : 20;
  check_two_objective_population(method, size, options.max_evaluations, "optimizer.population",
                                 "optimizer.max_evaluations");
  if (x0.empty()) x0 = problem.initial_point();
  check_design_vector(problem, x0, "starting point");

  detail::SigintGuard sigint(options.handle_sigint);
  detail::interrupt_flag().store(false);
  detail::EvaluationDriver driver(problem, options, callback);
  const std::size_t n = driver.n();
  Context ctx{&driver, second_objective, options.constraint_tolerance};
  TwoObjectiveResult out;
  out.second_objective = second_objective;
  TerminationReason reason = TerminationReason::Converged;
  const bool moead = method == TwoObjectiveMethod::Moead;
  std::string message = moead ? "pagmo: MOEA/D ran its generations" : "pagmo: NSGA-II ran its generations";
  try {
    pagmo::problem prob{TwoObjectiveUdp{&ctx, n}};
    const std::vector<double> flat = initial_population(driver, x0, static_cast<std::size_t>(size), options.seed);
    const pagmo::vector_double f = prob.extract<TwoObjectiveUdp>()->batch_fitness(flat);
    pagmo::population pop(prob, 0u, static_cast<unsigned>(options.seed) + 1u);
    for (long i = 0; i < size; ++i)
      pop.push_back(pagmo::vector_double(flat.begin() + i * static_cast<long>(n), flat.begin() + (i + 1) * static_cast<long>(n)),
                    {f[2 * i], f[2 * i + 1]});
    if (moead) {
      // MOEA/D-DE (Li and Zhang 2009) with pagmo's defaults: grid weights (one per member),
      // Tchebycheff decomposition, DE rand/2/exp (CR 1, F 0.5), polynomial mutation (eta 20),
      // diversity preservation (realb 0.9, limit 2). Neighbourhood: a fifth of the population, at
      // least 2 (Li and Zhang use 20 of 300-600). pagmo 2.18's moead has no batch evaluator: it
      // evaluates one offspring at a time and updates the neighbours at once, so its points go
      // one by one, never as batches.
      const auto neighbours = static_cast<pagmo::population::size_type>(std::max<long>(2, size / 5));
      pagmo::moead algo(generations(options.max_evaluations), "grid", "tchebycheff", neighbours, 1.0, 0.5, 20., 0.9, 2u,
                        true, static_cast<unsigned>(options.seed));
      pagmo::algorithm(std::move(algo)).evolve(pop);
    } else {
      pagmo::nsga2 nsga(generations(options.max_evaluations), 0.95, 10.,
                        1. / static_cast<double>(std::max<std::size_t>(n, 1)), 20., static_cast<unsigned>(options.seed));
      nsga.set_bfe(pagmo::bfe(pagmo::member_bfe{}));
      pagmo::algorithm(std::move(nsga)).evolve(pop);
    }
  } catch (const RunStopped&) {
    reason = TerminationReason::MaxEvaluations;
  } catch (const std::exception& ex) {
    reason = TerminationReason::Failure;
    message = std::string("the optimiser threw: ") + ex.what();
  }
  OptimizationResult& r = out.run;
  r.problem_name = problem.name();
  r.algorithm = moead ? "PAGMO_MOEAD" : "PAGMO_NSGA2";
  r.x0 = x0;
  for (const Variable& v : problem.variables()) r.variable_names.push_back(v.name);
  r.inequality_names = problem.inequality_names();
  r.equality_names = problem.equality_names();
  driver.fill(r);
  r.reason = driver.stopped() ? *driver.stop_reason() : reason;
  r.message = driver.stopped() ? driver.stop_message() : message;
  // the front: non-dominated feasible evaluations of the whole run
  std::vector<std::pair<std::pair<double, double>, std::size_t>> feasible;
  for (std::size_t i = 0; i < r.history.size(); ++i) {
    const EvaluationRecord& h = r.history[i];
    const auto m = h.metrics.find(second_objective);
    if (h.feasible && m != h.metrics.end() && std::isfinite(m->second)) feasible.push_back({{h.objective, m->second}, i});
  }
  std::sort(feasible.begin(), feasible.end());
  double last = std::numeric_limits<double>::infinity();
  for (const auto& [o, i] : feasible)
    if (o.second < last) {
      out.front.push_back(i);
      last = o.second;
    }
  if (detail::interrupt_flag().load()) detail::interrupt_flag().store(false);
  return out;
}

}  // namespace abuopt::opt
