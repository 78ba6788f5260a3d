#pragma once
// Two objectives by pagmo2's NSGA-II (optimizer/src/pagmo_nsga2.cpp): minimise the problem's
// objective and one of its metrics at once, under its constraints, through the same evaluation
// driver as minimize() (budget, evaluation archive and resumption, history, seeds):
//
//   opt::OptimizerOptions o;  o.max_evaluations = 400;  o.seed = 3;  o.population = 20;
//   opt::TwoObjectiveResult r = opt::minimize_two_objectives(problem, "startup_time_s", o);
//   double hv = opt::hypervolume_2d(r.front_objectives(), {f_ref, t_ref});
//
// Constraints by Deb's feasibility rules (as pagmo_adapter.cpp): an infeasible point is dominated
// by every feasible one and ranked by its violation. Generations go as batches through
// Problem::evaluate_batch (pagmo's member_bfe). The front is the non-dominated set of every
// feasible evaluation of the run (not only of the last population).
#include <string>
#include <utility>
#include <vector>

#include "abuopt/optimizer/optimization_result.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt {

struct TwoObjectiveResult {
  // The run as minimize() reports it (history of every evaluation; best point by the first objective).
  OptimizationResult run;
  std::string second_objective;        // the metric minimised beside the objective
  std::vector<std::size_t> front;      // indices into run.history, sorted by the first objective
  // (objective, metric) of each front point, in front order.
  std::vector<std::pair<double, double>> front_objectives() const;
};

// ConfigError before any evaluation: second_objective empty, population (default 20; NSGA-II needs
// a multiple of 4, at least 8) invalid, or a budget below one population. A point whose evaluation
// lacks the metric counts as failed.
TwoObjectiveResult minimize_two_objectives(Problem& problem, const std::string& second_objective,
                                           const OptimizerOptions& options, std::vector<double> x0 = {});

// The non-dominated subset of points (both minimised), sorted by the first coordinate.
std::vector<std::pair<double, double>> non_dominated_2d(std::vector<std::pair<double, double>> points);
// Area dominated by the points and bounded by the reference point (points not strictly better than
// the reference in both coordinates contribute nothing).
double hypervolume_2d(const std::vector<std::pair<double, double>>& points, std::pair<double, double> reference);

}  // namespace abuopt::opt
