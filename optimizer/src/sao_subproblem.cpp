// SAO: the sub-problem on the surrogates (see sao.hpp, step 4; NLopt SLSQP or COBYLA from the
// centre and the best known point of the region, a feasibility phase when the surrogate
// constraints cannot be met) and the penalty weight of the merit (step 5).
#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <type_traits>

#include "sao_run.hpp"

namespace abuopt::opt::detail {

namespace {

struct OptDeleter {
  void operator()(nlopt_opt o) const { nlopt_destroy(o); }
};
using OptPtr = std::unique_ptr<std::remove_pointer_t<nlopt_opt>, OptDeleter>;

// NLopt callbacks on the surrogates.
struct SubContext {
  const Models* models;
  bool feasibility_phase;
};

double sub_objective(unsigned n, const double* s, double* grad, void* data) {
  const SubContext& c = *static_cast<SubContext*>(data);
  const Eigen::VectorXd xs = Eigen::Map<const Eigen::VectorXd>(s, n);
  const Models& m = *c.models;
  if (!c.feasibility_phase) {
    if (grad) {
      const Eigen::VectorXd gr = m.f_grad(xs);
      std::copy(gr.data(), gr.data() + n, grad);
    }
    return m.f(xs);
  }
  // sum max(0, g)^2 + sum h^2
  double p = 0;
  Eigen::VectorXd gr = Eigen::VectorXd::Zero(n);
  for (std::size_t i = 0; i < m.n_g(); ++i) {
    const double v = m.g(i, xs);
    if (v > 0) {
      p += v * v;
      if (grad) gr += 2 * v * m.g_grad(i, xs);
    }
  }
  for (std::size_t j = 0; j < m.n_h(); ++j) {
    const double v = m.h(j, xs);
    p += v * v;
    if (grad) gr += 2 * v * m.h_grad(j, xs);
  }
  if (grad) std::copy(gr.data(), gr.data() + n, grad);
  return p;
}

template <bool Equality>
void sub_constraints(unsigned m, double* result, unsigned n, const double* s, double* grad, void* data) {
  const SubContext& c = *static_cast<SubContext*>(data);
  const Eigen::VectorXd xs = Eigen::Map<const Eigen::VectorXd>(s, n);
  for (unsigned i = 0; i < m; ++i) {
    result[i] = Equality ? c.models->h(i, xs)
                         : c.models->g(i, xs) + (i < c.models->g_margin.size() ? c.models->g_margin[i] : 0.0);
    if (grad) {
      const Eigen::VectorXd gr = Equality ? c.models->h_grad(i, xs) : c.models->g_grad(i, xs);
      std::copy(gr.data(), gr.data() + n, grad + static_cast<std::size_t>(i) * n);
    }
  }
}

}  // namespace

Eigen::VectorXd SaoRun::run_nlopt(const Models& models, bool feasibility_phase, const Eigen::VectorXd& start,
                                  const RegionBox& box) const {
  const Eigen::VectorXd& lo = box.lo;
  const Eigen::VectorXd& hi = box.hi;
  const unsigned n = static_cast<unsigned>(n_);
  const bool slsqp = sao_.subproblem_solver == SubproblemSolver::Slsqp;
  OptPtr opt(nlopt_create(slsqp ? NLOPT_LD_SLSQP : NLOPT_LN_COBYLA, n));
  if (!opt) return start;
  SubContext ctx{&models, feasibility_phase};
  nlopt_set_lower_bounds(opt.get(), lo.data());
  nlopt_set_upper_bounds(opt.get(), hi.data());
  nlopt_set_min_objective(opt.get(), sub_objective, &ctx);
  if (!feasibility_phase) {
    const double tol = 0.1 * options_.constraint_tolerance;
    if (m_ineq_ > 0) {
      std::vector<double> t(m_ineq_, tol);
      nlopt_add_inequality_mconstraint(opt.get(), static_cast<unsigned>(m_ineq_), sub_constraints<false>, &ctx,
                                       t.data());
    }
    if (m_eq_ > 0) {
      std::vector<double> t(m_eq_, tol);
      nlopt_add_equality_mconstraint(opt.get(), static_cast<unsigned>(m_eq_), sub_constraints<true>, &ctx, t.data());
    }
  }
  nlopt_set_xtol_abs1(opt.get(), 1e-10);
  nlopt_set_ftol_rel(opt.get(), 1e-14);
  nlopt_set_maxeval(opt.get(), sao_.subproblem_max_evaluations);
  if (!slsqp) {
    std::vector<double> dx(n);
    for (unsigned i = 0; i < n; ++i) dx[i] = std::max(1e-3, 0.25 * (hi[i] - lo[i]));
    nlopt_set_initial_step(opt.get(), dx.data());
  }
  std::vector<double> x(start.data(), start.data() + n);
  for (unsigned i = 0; i < n; ++i) x[i] = std::clamp(x[i], lo[i], hi[i]);
  double f = 0;
  nlopt_optimize(opt.get(), x.data(), &f);  // whatever the code, x holds its last iterate
  Eigen::VectorXd out = Eigen::Map<Eigen::VectorXd>(x.data(), n);
  for (int i = 0; i < n_; ++i)
    if (!std::isfinite(out[i])) out[i] = start[i];
  return out.cwiseMax(lo).cwiseMin(hi);
}

Eigen::VectorXd SaoRun::solve_subproblem(Models& models, bool& feasibility_phase) {
  const RegionBox box = region_box();
  // starts: the centre and the best known point of the region (by the current merit)
  std::vector<Eigen::VectorXd> starts = {Eigen::VectorXd::Zero(n_)};
  {
    double best = merit(known_[centre_]);
    std::optional<Eigen::VectorXd> s_best;
    for (const KnownPoint& p : known_)
      if (p.fits() && in_region(p.z) && merit(p) < best) {
        best = merit(p);
        s_best = to_s(p.z);
      }
    if (s_best) starts.push_back(*s_best);
  }
  const double tol = options_.constraint_tolerance;
  std::optional<Eigen::VectorXd> best_s;
  double best_f = kInf;
  // with confirmed constraint noise first with the constraints backed off by it, then (nothing
  // feasible so) without
  std::vector<double> margin(m_ineq_, 0.0);
  bool backed_off = false;
  for (std::size_t i = 0; i < m_ineq_ && i + 1 < models.noise.size(); ++i) {
    margin[i] = sao_.noise_tolerance * models.noise[1 + i];
    backed_off = backed_off || margin[i] > 0;
  }
  for (int attempt = backed_off ? 0 : 1; attempt < 2 && !best_s; ++attempt) {
    models.g_margin = attempt == 0 ? margin : std::vector<double>(m_ineq_, 0.0);
    for (const auto& st : starts) {
      const Eigen::VectorXd s = run_nlopt(models, false, st, box);
      double v = 0;
      for (std::size_t i = 0; i < m_ineq_; ++i) v = std::max(v, models.g(i, s) + models.g_margin[i]);
      for (std::size_t j = 0; j < m_eq_; ++j) v = std::max(v, std::fabs(models.h(j, s)));
      if (v > std::max(tol, 1e-12)) continue;
      const double f = models.f(s);
      if (f < best_f) {
        best_f = f;
        best_s = s;
      }
    }
  }
  models.g_margin.assign(m_ineq_, 0.0);
  if (best_s) {
    feasibility_phase = false;
    return *best_s;
  }
  // no surrogate-feasible point found in the region: minimise the predicted violation
  feasibility_phase = true;
  double best_v = kInf;
  Eigen::VectorXd out = Eigen::VectorXd::Zero(n_);
  for (const auto& st : starts) {
    const Eigen::VectorXd s = run_nlopt(models, true, st, box);
    const double v = models.l1(s);
    if (v < best_v) {
      best_v = v;
      out = s;
    }
  }
  return out;
}

// mu >= factor * max |lambda|, the multipliers estimated by least squares from the surrogate
// gradients at s (free variables, active inequality constraints and the equalities).
void SaoRun::update_penalty(const Models& models, const Eigen::VectorXd& s) {
  if (m_ineq_ + m_eq_ == 0) return;
  const RegionBox box = region_box();
  const Eigen::VectorXd& lo = box.lo;
  const Eigen::VectorXd& hi = box.hi;
  std::vector<int> free;
  for (int i = 0; i < n_; ++i)
    if (s[i] > lo[i] + 1e-7 && s[i] < hi[i] - 1e-7) free.push_back(i);
  std::vector<Eigen::VectorXd> grads;
  for (std::size_t i = 0; i < models.n_g(); ++i)
    if (models.g(i, s) >= -1e-6 * std::max(1.0, std::fabs(models.g(i, Eigen::VectorXd::Zero(n_)))))
      grads.push_back(models.g_grad(i, s));
  for (std::size_t j = 0; j < models.n_h(); ++j) grads.push_back(models.h_grad(j, s));
  if (free.empty() || grads.empty()) return;
  const Eigen::VectorXd gf = models.f_grad(s);
  Eigen::MatrixXd A(free.size(), grads.size());
  Eigen::VectorXd b(free.size());
  for (std::size_t r = 0; r < free.size(); ++r) {
    b[r] = -gf[free[r]];
    for (std::size_t c = 0; c < grads.size(); ++c) A(r, c) = grads[c][free[r]];
  }
  const Eigen::VectorXd lambda = A.completeOrthogonalDecomposition().solve(b);
  if (!lambda.allFinite()) return;
  const double need = sao_.penalty_multiplier_factor * lambda.cwiseAbs().maxCoeff();
  if (need > mu_ && need < 1e12) mu_ = need;
}

}  // namespace abuopt::opt::detail
