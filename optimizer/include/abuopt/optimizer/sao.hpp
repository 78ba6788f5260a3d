#pragma once
// SAO: sequential approximate optimisation in a trust region (the ADOPT / Dakota
// SurrBasedLocalMinimizer idea), behind the same Problem contract and returning the same
// OptimizationResult as minimize().
//
//   abuopt::opt::OptimizerOptions o;  o.max_evaluations = 200;
//   abuopt::opt::SaoOptions sao;       sao.surrogate = "auto";
//   abuopt::opt::OptimizationResult r = abuopt::opt::minimize_sao(problem, o, sao);
//
// One iteration, in the unit box z = (x - lower) / (upper - lower) (every variable scaled to its
// bounds) around the centre z_c with radius r (half-width, a fraction of each variable's range):
//   1. Region R = [z_c - r, z_c + r] clipped to [0, 1]^n. Local coordinates s = (z - z_c) / r.
//   2. DOE with reuse: every evaluated point (this run, and the entries of an attached
//      EvaluationArchive) lying in R counts. Candidate DOE points (Koshal, axial, central
//      composite or Latin hypercube in R) that are within `reuse_distance` (in s) of a point
//      already known are covered by it; the others are evaluated, farthest-from-known first,
//      until R holds `doe_points` points spanning a linear model.
//   3. Surrogates of f, every g_i and every h_j, fitted by weighted least squares in s on the
//      points of R (weight 1) and of the neighbourhood 2R (weight 1/|s|_inf^4). Basis "auto":
//      quadratic if there are enough points, else pure quadratic, else linear.
//   4. Sub-problem: minimise f^(s) s.t. g^(s) <= 0, h^(s) = 0, s in R, with NLopt SLSQP and
//      analytic surrogate gradients, from the centre and from the best known point in R. If the
//      surrogate constraints cannot be met in R, the sub-problem minimises the predicted
//      violation sum max(0, g^)^2 + h^2 instead (feasibility phase).
//   5. The candidate is evaluated on the true problem. Merit: exact L1 penalty
//      phi = f + mu (sum max(0, g_i) + sum |h_j|), mu raised to 2 max |lambda| (multipliers
//      estimated by least squares from the surrogate gradients at the candidate); in the
//      feasibility phase the merit is the violation alone.
//   6. Ratio test (Dakota): rho = (phi(c) - phi(x*)) / (phi^(c) - phi^(x*)).
//      rho <= 0: reject, keep the centre, r *= shrink_factor.
//      0 < rho <= 0.25: accept, r *= shrink_factor.   0.75 <= rho <= 1.25 and the step on the
//      boundary of R: accept, r *= expand_factor (up to max_radius). Otherwise accept, keep r,
//      except that an accepted step shorter than short_step * r shrinks r (see short_step).
// Stops (best point so far always returned, as minimize() does):
//   r < min_radius (converged_xtol); the centre's merit improved by less than
//   stall_tolerance * max(1, |phi|) for stall_iterations iterations (converged_ftol);
//   OptimizerOptions::max_iterations iterations (max_iterations; 0: no limit);
//   OptimizerOptions::max_evaluations / max_time_s / target / SIGINT / callback as in minimize().
// Like every optimiser, success() only if converged AND the best point is feasible.
//
// Options read from OptimizerOptions: max_evaluations, max_time_s, max_iterations, target,
// constraint_tolerance, seed (LHS), handle_sigint, keep_history. The algorithm name is ignored
// (minimize() knows "SAO" only once the dispatcher hooks minimize_sao in).
#include <string>
#include <vector>

#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/optimizer/minimize.hpp"

namespace abuopt::opt {

class EvaluationArchive;  // evaluation_archive.hpp

struct SaoOptions {
  // Surrogate of the objective and of every constraint: auto, linear, interactions,
  // pure_quadratic, quadratic, kriging. auto: the richest of quadratic > pure_quadratic > linear
  // that the points of the region support.
  std::string surrogate = "auto";
  // Candidate DOE in the region: auto, koshal, axial, central_composite, lhs.
  // auto: koshal for a linear surrogate, axial (centre and +-r on each axis) then the corners of
  // a central composite design for the quadratic ones, lhs for kriging.
  std::string doe = "auto";
  // Points wanted in the region before fitting; 0: automatic (linear: n+1, interactions: its
  // term count, pure_quadratic / auto / kriging: 2n+1, quadratic: (n+1)(n+2)/2).
  int doe_points = 0;
  // Multiplies the automatic count (doe_points == 0). Noisy problems: 2 (least squares over about
  // twice as many points as terms smooths the noise instead of interpolating it). In [1, 10].
  double doe_points_factor = 1.0;
  // A DOE candidate within this distance (infinity norm, local coordinates where the region is
  // [-1,1]^n) of a known point is covered by it and not evaluated. In (0, 1].
  double reuse_distance = 0.3;
  // Fit also on the points of the neighbourhood |s|_inf <= neighbourhood (>= 1; 1: region only),
  // weighted 1/|s|_inf^4.
  double neighbourhood = 2.0;

  // Trust region half-width as a fraction of each variable's range.
  double initial_radius = 0.1;   // in (0, 1]
  double min_radius = 1e-5;      // stop below it; in (0, initial_radius]
  double max_radius = 0.5;       // in [initial_radius, 1]
  double shrink_factor = 0.25;   // in (0, 1)
  double expand_factor = 2.0;    // >= 1
  // Ratio-test thresholds (Dakota's defaults).
  double rho_shrink = 0.25;      // rho <= rho_shrink: shrink (rho <= 0: also reject)
  double rho_expand_low = 0.75;  // rho in [rho_expand_low, rho_expand_high] and the step on
  double rho_expand_high = 1.25; // the boundary: expand

  // Zeroth-order additive correction (Dakota's `correction additive zeroth_order`): every
  // surrogate is shifted to match the true value at the centre.
  bool correction = true;
  // An accepted step shorter than short_step * r (infinity norm) also shrinks the region by
  // shrink_factor: the surrogates say the optimum is near, and a smaller region refines them
  // (without it a biased model creeps in ever smaller steps with rho ~ 1). 0: off. In [0, 1).
  double short_step = 0.1;

  // Initial exact-penalty weight mu; 0: automatic, 10 max(1, |f(x0)|).
  double penalty_initial = 0.0;
  // mu >= penalty_multiplier_factor * max |lambda| (estimated multipliers); >= 1.
  double penalty_multiplier_factor = 2.0;

  // Stall test: no improvement of the centre's merit by more than
  // stall_tolerance * max(1, |phi|) for stall_iterations iterations.
  int stall_iterations = 8;       // >= 1
  double stall_tolerance = 1e-8;  // >= 0

  // Sub-problem solver: slsqp (NLopt SLSQP, surrogate gradients) or cobyla (NLopt COBYLA).
  std::string subproblem_solver = "slsqp";
  int subproblem_max_evaluations = 500;  // per start; >= 10
  // Kriging nugget (relative to the process variance); raise it (e.g. 1e-2) for noisy problems.
  double kriging_nugget = 1e-8;

  // Points of this archive (same problem id) inform the surrogates without being evaluated
  // again. Not read from YAML; not owned; may be null.
  const EvaluationArchive* archive = nullptr;

  // Throws abuopt::ConfigError naming the key, the value and the rule
  // ("sao.min_radius = 0: must be in (0, initial_radius = 0.1]"); `prefix` is the section's path.
  void validate(const std::string& prefix = "sao") const;
};

// Reads the keys of a `sao:` section (pass root.child("sao")); absent keys keep their defaults,
// unknown keys are errors (finish() is called), then validate().
SaoOptions read_sao_options(YamlReader& section);

// Minimises `problem` from x0 (empty: problem.initial_point()) by SAO.
// Throws abuopt::ConfigError before any evaluation for invalid options (the algorithm name in
// `options` is not checked), an invalid problem or starting point. Once evaluations start it
// never throws: everything else is a TerminationReason. The result's algorithm is
// "SAO(<surrogate>)".
OptimizationResult minimize_sao(Problem& problem, const OptimizerOptions& options, const SaoOptions& sao,
                                std::vector<double> x0 = {}, const EvaluationCallback& callback = {});

// true for "SAO" (case-insensitive): how a caller dispatches between minimize() and
// minimize_sao() by algorithm name.
bool is_sao_algorithm(const std::string& name);

// minimize() for every algorithm name, plus "SAO" (with `sao` options).
OptimizationResult minimize_any(Problem& problem, const OptimizerOptions& options, const SaoOptions& sao = {},
                                std::vector<double> x0 = {}, const EvaluationCallback& callback = {});

}  // namespace abuopt::opt
