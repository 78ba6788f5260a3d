#pragma once
// Two objectives by pagmo2's NSGA-II or MOEA/D (optimizer/src/pagmo_nsga2.cpp): minimise the problem's
// objective and one of its metrics at once, under its constraints, through the same evaluation
// driver as minimize() (budget, evaluation archive and resumption, history, seeds):
//
//   opt::OptimizerOptions o;  o.max_evaluations = 400;  o.seed = 3;  o.population = 20;
//   opt::TwoObjectiveResult r = opt::minimize_two_objectives(problem, "startup_time_s", o);
//   double hv = opt::hypervolume_2d(r.front_objectives(), {f_ref, t_ref});
//
// Constraints by Deb's feasibility rules (as pagmo_adapter.cpp): an infeasible point is dominated
// by every feasible one and ranked by its violation. Both pagmo algorithms are unconstrained; the
// rules are folded into the two fitness values (1e30 (1 + violation) in both), so MOEA/D's
// Tchebycheff value of an infeasible point is above every feasible one's and grows with the
// violation (a penalty that ranks as the rules do, as long as feasible objectives stay << 1e30).
// NSGA-II's generations go as batches through Problem::evaluate_batch (pagmo's member_bfe);
// MOEA/D (pass TwoObjectiveMethod::Moead) is steady-state in pagmo 2.18 (no batch evaluator) and
// evaluates one point at a time. MOEA/D's Tchebycheff decomposition does not normalise the
// objectives: it suits two objectives of similar scale (mean |I_r| ~ 10-25 against T ~ 5-25 s).
// The front is the non-dominated set of every feasible evaluation of the run (not only of the
// last population).
#include <string>
#include <utility>
#include <vector>

#include "abuopt/optimizer/minimize.hpp"
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

enum class TwoObjectiveMethod { Nsga2, Moead };
std::string to_string(TwoObjectiveMethod m);  // "pagmo_nsga2", "pagmo_moead"
// "pagmo_nsga2" / "nsga2", "pagmo_moead" / "moead"; else ConfigError naming key and value.
TwoObjectiveMethod two_objective_method_from_string(const std::string& text, const std::string& key);
// ConfigError naming population_key or budget_key unless the population (0: the default 20) suits
// the method (NSGA-II: a multiple of 4, at least 8; MOEA/D: at least 4) and the budget holds one.
void check_two_objective_population(TwoObjectiveMethod method, long population, long max_evaluations,
                                    const std::string& population_key, const std::string& budget_key);

// ConfigError before any evaluation: second_objective empty, population (default 20) invalid for
// the method (check_two_objective_population), or a budget below one population. A point whose
// evaluation lacks the metric counts as failed. options.algorithm is not used (the method is).
// callback: after every evaluation, as minimize()'s; returning false stops the run
// (StoppedByCallback; the front is made of what was evaluated).
TwoObjectiveResult minimize_two_objectives(Problem& problem, const std::string& second_objective,
                                           const OptimizerOptions& options, std::vector<double> x0 = {},
                                           TwoObjectiveMethod method = TwoObjectiveMethod::Nsga2,
                                           const EvaluationCallback& callback = {});

// The non-dominated subset of points (both minimised), sorted by the first coordinate.
std::vector<std::pair<double, double>> non_dominated_2d(std::vector<std::pair<double, double>> points);
// Area dominated by the points and bounded by the reference point (points not strictly better than
// the reference in both coordinates contribute nothing).
double hypervolume_2d(const std::vector<std::pair<double, double>>& points, std::pair<double, double> reference);

}  // namespace abuopt::opt
