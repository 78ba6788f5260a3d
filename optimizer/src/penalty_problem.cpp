// The exact-L1-penalty form of a constrained problem (penalty_problem.hpp).
#include "abuopt/optimizer/penalty_problem.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace abuopt::opt {

PenaltyProblem::PenaltyProblem(Problem& inner, double weight) : inner_(&inner), weight_(weight) {
  if (!(std::isfinite(weight) && weight > 0))
    throw std::invalid_argument("PenaltyProblem: weight " + format_number(weight) + " must be finite and > 0");
}

PenaltyProblem::PenaltyProblem(std::unique_ptr<Problem> inner, double weight)
    : PenaltyProblem(*inner, weight) {
  owned_ = std::move(inner);
}

Evaluation PenaltyProblem::evaluate(const std::vector<double>& x) { return penalise(inner_->evaluate(x)); }

Evaluation PenaltyProblem::penalise(Evaluation e) const {
  if (!e.ok) return e;
  e.metrics["objective_without_penalty"] = e.objective;
  const std::vector<std::string> g_names = inner_->inequality_names();
  const std::vector<std::string> h_names = inner_->equality_names();
  check_evaluation_shape(g_names.size(), h_names.size(), e);
  double penalty = 0;
  for (std::size_t i = 0; i < e.inequality.size(); ++i) {
    e.metrics["g_" + g_names[i]] = e.inequality[i];
    penalty += std::max(0.0, e.inequality[i]);
  }
  for (std::size_t j = 0; j < e.equality.size(); ++j) {
    e.metrics["h_" + h_names[j]] = e.equality[j];
    penalty += std::fabs(e.equality[j]);
  }
  e.objective += weight_ * penalty;
  e.inequality.clear();
  e.equality.clear();
  return e;
}

}  // namespace abuopt::opt
