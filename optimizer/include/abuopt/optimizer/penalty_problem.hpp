#pragma once
// A constrained problem in exact-L1-penalty form, for optimisers that handle bounds only (the idea
// of pagmo's `unconstrain` meta-problem): it declares no constraints and minimises
//   f(x) + w (sum_i max(0, g_i(x)) + sum_j |h_j(x)|)
// of the wrapped problem. Every evaluation keeps the wrapped problem's metrics and adds
// `objective_without_penalty` = f(x), and `g_<name>` / `h_<name>` for every constraint value, so a
// report can still show the real constraints. A failed evaluation is passed on unchanged.
//
//   StartupProfileProblem p(settings);
//   opt::PenaltyProblem pen(p, 20.0);     // p must outlive pen
//   opt::minimize(pen, bobyqa_options);
#include <memory>

#include "abuopt/optimizer/problem.hpp"

namespace abuopt::opt {

class PenaltyProblem : public Problem {
 public:
  // `inner` must outlive this object. Throws std::invalid_argument unless weight is finite and > 0.
  PenaltyProblem(Problem& inner, double weight);
  // Owns the wrapped problem.
  PenaltyProblem(std::unique_ptr<Problem> inner, double weight);

  std::string name() const override { return inner_->name(); }
  std::vector<Variable> variables() const override { return inner_->variables(); }
  Evaluation evaluate(const std::vector<double>& x) override;
  bool thread_safe() const override { return inner_->thread_safe(); }
  Evaluation evaluate_shared(const std::vector<double>& x, std::size_t concurrent) override {
    return penalise(inner_->evaluate_shared(x, concurrent));
  }
  std::size_t sample_size() const override { return inner_->sample_size(); }
  std::size_t max_sample_size() const override { return inner_->max_sample_size(); }
  bool stochastic() const override { return inner_->stochastic(); }
  Evaluation evaluate_sampled(const std::vector<double>& x, std::size_t n, std::size_t concurrent = 1) override {
    return penalise(inner_->evaluate_sampled(x, n, concurrent));
  }
  // The penalty form of an evaluation of the wrapped problem (what evaluate() does after calling
  // it): for values the wrapped problem computed elsewhere, e.g. on a validation sample.
  Evaluation penalise(Evaluation e) const;
  std::vector<double> initial_point() const override { return inner_->initial_point(); }
  std::optional<BestKnown> best_known() const override { return inner_->best_known(); }

  double weight() const { return weight_; }
  Problem& inner() { return *inner_; }

 private:
  std::unique_ptr<Problem> owned_;
  Problem* inner_;
  double weight_;
};

}  // namespace abuopt::opt
