// Ipopt adapter through its TNLP interface: dense finite-difference gradient and constraint
// Jacobian from the evaluation driver, limited-memory (L-BFGS) Hessian, bounds kept exactly
// (bound_relax_factor 0), the evaluation budget enforced by the driver (intermediate_callback
// returns false once the driver has stopped).
#include "IpIpoptApplication.hpp"
#include "IpTNLP.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "adapters.hpp"

namespace abuopt::opt::detail {

namespace {

using Ipopt::Index;
using Ipopt::Number;

class DriverTnlp : public Ipopt::TNLP {
 public:
  DriverTnlp(EvaluationDriver& d, const std::vector<double>& y0) : d_(d), y0_(y0) {}

  long iterations = 0;
  // Ipopt may keep iterating on the same points when finite-difference noise keeps it above its
  // tolerance; after kStallIterations iterations without a new evaluation it is stopped.
  static constexpr int kStallIterations = 5;
  bool stalled = false;

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag, IndexStyleEnum& index_style) override {
    n = static_cast<Index>(d_.n());
    m = static_cast<Index>(d_.n_inequality() + d_.n_equality());
    nnz_jac_g = n * m;
    nnz_h_lag = 0;
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l, Number* g_u) override {
    for (Index i = 0; i < n; ++i) {
      x_l[i] = d_.lower_scaled()[i];
      x_u[i] = d_.upper_scaled()[i];
    }
    const Index mi = static_cast<Index>(d_.n_inequality());
    for (Index j = 0; j < m; ++j) {
      g_l[j] = j < mi ? -1e19 : 0.0;  // Ipopt's default nlp_lower_bound_inf is -1e19
      g_u[j] = 0.0;
    }
    return true;
  }

  bool get_starting_point(Index n, bool init_x, Number* x, bool init_z, Number*, Number*, Index, bool init_lambda,
                          Number*) override {
    if (!init_x || init_z || init_lambda) return false;
    std::copy(y0_.begin(), y0_.begin() + n, x);
    return true;
  }

  bool eval_f(Index, const Number* x, bool, Number& obj_value) override {
    const EvaluatedPoint* p = d_.evaluate(x);
    if (!p || !p->e.ok) return false;
    obj_value = p->e.objective;
    return true;
  }

  bool eval_grad_f(Index, const Number* x, bool, Number* grad_f) override {
    const EvaluatedPoint* p = d_.evaluate(x);
    if (!p || !p->e.ok) return false;
    return d_.derivatives(x, *p, grad_f, nullptr, nullptr);
  }

  bool eval_g(Index, const Number* x, bool, Index, Number* g) override {
    const EvaluatedPoint* p = d_.evaluate(x);
    if (!p || !p->e.ok) return false;
    std::copy(p->e.inequality.begin(), p->e.inequality.end(), g);
    std::copy(p->e.equality.begin(), p->e.equality.end(), g + d_.n_inequality());
    return true;
  }

  bool eval_jac_g(Index n, const Number* x, bool, Index m, Index, Index* iRow, Index* jCol, Number* values) override {
    if (!values) {
      for (Index r = 0, k = 0; r < m; ++r)
        for (Index c = 0; c < n; ++c, ++k) {
          iRow[k] = r;
          jCol[k] = c;
        }
      return true;
    }
    const EvaluatedPoint* p = d_.evaluate(x);
    if (!p || !p->e.ok) return false;
    double* jac_eq = values + d_.n_inequality() * static_cast<std::size_t>(n);
    return d_.derivatives(x, *p, nullptr, d_.n_inequality() ? values : nullptr, d_.n_equality() ? jac_eq : nullptr);
  }

  void finalize_solution(Ipopt::SolverReturn, Index, const Number*, const Number*, const Number*, Index,
                         const Number*, const Number*, Number, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {}

  bool intermediate_callback(Ipopt::AlgorithmMode, Index iter, Number, Number, Number, Number, Number, Number, Number,
                             Number, Index, const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    iterations = iter;
    if (d_.evaluations() == evaluations_at_last_iteration_) {
      if (++iterations_without_new_points_ >= kStallIterations) {
        stalled = true;
        return false;
      }
    } else {
      iterations_without_new_points_ = 0;
    }
    evaluations_at_last_iteration_ = d_.evaluations();
    return !d_.stopped();
  }

 private:
  EvaluationDriver& d_;
  std::vector<double> y0_;
  long evaluations_at_last_iteration_ = -1;
  int iterations_without_new_points_ = 0;
};

AdapterOutcome map_status(Ipopt::ApplicationReturnStatus s) {
  using R = TerminationReason;
  switch (s) {
    case Ipopt::Solve_Succeeded: return {R::Converged, "Ipopt: optimal solution found", "", 0, {}};
    case Ipopt::Solved_To_Acceptable_Level:
      return {R::Converged, "Ipopt: solved to an acceptable level (acceptable_tol)", "", 0, {}};
    case Ipopt::Infeasible_Problem_Detected: return {R::Infeasible, "Ipopt: converged to a point of local infeasibility", "", 0, {}};
    case Ipopt::Search_Direction_Becomes_Too_Small:
      return {R::ConvergedXtol, "Ipopt: search direction became too small", "", 0, {}};
    case Ipopt::Diverging_Iterates: return {R::Failure, "Ipopt: iterates diverging", "", 0, {}};
    case Ipopt::User_Requested_Stop: return {R::StoppedByCallback, "Ipopt: stopped on request", "", 0, {}};
    case Ipopt::Feasible_Point_Found: return {R::Converged, "Ipopt: feasible point found", "", 0, {}};
    case Ipopt::Maximum_Iterations_Exceeded: return {R::MaxIterations, "Ipopt: maximum number of iterations", "", 0, {}};
    case Ipopt::Restoration_Failed: return {R::Failure, "Ipopt: restoration phase failed", "", 0, {}};
    case Ipopt::Error_In_Step_Computation: return {R::Failure, "Ipopt: error in step computation", "", 0, {}};
    case Ipopt::Maximum_CpuTime_Exceeded: return {R::MaxTime, "Ipopt: maximum CPU time exceeded", "", 0, {}};
    case Ipopt::Not_Enough_Degrees_Of_Freedom:
      return {R::Failure, "Ipopt: not enough degrees of freedom (more equality constraints than variables?)", "", 0, {}};
    case Ipopt::Invalid_Problem_Definition: return {R::Failure, "Ipopt: invalid problem definition", "", 0, {}};
    case Ipopt::Invalid_Option: return {R::Failure, "Ipopt: invalid option", "", 0, {}};
    case Ipopt::Invalid_Number_Detected:
      return {R::Failure, "Ipopt: invalid number (NaN/inf) in the problem functions", "", 0, {}};
    default: return {R::Failure, "Ipopt: internal error (status " + std::to_string(static_cast<int>(s)) + ")", "", 0, {}};
  }
}

}  // namespace

AdapterOutcome run_ipopt(EvaluationDriver& d, const OptimizerOptions& options, const std::vector<double>& x0) {
  std::vector<double> y0 = d.to_scaled(x0);
  for (std::size_t i = 0; i < d.n(); ++i) y0[i] = std::min(std::max(y0[i], d.lower_scaled()[i]), d.upper_scaled()[i]);
  Ipopt::SmartPtr<DriverTnlp> tnlp = new DriverTnlp(d, y0);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  auto opts = app->Options();
  opts->SetStringValue("sb", "yes");  // no banner
  opts->SetIntegerValue("print_level", options.print_level);
  opts->SetStringValue("hessian_approximation", "limited-memory");
  opts->SetNumericValue("bound_relax_factor", 0.0);  // never evaluate outside the bounds
  opts->SetStringValue("honor_original_bounds", "yes");
  opts->SetNumericValue("constr_viol_tol", std::max(options.constraint_tolerance, 1e-12));
  opts->SetNumericValue("tol", std::max(options.ftol_rel, 1e-12));
  if (options.max_iterations > 0) opts->SetIntegerValue("max_iter", static_cast<Index>(options.max_iterations));
  if (options.max_time_s > 0) opts->SetNumericValue("max_cpu_time", options.max_time_s);
  AdapterOutcome out;
  out.algorithm_label = "IPOPT";
  Ipopt::ApplicationReturnStatus status = app->Initialize("");
  if (status != Ipopt::Solve_Succeeded) {
    out.reason = TerminationReason::Failure;
    out.message = "Ipopt failed to initialise (status " + std::to_string(static_cast<int>(status)) + ")";
    return out;
  }
  status = app->OptimizeTNLP(Ipopt::SmartPtr<Ipopt::TNLP>(GetRawPtr(tnlp)));
  AdapterOutcome mapped = map_status(status);
  mapped.algorithm_label = out.algorithm_label;
  mapped.iterations = tnlp->iterations;
  if (status == Ipopt::User_Requested_Stop && tnlp->stalled) {
    mapped.reason = TerminationReason::ConvergedXtol;
    mapped.message = "Ipopt stopped: no new point in " + std::to_string(DriverTnlp::kStallIterations) +
                     " iterations (finite-difference noise above its tolerance)";
  }
  return mapped;
}

}  // namespace abuopt::opt::detail
