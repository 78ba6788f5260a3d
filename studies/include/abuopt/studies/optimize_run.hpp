#pragma once
// One optimisation of the startup-profile problem as `abuopt optimize` runs it (docs/optimize.md),
// for every front end (the command, the Python module's abuopt.optimize): the problem, its penalty
// form when constraints.penalty_weight > 0 (what the optimiser then sees), the evaluation archive
// in front of it (a rerun answers stored points from it; SAO's surrogates read it), and afterwards
// the out-of-sample check of the best design against the report's final profile.
//
//   OptimizeRun run(settings, options);       // the problem (ConfigError for bad settings)
//   run.open_archive("out/archive.sqlite", "optimize", "cfg.yaml", hash);
//   opt::OptimizationResult r = run.minimize(callback);
//   if (!r.x.empty()) OutOfSampleComparison c = run.compare_out_of_sample(r);
#include <memory>
#include <optional>
#include <string>

#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/optimizer/penalty_problem.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"
#include "abuopt/studies/out_of_sample.hpp"

namespace abuopt {

class OptimizeRun {
 public:
  // Builds the problem from `settings` (ConfigError when they are invalid) and its penalty form.
  OptimizeRun(problems::StartupProfileSettings settings, opt::OptimizerOptions options);
  OptimizeRun(const OptimizeRun&) = delete;
  OptimizeRun& operator=(const OptimizeRun&) = delete;

  problems::StartupProfileProblem& problem() { return *problem_; }
  const problems::StartupProfileProblem& problem() const { return *problem_; }
  // The penalty form the optimiser sees, or null (constraints.penalty_weight == 0).
  const opt::PenaltyProblem* penalty() const { return penalised_ ? &*penalised_ : nullptr; }
  // What the optimiser sees: the problem or its penalty form (not archived).
  opt::Problem& optimised() { return penalised_ ? static_cast<opt::Problem&>(*penalised_) : *problem_; }
  // Opens the archive at `path` (":memory:": an SQLite archive in memory, nothing written) for the
  // problem's identity, checks its signature and records a metadata row (command, config as
  // given, config_hash). Once, before minimize().
  void open_archive(const std::string& path, const std::string& command, const std::string& config,
                    const std::string& config_hash);
  // The archive (open_archive first).
  opt::EvaluationArchive& archive() { return *archive_; }
  // The options minimize() uses (e.g. set options().scheduler, options().handle_sigint before it).
  opt::OptimizerOptions& options() { return options_; }
  // Evaluations of this problem stored in the archive when it was opened.
  long stored_at_start() const { return stored_at_start_; }

  // opt::minimize of the archived problem from the problem's x0 (SAO reads the archive's points);
  // without open_archive() of the problem itself.
  opt::OptimizationResult minimize(const opt::EvaluationCallback& callback = {});

  // compare_out_of_sample of the best design (r.x not empty), penalised as the optimiser saw it.
  OutOfSampleComparison compare_out_of_sample(const opt::OptimizationResult& r) const;

 private:
  std::unique_ptr<problems::StartupProfileProblem> problem_;
  std::optional<opt::PenaltyProblem> penalised_;
  opt::OptimizerOptions options_;
  std::unique_ptr<opt::EvaluationArchive> archive_;
  long stored_at_start_ = 0;
  std::optional<opt::ArchivedProblem> archived_;
};

}  // namespace abuopt
