// NLopt adapter (C API: nlopt_force_stop lets the evaluation wrapper stop any algorithm,
// including the sub-optimiser of AUGLAG / MLSL, without throwing through C code).
#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "adapters.hpp"

namespace abuopt::opt::detail {

namespace {

nlopt_algorithm nlopt_code(const std::string& name) {
  if (name == "COBYLA") return NLOPT_LN_COBYLA;
  if (name == "BOBYQA") return NLOPT_LN_BOBYQA;
  if (name == "NEWUOA_BOUND") return NLOPT_LN_NEWUOA_BOUND;
  if (name == "SBPLX") return NLOPT_LN_SBPLX;
  if (name == "NELDERMEAD") return NLOPT_LN_NELDERMEAD;
  if (name == "PRAXIS") return NLOPT_LN_PRAXIS;
  if (name == "DIRECT_L") return NLOPT_GN_DIRECT_L;
  if (name == "CRS2_LM") return NLOPT_GN_CRS2_LM;
  if (name == "ISRES") return NLOPT_GN_ISRES;
  if (name == "ESCH") return NLOPT_GN_ESCH;
  if (name == "MLSL_LDS") return NLOPT_G_MLSL_LDS;
  if (name == "AUGLAG") return NLOPT_AUGLAG;
  if (name == "MMA") return NLOPT_LD_MMA;
  if (name == "CCSAQ") return NLOPT_LD_CCSAQ;
  if (name == "SLSQP") return NLOPT_LD_SLSQP;
  if (name == "LBFGS") return NLOPT_LD_LBFGS;
  throw std::logic_error("no NLopt algorithm for " + name);
}

struct OptDeleter {
  void operator()(nlopt_opt o) const { nlopt_destroy(o); }
};
using OptPtr = std::unique_ptr<std::remove_pointer_t<nlopt_opt>, OptDeleter>;

struct Context {
  EvaluationDriver* driver;
  nlopt_opt outer;
};

void stop_if_needed(Context& c) {
  if (c.driver->stopped()) nlopt_force_stop(c.outer);
}

double objective(unsigned n, const double* y, double* grad, void* data) {
  Context& c = *static_cast<Context*>(data);
  const EvaluatedPoint* p = c.driver->evaluate(y);
  if (!p) {
    if (grad) std::fill(grad, grad + n, 0.0);
    nlopt_force_stop(c.outer);
    return HUGE_VAL;
  }
  if (grad && !c.driver->derivatives(y, *p, grad, nullptr, nullptr)) std::fill(grad, grad + n, 0.0);
  stop_if_needed(c);
  return p->e.ok ? p->e.objective : c.driver->failure_objective();
}

template <bool Equality>
void constraints(unsigned m, double* result, unsigned n, const double* y, double* grad, void* data) {
  Context& c = *static_cast<Context*>(data);
  const EvaluatedPoint* p = c.driver->evaluate(y);
  if (!p || !p->e.ok) {
    std::fill(result, result + m, p ? c.driver->failure_constraint() : HUGE_VAL);
    if (grad) std::fill(grad, grad + static_cast<std::size_t>(m) * n, 0.0);
    if (!p) nlopt_force_stop(c.outer);
    return;
  }
  const std::vector<double>& v = Equality ? p->e.equality : p->e.inequality;
  std::copy(v.begin(), v.end(), result);
  if (grad) {
    const bool ok = Equality ? c.driver->derivatives(y, *p, nullptr, nullptr, grad)
                             : c.driver->derivatives(y, *p, nullptr, grad, nullptr);
    if (!ok) std::fill(grad, grad + static_cast<std::size_t>(m) * n, 0.0);
  }
  stop_if_needed(c);
}

void set_tolerances(nlopt_opt o, const OptimizerOptions& options, const EvaluationDriver& d) {
  nlopt_set_xtol_rel(o, options.xtol_rel);
  // An absolute floor in scaled units, so that a variable converging to 0 can meet the test.
  nlopt_set_xtol_abs1(o, 0.01 * options.xtol_rel);
  nlopt_set_ftol_rel(o, options.ftol_rel);
  nlopt_set_ftol_abs(o, options.ftol_abs);
  if (options.initial_step > 0) {
    std::vector<double> dx(d.n());
    for (std::size_t i = 0; i < d.n(); ++i) dx[i] = options.initial_step * (d.upper_scaled()[i] - d.lower_scaled()[i]);
    nlopt_set_initial_step(o, dx.data());
  }
}

AdapterOutcome map_result(nlopt_result r, EvaluationDriver& d) {
  AdapterOutcome out;
  switch (r) {
    case NLOPT_SUCCESS: out = {TerminationReason::Converged, "NLopt: success", "", 0, {}}; break;
    case NLOPT_STOPVAL_REACHED: out = {TerminationReason::TargetReached, "NLopt: stopval reached", "", 0, {}}; break;
    case NLOPT_FTOL_REACHED: out = {TerminationReason::ConvergedFtol, "NLopt: ftol_rel or ftol_abs reached", "", 0, {}}; break;
    case NLOPT_XTOL_REACHED: out = {TerminationReason::ConvergedXtol, "NLopt: xtol_rel reached", "", 0, {}}; break;
    case NLOPT_MAXEVAL_REACHED:
      out = {TerminationReason::MaxEvaluations,
             "NLopt's own call limit (10 x max_evaluations + 100, counting repeated points) reached", "", 0, {}};
      break;
    case NLOPT_MAXTIME_REACHED: out = {TerminationReason::MaxTime, "NLopt: maxtime reached", "", 0, {}}; break;
    case NLOPT_FORCED_STOP: out = {TerminationReason::Failure, "NLopt: forced stop", "", 0, {}}; break;
    case NLOPT_ROUNDOFF_LIMITED:
      out = {TerminationReason::RoundoffLimited, "NLopt: roundoff errors limited progress", "", 0, {}};
      break;
    case NLOPT_OUT_OF_MEMORY: out = {TerminationReason::Failure, "NLopt: out of memory", "", 0, {}}; break;
    case NLOPT_INVALID_ARGS: out = {TerminationReason::Failure, "NLopt: invalid arguments", "", 0, {}}; break;
    default: out = {TerminationReason::Failure, "NLopt: failure", "", 0, {}}; break;
  }
  (void)d;
  return out;
}

}  // namespace

AdapterOutcome run_nlopt(EvaluationDriver& d, const AlgorithmInfo& algorithm, const AlgorithmInfo* local,
                         bool wrap_in_auglag, const OptimizerOptions& options, const std::vector<double>& x0) {
  const unsigned n = static_cast<unsigned>(d.n());
  const bool uses_local = wrap_in_auglag || algorithm.needs_local;
  // the algorithm that solves AUGLAG's / MLSL's sub-problems (none for a plain run: never bind a
  // reference to *local then, local is null)
  const AlgorithmInfo* inner = wrap_in_auglag ? &algorithm : local;
  if (uses_local && !inner)
    throw std::invalid_argument("run_nlopt: " + algorithm.name + " needs a local algorithm and none was given");

  nlopt_algorithm outer_code = nlopt_code(algorithm.name);
  std::string label = algorithm.name;
  if (wrap_in_auglag) {
    // AUGLAG_EQ keeps the inequality constraints in the local problem when it handles them.
    outer_code = algorithm.inequality_constraints ? NLOPT_AUGLAG_EQ : NLOPT_AUGLAG;
    label = std::string(algorithm.inequality_constraints ? "AUGLAG_EQ" : "AUGLAG") + "(" + algorithm.name + ")";
  } else if (uses_local) {
    label = algorithm.name + "(" + local->name + ")";
  }

  OptPtr opt(nlopt_create(outer_code, n));
  if (!opt) throw std::runtime_error("nlopt_create failed for " + label);
  OptPtr local_opt;
  if (uses_local) {
    local_opt.reset(nlopt_create(nlopt_code(inner->name), n));
    if (!local_opt) throw std::runtime_error("nlopt_create failed for " + inner->name);
    set_tolerances(local_opt.get(), options, d);
  }

  Context ctx{&d, opt.get()};
  nlopt_set_lower_bounds(opt.get(), d.lower_scaled().data());
  nlopt_set_upper_bounds(opt.get(), d.upper_scaled().data());
  nlopt_set_min_objective(opt.get(), objective, &ctx);
  if (d.n_inequality() > 0) {
    std::vector<double> tol(d.n_inequality(), options.constraint_tolerance);
    nlopt_add_inequality_mconstraint(opt.get(), static_cast<unsigned>(d.n_inequality()), constraints<false>, &ctx,
                                     tol.data());
  }
  if (d.n_equality() > 0) {
    std::vector<double> tol(d.n_equality(), options.constraint_tolerance);
    nlopt_add_equality_mconstraint(opt.get(), static_cast<unsigned>(d.n_equality()), constraints<true>, &ctx,
                                   tol.data());
  }
  set_tolerances(opt.get(), options, d);
  // The driver enforces the budget and time; these are safety nets only.
  nlopt_set_maxeval(opt.get(), static_cast<int>(std::min<long>(options.max_evaluations * 10 + 100, 2000000000L)));
  if (options.max_time_s > 0) nlopt_set_maxtime(opt.get(), options.max_time_s * 1.5 + 1.0);
  if (options.population > 0) nlopt_set_population(opt.get(), static_cast<unsigned>(options.population));
  if (local_opt) nlopt_set_local_optimizer(opt.get(), local_opt.get());
  nlopt_srand(options.seed);

  std::vector<double> y = d.to_scaled(x0);
  for (std::size_t i = 0; i < n; ++i) y[i] = std::min(std::max(y[i], d.lower_scaled()[i]), d.upper_scaled()[i]);
  double f = 0;
  const nlopt_result r = nlopt_optimize(opt.get(), y.data(), &f);
  AdapterOutcome out = map_result(r, d);
  if (r < 0 && r != NLOPT_FORCED_STOP) {
    const char* err = nlopt_get_errmsg(opt.get());
    if (err) out.message += std::string(": ") + err;
  }
  out.algorithm_label = label;
  return out;
}

}  // namespace abuopt::opt::detail
