#pragma once
// SAO: sequential approximate optimisation in a trust region (the ADOPT / Dakota
// SurrBasedLocalMinimizer idea), behind the same Problem contract and returning the same
// OptimizationResult as minimize().
//
//   abuopt::opt::OptimizerOptions o;  o.max_evaluations = 200;
//   abuopt::opt::SaoOptions sao;       sao.surrogate = abuopt::opt::SurrogateKind::Auto;
//   abuopt::opt::OptimizationResult r = abuopt::opt::minimize_sao(problem, o, sao);
//
// One iteration, in the unit box z = (x - lower) / (upper - lower) (every variable scaled to its
// bounds) around the centre z_c with radius r (half-width, a fraction of each variable's range):
//   1. Region R = [z_c - r, z_c + r] clipped to [0, 1]^n. Local coordinates s = (z - z_c) / r.
//   2. Points: every evaluated point (this run, and the entries of an attached
//      EvaluationArchive) is kept; those in the fit zone |s|_inf <= neighbourhood (4) are fitted.
//      Default (doe auto): no design per region; a point is added on the boundary of R along the
//      weakest direction only while the zone's weighted spread is below geometry_spread (or it
//      holds fewer than n+1 points): about n+1 points at the start, few afterwards. With an
//      explicit design, doe_points, doe_points_factor > 1 or kriging, each region is filled with
//      a Koshal / axial / central composite / Latin hypercube design, reusing known points within
//      `reuse_distance` (in s), farthest-from-known first.
//   3. Surrogates of f, every g_i and every h_j, fitted by weighted least squares in s on the
//      points of R (weight 1) and of the rest of the fit zone (weight 1/|s|_inf^4). Basis "auto":
//      quadratic if there are enough points, else pure quadratic, else linear. Each response in its
//      own intervening variables (sao_intervening.hpp; option intervening: linear, reciprocal,
//      fitted exponents, auto by weighted leave-one-out error); the sub-problem sees the composed
//      models and their chain-rule gradients.
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
// OptimizationResult::iteration_records holds one record per iteration (radius before and after,
// predicted and actual reduction, rho, the noise level allowed for, penalty weight, run count).
//
// SAO is an algorithm of minimize() like any other: `algorithm: SAO` (any case) runs it with
// OptimizerOptions::sao, through the same evaluation wrapper, SIGINT handling and result
// building. Options used besides `sao`: max_evaluations, max_time_s, max_iterations, target,
// constraint_tolerance, seed (LHS), handle_sigint, keep_history.
#include <vector>

#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/sao_options.hpp"

namespace abuopt::opt {

// minimize() with algorithm SAO and OptimizerOptions::sao = `sao` (the algorithm name and
// local_algorithm in `options` are ignored). Throws abuopt::ConfigError before any evaluation for
// invalid options, an invalid problem or starting point. Once evaluations start it never throws:
// everything else is a TerminationReason. The result's algorithm is "SAO(<surrogate>)".
OptimizationResult minimize_sao(Problem& problem, const OptimizerOptions& options, const SaoOptions& sao,
                                std::vector<double> x0 = {}, const EvaluationCallback& callback = {});

}  // namespace abuopt::opt
