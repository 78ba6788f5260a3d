#pragma once
// Options of SAO, the sequential approximate optimiser (sao.hpp; every key in docs/sao.md).
// They live in their own header so that OptimizerOptions can carry them: with
// `algorithm: SAO`, minimize() runs SAO with OptimizerOptions::sao.
//
//   optimizer:
//     algorithm: SAO
//     sao: {initial_radius: 0.2, doe_points_factor: 2}
#include <optional>
#include <string>
#include <vector>

#include "abuopt/common/config_fields.hpp"
#include "abuopt/common/yaml_reader.hpp"

namespace abuopt::opt {

class EvaluationArchive;  // evaluation_archive.hpp

// The choices of SAO, parsed once when read. to_string gives the YAML spelling (snake_case, e.g.
// "pure_quadratic"); <name>_from_string is its inverse and throws abuopt::ConfigError naming `key`,
// the value and the valid spellings ("sao.doe = sobol: must be one of: auto, koshal, ...").
enum class SurrogateKind { Auto, Linear, Interactions, PureQuadratic, Quadratic, Kriging };
enum class DoeKind { Auto, Koshal, Axial, CentralComposite, Lhs };
enum class InterveningKind { Auto, Linear, Reciprocal, Exponential };
enum class SubproblemSolver { Slsqp, Cobyla };

std::string to_string(SurrogateKind kind);
std::string to_string(DoeKind kind);
std::string to_string(InterveningKind kind);
std::string to_string(SubproblemSolver solver);
SurrogateKind surrogate_kind_from_string(const std::string& text, const std::string& key = "sao.surrogate");
DoeKind doe_kind_from_string(const std::string& text, const std::string& key = "sao.doe");
InterveningKind intervening_kind_from_string(const std::string& text, const std::string& key = "sao.intervening");
SubproblemSolver subproblem_solver_from_string(const std::string& text,
                                               const std::string& key = "sao.subproblem_solver");
// The spellings of every enumerator, in declaration order.
const std::vector<std::string>& surrogate_kind_names();
const std::vector<std::string>& doe_kind_names();
const std::vector<std::string>& intervening_kind_names();
const std::vector<std::string>& subproblem_solver_names();

// SAO's global phase (docs/sao.md, "Global phase"): before the local trust region, a
// space-filling design over the whole box (a maximin Latin hypercube of `points` points besides
// the start), then `iterations` infill points, each where the constrained expected improvement of
// kriging models of the objective and of every constraint is largest; the trust region then starts
// from the incumbent (the best point that satisfies the constraints). With `restart`, a trust
// region that converges with budget left is followed by n + 1 more infill points and a new trust
// region from the incumbent, until the budget is spent. With `polish` (off by default), on a
// sampled problem each trust region that shrinks below 1e-3 of the ranges (or stalls) ends in a
// compass search.
//
// When it runs (`mode`): auto (default) on a stochastic problem (Problem::stochastic(): a Monte
// Carlo, a noisy benchmark) or when `points` is given, else not; always; never.
// Its size: `points` 0 and `iterations` 0 (default) are automatic, 4 (n + 1) each, at most a sixth
// of max_evaluations each (and at least 2 points).
//
//   sao: {global_phase: {points: 20, iterations: 20}}
enum class GlobalPhaseMode { Auto, Always, Never };
struct SaoGlobalPhase {
  GlobalPhaseMode mode = GlobalPhaseMode::Auto;
  int points = 0;      // 0 (automatic) or >= 2
  int iterations = 0;  // >= 0; with points > 0 as given, else automatic
  bool restart = true;  // restart from the incumbent after convergence with budget left
  // On a sampled problem (a Monte Carlo estimate: piecewise constant in the design under common
  // random numbers), a trust region that shrinks below 1e-3 of the ranges or stalls hands over to
  // a compass search on the exact merit that snaps to the bounds (docs/sao.md, "Polish on a
  // sampled problem"). Off by default: it lowers the in-sample values but, measured on the large
  // comparison, not the out-of-sample ones.
  bool polish = false;

  // Whether the phase runs on a problem (stochastic: Problem::stochastic()).
  bool enabled(bool stochastic) const {
    return mode == GlobalPhaseMode::Always || (mode == GlobalPhaseMode::Auto && (stochastic || points > 0));
  }
  // The design's point count and the infill count for n variables and a budget (0: none).
  int design_points(int n, long max_evaluations) const;
  int infill_points(int n, long max_evaluations) const;
};
const std::vector<std::string>& global_phase_mode_names();
std::string to_string(GlobalPhaseMode mode);

// SAO's sample size schedule for sampled problems (docs/sao.md, "Adaptive sample size"; the
// problem must support Problem::evaluate_sampled): iteration k evaluates at
//   n_k = clamp(max(n_floor, n0 2^ceil(log2((r0 / r_k)^p))), n0, n_max),  never below n_{k-1},
// r0 = initial_radius, r_k the radius; n_floor doubles (from n_k) after a failed step whose
// shortfall is within the noise of a difference of two merits (the ratio test could not tell
// noise from a real change). When n grows the centre is evaluated again at the new size; values at
// smaller sizes stay in the fits, shifted by the change seen at that centre and weighted n_i / n.
// initial 0: off (every evaluation at the problem's own sample size).
//
//   sao: {samples: {initial: 64, max: 256, exponent: 2}}
struct SaoSampling {
  int initial = 0;        // n0: 0 (off) or >= 1
  int max = 0;            // n_max: 0, the problem's max_sample_size(); else >= initial
  double exponent = 2.0;  // p in [0, 8]
  bool enabled() const { return initial > 0; }
};

struct SaoOptions {
  // Surrogate of the objective and of every constraint: auto, linear, interactions,
  // pure_quadratic, quadratic, kriging. auto: the richest of quadratic > pure_quadratic > linear
  // that the points of the region support.
  SurrogateKind surrogate = SurrogateKind::Auto;
  // Candidate DOE in the region: auto, koshal, axial, central_composite, lhs.
  // auto (with doe_points 0, doe_points_factor 1 and a response surface): no design per region;
  // every evaluated point joins the fit and points are added only where the fit zone lacks spread
  // (see geometry_spread): about n+1 points at the start, few afterwards. Otherwise (an explicit
  // design, a point count, a factor > 1 or kriging) each region is filled with the design:
  // koshal for a linear surrogate, axial (centre and +-r on each axis) then the corners of a
  // central composite design for the quadratic ones, lhs for kriging.
  DoeKind doe = DoeKind::Auto;
  // Points wanted in the region before fitting (designs per region only); 0: automatic (linear:
  // n+1, interactions: its term count, pure_quadratic / auto / kriging: 2n+1, quadratic:
  // (n+1)(n+2)/2).
  int doe_points = 0;
  // Multiplies the automatic count (doe_points == 0) and, above 1, selects designs per region.
  // Noisy problems: 2 (least squares over about twice as many points as terms smooths the noise
  // instead of interpolating it). In [1, 10].
  double doe_points_factor = 1.0;
  // A DOE candidate within this distance (infinity norm, local coordinates where the region is
  // [-1,1]^n) of a known point is covered by it and not evaluated. In (0, 1].
  double reuse_distance = 0.3;
  // Fit also on the points of the neighbourhood |s|_inf <= neighbourhood (>= 1; 1: region only),
  // weighted 1/|s|_inf^4 (the fit zone). In [1, 10].
  double neighbourhood = 4.0;
  // Geometry of the fit zone without a design per region (doe auto): a point is added on the
  // region's boundary along the weakest direction while the weighted covariance of the zone's
  // local coordinates has its smallest eigenvalue below geometry_spread^2 (or the zone has fewer
  // than n+1 points). In (0, 1).
  double geometry_spread = 0.2;

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

  // Intervening variables of the surrogates (sao_intervening.hpp): each response is a polynomial
  // in y_i = x_i (linear), 1/x_i (reciprocal) or x_i^p_i with p_i fitted in [-3, 3] (exponential)
  // of the original variables x; auto: per response and iteration, linear unless reciprocal or
  // exponential has a much smaller weighted leave-one-out (PRESS) error of a linear model on the
  // fit zone (1/4, resp. 1/50 of it; docs/sao.md). A variable whose lower
  // bound is <= 0 always stays linear. Response surfaces only (kriging: reciprocal if asked, else
  // linear). auto, linear, reciprocal, exponential.
  InterveningKind intervening = InterveningKind::Auto;
  // Overrides for the objective and for every constraint (none: as `intervening`).
  std::optional<InterveningKind> intervening_objective;
  std::optional<InterveningKind> intervening_constraints;

  // Zeroth-order additive correction (Dakota's `correction additive zeroth_order`): every
  // surrogate is shifted to match the true value at the centre.
  bool correction = true;
  // An accepted step shorter than short_step * r (infinity norm) also shrinks the region by
  // shrink_factor: the surrogates say the optimum is near, and a smaller region refines them
  // (without it a biased model creeps in ever smaller steps with rho ~ 1). 0: off. In [0, 1).
  double short_step = 0.1;

  // Noise tolerance of the ratio test (kappa): the merit's noise level sigma is estimated from the
  // residuals of the least-squares surrogates (docs/sao.md); a step whose predicted reduction is
  // at most kappa * sigma does not shrink the region when it fails, and an accepted step whose
  // shortfall (predicted - actual) is at most kappa * sigma does not either. 0: off (the classical
  // ratio test). In [0, 100].
  double noise_tolerance = 1.0;
  // Noise detected from the data (docs/sao.md): after two failed steps in a row the centre's
  // neighbourhood is probed by four evaluations on a segment; if their second differences at two
  // step lengths say the noise is comparable with the predicted reduction, the run switches to regression designs (twice the automatic point count,
  // as doe_points_factor 2) and to a maximum-likelihood nugget for kriging. false: never.
  bool noise_detection = true;
  // Stop on noise (docs/sao.md, "Stop when the rest is noise"): once the objective's noise level
  // sigma is known (confirmed from the fits or measured by the probe), the run ends when the best
  // feasible objective improved by less than noise_stop * sigma over the last noise_stop_window
  // evaluations of the trust region (restarts included); without it a noisy run spends its whole
  // budget on improvements the noise cannot tell apart. 0: off. In [0, 100].
  double noise_stop = 2.0;
  // The window of that test in evaluations; 0: automatic, 10 (n + 1).
  int noise_stop_window = 0;

  // Initial exact-penalty weight mu; 0: automatic, 10 max(1, |f(x0)|) on a stochastic problem,
  // 1e-3 max(1, |f(x0)|) on a deterministic one (the multiplier estimates raise it).
  double penalty_initial = 0.0;
  // mu >= penalty_multiplier_factor * max |lambda| (estimated multipliers); >= 1.
  double penalty_multiplier_factor = 2.0;

  // Stall test: no improvement of the centre's merit by more than
  // stall_tolerance * max(1, |phi|) for stall_iterations iterations.
  int stall_iterations = 8;       // >= 1
  double stall_tolerance = 1e-8;  // >= 0

  // Sub-problem solver: slsqp (NLopt SLSQP, surrogate gradients) or cobyla (NLopt COBYLA).
  SubproblemSolver subproblem_solver = SubproblemSolver::Slsqp;
  int subproblem_max_evaluations = 500;  // per start; >= 10
  // Kriging nugget (relative to the process variance); raise it (e.g. 1e-2) for noisy problems.
  double kriging_nugget = 1e-8;

  // Space-filling design and expected-improvement infill before the trust region (off by default).
  SaoGlobalPhase global_phase;

  // Sample size that follows the need (sampled problems; off by default).
  SaoSampling samples;

  // Points of this archive (same problem id) inform the surrogates without being evaluated
  // again. Not read from YAML; not owned; may be null.
  const EvaluationArchive* archive = nullptr;

  // Throws abuopt::ConfigError naming the key, the value and the rule
  // ("sao.min_radius = 0: must be in (0, initial_radius = 0.1]"); `prefix` is the section's path.
  void validate(const std::string& prefix = "sao") const;
};

// The one field list of the `sao:` section (config_fields.hpp): reading, writing and the single-
// value rules come from it; validate() adds the rules that relate keys.
void describe_fields(FieldArchive& a, SaoOptions& o);
void describe_fields(FieldArchive& a, SaoGlobalPhase& o);
void describe_fields(FieldArchive& a, SaoSampling& o);

// Reads the keys of a `sao:` section (pass root.child("sao")); absent keys keep their defaults,
// unknown keys are errors (finish() is called), then validate().
SaoOptions read_sao_options(YamlReader& section);
// The section as YAML (every key; read_sao_options of it gives the same options).
std::string to_yaml(const SaoOptions& o);

}  // namespace abuopt::opt
