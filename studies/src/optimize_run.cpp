// One optimisation as `abuopt optimize` runs it (optimize_run.hpp).
#include "abuopt/studies/optimize_run.hpp"

#include <utility>

namespace abuopt {

OptimizeRun::OptimizeRun(problems::StartupProfileSettings settings, opt::OptimizerOptions options)
    : problem_(std::make_unique<problems::StartupProfileProblem>(std::move(settings))), options_(std::move(options)) {
  const double weight = problem_->settings().constraints.penalty_weight;
  if (weight > 0) penalised_.emplace(*problem_, weight);
}

void OptimizeRun::open_archive(const std::string& path, const std::string& command, const std::string& config,
                               const std::string& config_hash) {
  archived_.reset();
  archive_ = std::make_unique<opt::EvaluationArchive>(path, problem_->identity());
  stored_at_start_ = archive_->count();
  archive_->record_metadata(command, config, config_hash);
  archived_.emplace(optimised(), *archive_);
}

opt::OptimizationResult OptimizeRun::minimize(const opt::EvaluationCallback& callback) {
  if (!archived_) return opt::minimize(optimised(), options_, {}, callback);
  opt::OptimizerOptions o = options_;
  o.sao.archive = archive_.get();  // SAO: archived points inform its surrogates
  return opt::minimize(*archived_, o, {}, callback);
}

OutOfSampleComparison OptimizeRun::compare_out_of_sample(const opt::OptimizationResult& r) const {
  return abuopt::compare_out_of_sample(*problem_, r, penalty());
}

}  // namespace abuopt
