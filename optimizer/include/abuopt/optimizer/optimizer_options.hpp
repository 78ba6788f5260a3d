#pragma once
// Options of every optimiser run (the idea of Ceres' Solver::Options: one plain struct, commented
// defaults, a validity check). Read from the YAML section `optimizer:` by read_optimizer_options.
//
//   optimizer:
//     algorithm: slsqp            # see docs/optimizers.md or algorithm_names()
//     max_evaluations: 500
//     finite_difference: central
#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/optimizer/sao_options.hpp"

namespace abuopt::opt {

class EvaluationScheduler;  // evaluation_scheduler.hpp

enum class FiniteDifference { Forward, Central };
std::string to_string(FiniteDifference kind);  // "forward", "central"
// Inverse of to_string; throws abuopt::ConfigError naming `key`, the value and the valid names.
FiniteDifference finite_difference_from_string(const std::string& text,
                                               const std::string& key = "optimizer.finite_difference");

struct OptimizerOptions {
  // Algorithm name, case-insensitive (COBYLA, BOBYQA, SLSQP, IPOPT, SAO, ...; algorithm_names()).
  std::string algorithm = "cobyla";
  // Local optimiser for AUGLAG and MLSL_LDS, and the one a bound-only local algorithm is wrapped
  // around when the problem has constraints. Empty: BOBYQA (SBPLX for one variable).
  std::string local_algorithm;

  // Budget of evaluations the optimiser may request (> 0). Answers from an evaluation archive
  // count (so a resumed run stops where the uninterrupted run would have); a repeat of a point
  // already evaluated in the same run is answered from memory and does not count.
  long max_evaluations = 1000;
  // Wall-clock limit in seconds; 0: none.
  double max_time_s = 0.0;
  // Iteration limit for Ipopt (max_iter); 0: Ipopt's default (3000). NLopt has no iterations.
  long max_iterations = 0;

  // Stop when a step changes every x_i by less than xtol_rel * |x_i| (NLopt: on x / scale, with
  // an absolute floor of 0.01 * xtol_rel so that a variable converging to 0 can stop); 0: off.
  double xtol_rel = 1e-6;
  // Stop when a step changes f by less than ftol_rel * |f|; 0: off. Ipopt: its `tol`.
  double ftol_rel = 1e-8;
  // Stop when a step changes f by less than ftol_abs; 0: off.
  double ftol_abs = 0.0;
  // Stop as soon as a feasible point has f <= target; unset: no target.
  std::optional<double> target;

  // A point is feasible when every g_i <= tol and every |h_j| <= tol.
  double constraint_tolerance = 1e-6;

  // Finite-difference gradients (gradient-based algorithms and Ipopt): forward costs n extra
  // evaluations per gradient, central 2n and is more accurate.
  FiniteDifference finite_difference = FiniteDifference::Forward;
  // Relative step h: the step for x_i is h * max(|x_i|, scale_i). 0: sqrt(machine epsilon)
  // (1.5e-8) for forward, cbrt(machine epsilon) (6.1e-6) for central. Noisy objectives (Monte
  // Carlo) need a step well above the noise, e.g. 1e-3.
  double fd_relative_step = 0.0;

  // Seed of the stochastic algorithms (CRS2_LM, ISRES, ESCH, MLSL_LDS, the PAGMO_* methods); the
  // same seed gives the same run.
  unsigned long seed = 1;
  // Population of CRS2_LM, ISRES, ESCH and the PAGMO_* methods, and the number of starts per
  // MLSL_LDS iteration; 0: the algorithm's default.
  long population = 0;
  // First step of the derivative-free local algorithms as a fraction of each variable's range;
  // 0: NLopt's own choice.
  double initial_step = 0.0;

  // Ipopt print_level (0 = silent, 5 = Ipopt's usual output).
  int print_level = 0;
  // Install a SIGINT (Ctrl-C) handler for the run: the run stops after the current evaluation
  // and returns the best point so far (reason `interrupted`). The previous handler is restored.
  bool handle_sigint = true;
  // Keep every evaluation in OptimizationResult::history.
  bool keep_history = true;

  // Evaluation concurrency (evaluation_scheduler.hpp): independent points (a design of
  // experiments, finite-difference neighbours) are evaluated this many at once when the problem
  // is thread_safe(); 0: all hardware threads; 1: one after another. Results, history and
  // archive never depend on it (only wall times do).
  std::size_t evaluation_threads = 0;
  // Where batches run instead of threads (e.g. MPI ranks: abuopt::parallel); null: threads as above.
  // Not a config key.
  std::shared_ptr<EvaluationScheduler> scheduler;

  // Settings of SAO, used when algorithm is SAO (docs/sao.md); ignored otherwise.
  SaoOptions sao;

  // Throws abuopt::ConfigError naming the key, the value and the rule
  // ("optimizer.max_evaluations = 0: must be > 0"); unknown algorithm names list the valid ones.
  void validate() const;
};

// Reads the keys of an `optimizer:` section (pass root.child("optimizer")); absent keys keep their
// defaults, unknown keys are errors (the section's finish() is called), then validate().
// SAO's settings come from the section's own `sao:` key (optimizer: {algorithm: SAO, sao: {...}})
// or, for a config that keeps them elsewhere (e.g. a top-level `sao:`), from `sao_section`
// (finish() is called on it too); giving both, or either with another algorithm, is an error.
OptimizerOptions read_optimizer_options(YamlReader& section, YamlReader* sao_section = nullptr);

// The one field list of the `optimizer:` section (config_fields.hpp), `sao` nested when the
// algorithm is SAO (reading it is read_optimizer_options' job: it may come from two places).
void describe_fields(FieldArchive& a, OptimizerOptions& o);
// The section as YAML (read_optimizer_options of it gives the same options).
std::string to_yaml(const OptimizerOptions& o);

}  // namespace abuopt::opt
