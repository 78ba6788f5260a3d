#include "abuopt/optimizer/minimize.hpp"

#include <exception>

#include "abuopt/common/config_error.hpp"
#include "adapters.hpp"
#include "evaluation_driver.hpp"

namespace abuopt::opt {

void request_stop() noexcept { detail::interrupt_flag().store(true); }

namespace {

std::string count_text(std::size_t k, const char* what) {
  return std::to_string(k) + " " + what + (k == 1 ? "" : "s");
}

}  // namespace

OptimizationResult minimize(Problem& problem, const OptimizerOptions& options, std::vector<double> x0,
                            const EvaluationCallback& callback) {
  // ---- everything that can be wrong before the first evaluation is a ConfigError ----
  options.validate();
  check_problem(problem);
  if (x0.empty()) x0 = problem.initial_point();
  check_design_vector(problem, x0, "starting point");

  const AlgorithmInfo& algorithm = find_algorithm(options.algorithm, "optimizer.algorithm");
  const std::size_t n = problem.variables().size();
  const std::size_t m_ineq = problem.inequality_names().size();
  const std::size_t m_eq = problem.equality_names().size();
  const bool needs_ineq = m_ineq > 0 && !algorithm.inequality_constraints;
  const bool needs_eq = m_eq > 0 && !algorithm.equality_constraints;
  bool wrap = false;
  if (needs_ineq || needs_eq) {
    const std::string what = needs_ineq && needs_eq ? "inequality and equality constraints"
                             : needs_ineq           ? count_text(m_ineq, "inequality constraint")
                                                    : count_text(m_eq, "equality constraint");
    if (algorithm.family == AlgorithmFamily::Global)
      throw ConfigError("optimizer.algorithm", options.algorithm,
                        "the global algorithm " + algorithm.name + " handles bounds only and problem '" +
                            problem.name() + "' has " + what +
                            "; use ISRES (global, constrained), COBYLA, SLSQP or IPOPT (local), or AUGLAG");
    wrap = true;  // a local algorithm: solved inside AUGLAG's augmented Lagrangian
  }
  const AlgorithmInfo* local = nullptr;
  if (algorithm.needs_local) {
    if (options.local_algorithm.empty())
      local = &find_algorithm(n >= 2 ? "BOBYQA" : "SBPLX");
    else
      local = &find_algorithm(options.local_algorithm, "optimizer.local_algorithm");
  }
  auto too_few = [&](const AlgorithmInfo& a) {
    return (a.name == "BOBYQA" || a.name == "NEWUOA_BOUND" || a.name == "PRAXIS") && n < 2;
  };
  if (too_few(algorithm) || (local && too_few(*local)))
    throw ConfigError("optimizer.algorithm", options.algorithm,
                      (too_few(algorithm) ? algorithm.name : local->name) +
                          " needs at least 2 variables; problem '" + problem.name() + "' has 1 (use COBYLA or SBPLX)");

  if (algorithm.name == "SAO") detail::check_sao_sampling(problem, options.sao);
  if (detail::is_pagmo_algorithm(algorithm.name)) detail::check_pagmo(algorithm.name, n, options);

  // ---- the run: from here on nothing throws; the best point so far is always returned ----
  detail::SigintGuard sigint(options.handle_sigint);
  detail::interrupt_flag().store(false);
  detail::EvaluationDriver driver(problem, options, callback);
  detail::AdapterOutcome outcome;
  outcome.algorithm_label = algorithm.name;
  try {
    if (algorithm.name == "IPOPT")
      outcome = detail::run_ipopt(driver, options, x0);
    else if (algorithm.name == "SAO")
      outcome = detail::run_sao(driver, problem, options, x0);
    else if (detail::is_pagmo_algorithm(algorithm.name))
      outcome = detail::run_pagmo(driver, algorithm, options, x0);
    else
      outcome = detail::run_nlopt(driver, algorithm, local, wrap, options, x0);
  } catch (const std::exception& ex) {
    outcome.reason = TerminationReason::Failure;
    outcome.message = std::string("the optimiser threw: ") + ex.what();
  }

  OptimizationResult r;
  r.problem_name = problem.name();
  r.algorithm = outcome.algorithm_label;
  r.x0 = x0;
  r.iterations = outcome.iterations;
  r.iteration_records = std::move(outcome.records);
  for (const Variable& v : problem.variables()) r.variable_names.push_back(v.name);
  r.inequality_names = problem.inequality_names();
  r.equality_names = problem.equality_names();
  driver.fill(r);
  if (driver.fatal_error()) std::rethrow_exception(driver.fatal_error());  // e.g. the archive cannot be written

  if (driver.stopped()) {  // our own stop (budget, time, callback, interrupt, error, target) wins
    r.reason = *driver.stop_reason();
    r.message = driver.stop_message();
  } else {
    r.reason = outcome.reason;
    r.message = outcome.message;
  }
  if (wrap) r.message += " [" + algorithm.name + " handles bounds only: wrapped in AUGLAG for the constraints]";
  if (is_convergence(r.reason) && !r.has_feasible_point()) {
    r.message = "the algorithm stopped (" + to_string(r.reason) + ": " + r.message +
                ") but no evaluated point is feasible within the tolerance " +
                format_number(options.constraint_tolerance) +
                (r.x.empty() ? "" : " (smallest violation " + format_number(r.max_violation) + ")");
    r.reason = TerminationReason::Infeasible;
  }
  if (detail::interrupt_flag().load()) detail::interrupt_flag().store(false);
  return r;
}

}  // namespace abuopt::opt
