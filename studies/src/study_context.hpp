#pragma once
// What the stages of a study share (studies/src/study_runner.cpp builds it; one file per stage
// kind: study_stage_global.cpp, study_stage_local.cpp, study_stage_replicate.cpp,
// study_stage_validate.cpp).
#include <memory>
#include <string>
#include <vector>

#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/studies/study.hpp"

namespace abuopt::studies::detail {

// One discrete choice (a ball count): its problem, archived, and where the next stage starts.
struct ChoiceContext {
  std::size_t balls = 0;
  std::unique_ptr<problems::StartupProfileProblem> problem;
  std::unique_ptr<opt::EvaluationArchive> archive;
  std::unique_ptr<opt::ArchivedProblem> archived;
  std::vector<double> x;                 // the best design so far (empty: the family's x0)
  std::optional<std::size_t> last_design;  // the best design so far: index into StudyResult::designs
  std::vector<double> least_violation;   // per constraint: the smallest g_i seen (for "cannot be met")
};

struct StudyContext {
  const StudyFile& file;
  const StudyRunOptions& options;
  StudyResult& result;
  std::string archive_path;
  long used = 0;     // optimiser evaluations so far (budget)
  long done = 0;     // progress units done
  long total = 0;    // progress units planned
  bool interrupted = false;  // an optimiser stopped on SIGINT (its own handler ran, not the caller's)
  std::vector<ChoiceContext> choices;

  void log(const std::string& line) const;
  bool stop() const;
  void tick(long n = 1);
  // A fresh sample (this seed, this run count; 0: the sampling's): the baseline evaluated on it
  // and the choice's settings on it, whose relative constraints hold against that evaluation (the
  // baseline on the same sample, not the in-sample one).
  struct Fresh {
    problems::StartupProfileSettings settings;
    opt::Evaluation baseline;
  };
  Fresh fresh(std::size_t balls, std::uint64_t seed, std::size_t runs);
  // The baseline's settings on a sample (seed, runs; 0: keep).
  problems::StartupProfileSettings baseline_sample(std::uint64_t seed, std::size_t runs) const;
  // Evaluates a profile under `s` through the archive (key: the problem identity and the profile).
  opt::Evaluation evaluate_profile(const problems::StartupProfileSettings& s, const StartupProfile& p);
  // The settings of the baseline's ABU (the abu section as given).
  problems::StartupProfileSettings baseline_settings() const;
};

// One optimiser run of a stage on one problem through its archive (an optimiser that takes bounds
// only sees the exact-penalty form), at most max_evaluations (within the stage's own), from x0
// (empty: the family's); counts the budget, the progress and the trace.
struct OptimiserRun {
  std::vector<double> best_x;  // the best feasible point (none feasible: the optimiser's last best; empty: no evaluation)
  bool feasible = false;
  StageTrace trace;
};
OptimiserRun run_archived_optimiser(StudyContext& c, const StageSpec& stage, const std::string& trace_name,
                                    std::size_t balls, problems::StartupProfileProblem& problem,
                                    opt::ArchivedProblem& archived, long max_evaluations, const std::vector<double>& x0,
                                    std::vector<double>& least_violation);
// A design of the study at x of `problem` (its in-sample evaluation from the archive).
StudyDesign design_at(const ChoiceContext& ch, problems::StartupProfileProblem& problem, opt::ArchivedProblem& archived,
                      const std::string& label, const std::string& stage, const std::vector<double>& x);

// One optimiser stage on every choice (global: from the family's x0; local: from the best so far).
void run_optimiser_stage(StudyContext& c, const StageSpec& stage, bool from_best);
void run_global_stage(StudyContext& c, const StageSpec& stage);
void run_local_stage(StudyContext& c, const StageSpec& stage);
void run_replicate_stage(StudyContext& c, const StageSpec& stage);
void run_validate_stage(StudyContext& c, const StageSpec& stage);
void run_pareto_stage(StudyContext& c, const StageSpec& stage);
// The final positions of the recommended design and the baseline over the equilibrium set (two
// balls; studies/src/study_final_positions.cpp).
void final_positions(StudyContext& c, const StudyDesign& d, std::uint64_t seed, std::size_t runs);
// The recommended design without a replicate stage: the best in-sample feasible final design.
void recommend_in_sample(StudyContext& c);

// The feasibility of an evaluation of the problem (tolerance 1e-6 on relative constraints).
bool feasible(const opt::Evaluation& e);

}  // namespace abuopt::studies::detail
