#pragma once
// The one result type of every optimiser (the idea of Ceres' Solver::Summary): why it stopped,
// the best feasible point, counts, time, the history of every evaluation, and brief/full reports.
//
// The best point found is ALWAYS returned, whatever ended the run (budget, time, callback,
// Ctrl-C, an exception inside an evaluation). A run reports success() only if it converged AND
// its best point is feasible: an optimiser that claims convergence at an infeasible point is
// reported with reason `infeasible`.
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt {

enum class TerminationReason {
  Converged,           // the algorithm's own convergence test (no finer reason given)
  ConvergedFtol,       // change of f below ftol_rel / ftol_abs
  ConvergedXtol,       // change of x below xtol_rel (or Ipopt: search direction too small)
  TargetReached,       // a feasible point with f <= target
  MaxEvaluations,      // evaluation budget used up
  MaxIterations,       // iteration limit (Ipopt)
  MaxTime,             // wall-clock (or Ipopt CPU) limit
  StoppedByCallback,   // the evaluation callback returned false
  Interrupted,         // SIGINT (Ctrl-C) or request_stop()
  EvaluationError,     // an evaluation threw an exception
  Infeasible,          // the algorithm stopped without a feasible point
  RoundoffLimited,     // NLopt: roundoff errors limited progress
  Failure,             // the algorithm failed (message says why)
};

std::string to_string(TerminationReason reason);
// Inverse of to_string; throws abuopt::ConfigError listing the valid names.
TerminationReason termination_reason_from_string(const std::string& text);
// Converged, ConvergedFtol, ConvergedXtol, TargetReached.
bool is_convergence(TerminationReason reason);

// One evaluation as the optimiser saw it.
struct EvaluationRecord {
  long index = 0;                  // 0-based order of evaluation in the run
  std::vector<double> x;           // the point evaluated (inside the bounds)
  double objective = 0.0;
  std::vector<double> inequality;  // g(x)
  std::vector<double> equality;    // h(x)
  std::map<std::string, double> metrics;
  bool ok = true;
  bool feasible = false;           // ok and max_violation <= constraint_tolerance
  double max_violation = 0.0;
  bool from_archive = false;
  bool for_gradient = false;       // a finite-difference neighbour, not a point the optimiser chose
  double wall_time_s = 0.0;        // time of this evaluation
  double elapsed_s = 0.0;          // time since the run started, at the end of this evaluation
  std::string message;
};

// What one iteration of a trust-region method (SAO) did.
enum class IterationStep {
  Accepted,              // the candidate became the centre
  Rejected,              // the candidate was no better than the centre: the centre stays
  NoPredictedReduction,  // the surrogates saw no better point in the region: no candidate
  NoModel,               // no surrogate could be fitted (e.g. every point failed)
};
std::string to_string(IterationStep step);

// One iteration of a trust-region method (SAO; sao.hpp): the numbers of its ratio test. NaN where
// the iteration did not get that far (no candidate: no actual reduction, no rho).
struct IterationRecord {
  long iteration = 0;                // 1-based
  IterationStep step = IterationStep::NoModel;
  long evaluations = 0;              // evaluations of the run at the end of the iteration
  double radius = 0.0;               // trust-region radius of the iteration (fraction of each range)
  double next_radius = 0.0;          // after the ratio test
  double predicted_reduction = std::numeric_limits<double>::quiet_NaN();  // of the merit, by the surrogates
  double actual_reduction = std::numeric_limits<double>::quiet_NaN();     // of the merit, evaluated
  double rho = std::numeric_limits<double>::quiet_NaN();                  // actual / predicted
  double noise = 0.0;                // noise level of the merit the ratio test allowed for (0: none)
  double step_length = std::numeric_limits<double>::quiet_NaN();  // |s|_inf of the candidate (1: boundary)
  double penalty = 0.0;              // penalty weight mu of the merit after the iteration
  double centre_merit = 0.0;         // merit of the centre after the iteration
  bool feasibility_phase = false;    // the merit was the violation alone
  long runs = 0;                     // the centre's metric "runs" (Monte Carlo runs; 0 without it)
  std::string surrogate;             // basis fitted, e.g. "quadratic"
  std::string forms;                 // intervening form per response, e.g. "f:l g:r"
};

struct OptimizationResult {
  std::string problem_name;
  std::string algorithm;           // as run, e.g. "AUGLAG(BOBYQA)"
  TerminationReason reason = TerminationReason::Failure;
  std::string message;             // human-readable detail of the reason

  // Best point: the feasible point with the lowest objective; if no point was feasible, the
  // point with the smallest constraint violation (feasible == false). Empty x: no evaluation.
  std::vector<double> x;
  double objective = 0.0;
  std::vector<double> inequality;
  std::vector<double> equality;
  std::map<std::string, double> metrics;
  bool feasible = false;
  double max_violation = 0.0;
  double constraint_tolerance = 0.0;

  std::vector<double> x0;          // starting point
  long evaluations = 0;            // evaluations requested (including archive hits)
  long archive_hits = 0;           // of which answered from an evaluation archive
  // Sum of the sample sizes of the evaluations (Monte Carlo runs; problem.hpp sample_size()):
  // the simulations they stand for (archive hits included); 0 for a problem that is not sampled.
  long samples = 0;
  long failed_evaluations = 0;     // ok == false
  long gradient_evaluations = 0;   // of which finite-difference neighbours
  long repeated_requests = 0;      // in-run repeats answered from memory (not counted above)
  long clipped_requests = 0;       // requests outside the bounds that were clipped into them
  long iterations = 0;             // Ipopt and SAO iterations; 0 for NLopt
  double wall_time_s = 0.0;

  std::vector<std::string> variable_names;
  std::vector<std::string> inequality_names;
  std::vector<std::string> equality_names;
  std::vector<EvaluationRecord> history;  // every evaluation, in order (if keep_history)
  // SAO: one record per iteration (radius, rho, predicted and actual reduction, noise, runs); empty
  // for the other algorithms. `iterations` above is their count for SAO.
  std::vector<IterationRecord> iteration_records;

  // Converged and the best point is feasible.
  bool success() const;
  // A feasible point is available (whatever the reason).
  bool has_feasible_point() const { return feasible && !x.empty(); }

  // One line: "SLSQP on hs071: converged_ftol, f = 17.014017 (feasible), 131 evaluations
  // (0 from archive), 0.004 s".
  std::string brief_report() const;
  // Several lines: reason and message, counts, the best point variable by variable, the
  // constraints with their values, the metrics.
  std::string full_report() const;
};

}  // namespace abuopt::opt
