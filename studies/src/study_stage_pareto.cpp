// Stage kind `pareto`: the front of the objective against the startup time T by the
// epsilon-constraint method, on every choice. For each bound eps_k (ascending)
//
//     minimise f(x)   subject to   T(x) <= eps_k   and the study's other constraints
//
// with the stage's optimiser, from the previous bound's best point (which meets this looser bound
// too, and is kept when the optimiser finds nothing better: the front's objective can only fall as
// eps grows) and, for the first bound, from the best design so far. The bound replaces the study's own startup-time constraint
// (absolute or relative to the baseline). Each bound is a problem of its own (the bound is part of
// the problem's identity), archived in the study's archive, so a rerun resumes. With `seeds`,
// every front point and the baseline are evaluated on those fresh samples (out of sample: the
// in-sample front is biased low, as every optimum is).
#include <cmath>
#include <limits>
#include <sstream>

#include "abuopt/common/text.hpp"
#include "study_context.hpp"

namespace abuopt::studies::detail {

namespace {

std::string bound_label(double b) {
  std::string s = format_number(b);
  for (char& ch : s)
    if (ch == '.') ch = 'p';  // pareto_T7p5
  return s;
}

double mean_ir(const opt::Evaluation& e) {
  auto it = e.metrics.find("ir_magnitude_mean");
  return it == e.metrics.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
}

}  // namespace

void run_pareto_stage(StudyContext& c, const StageSpec& stage) {
  ParetoFront& front = c.result.front;
  front.stage = stage.name;
  front.points.clear();
  const bool several = c.choices.size() > 1;
  for (ChoiceContext& ch : c.choices) {
    std::vector<double> x0 = ch.x;  // the best so far
    std::optional<std::size_t> previous;  // index of the previous bound's point (feasible)
    for (double bound : stage.pareto_bounds) {
      if (c.stop()) return;
      std::string tag = bound_label(bound);
      tag.insert(tag.begin(), 'T');
      const long remaining = c.file.max_evaluations - c.used;
      if (remaining <= 0) {
        c.result.notes.push_back("stage " + stage.name + ": the bound " + tag + " skipped for " +
                                 std::to_string(ch.balls) + " balls: the budget (budget.max_evaluations = " +
                                 std::to_string(c.file.max_evaluations) + ") is spent");
        c.log(c.result.notes.back());
        continue;
      }
      problems::StartupProfileSettings s = settings_of_choice(c.file, ch.balls, c.result.baseline.metrics);
      if (c.options.threads) s.threads = *c.options.threads;
      s.constraints.max_startup_time_s = bound;
      problems::StartupProfileProblem problem(s);
      opt::EvaluationArchive archive(c.archive_path, problem.identity());
      opt::ArchivedProblem archived(problem, archive);
      std::vector<double> least(problem.inequality_names().size(), std::numeric_limits<double>::infinity());
      OptimiserRun run = run_archived_optimiser(c, stage, stage.name + "_" + tag, ch.balls, problem, archived,
                                                remaining, x0, least);
      c.result.traces.push_back(run.trace);
      if (run.best_x.empty()) continue;
      FrontPoint p;
      p.bound_s = bound;
      p.design = design_at(ch, problem, archived,
                           (several ? "balls" + std::to_string(ch.balls) + "_" : std::string()) + "pareto_" + tag,
                           stage.name, run.best_x);
      p.feasible = feasible(p.design.in_sample);
      // a looser bound keeps the tighter bound's design when the optimiser found nothing better
      if (previous) {
        const FrontPoint& q = front.points[*previous];
        if (q.feasible && (!p.feasible || q.design.in_sample.objective < p.design.in_sample.objective)) {
          const std::vector<double> xq = q.design.x;
          p.design = design_at(ch, problem, archived, p.design.label, stage.name, xq);  // T(xq) <= the tighter bound
          p.feasible = feasible(p.design.in_sample);
        }
      }
      p.evaluations = run.trace.evaluations;
      p.archive_hits = run.trace.archive_hits;
      std::ostringstream os;
      os << "  " << tag << ": T " << format_number(std::round(p.design.profile.duration_s() * 1000) / 1000)
         << " s, mean |I_r| " << format_number(std::round(mean_ir(p.design.in_sample) * 1000) / 1000)
         << (p.feasible ? "" : " (NOT feasible)");
      c.log(os.str());
      if (p.feasible) {
        x0 = p.design.x;
        previous = front.points.size();
      }
      front.points.push_back(p);
    }
  }
  // dominance within each choice (feasible points only)
  for (FrontPoint& a : front.points) {
    a.dominated = false;
    if (!a.feasible) continue;
    for (const FrontPoint& b : front.points) {
      if (&a == &b || !b.feasible || a.design.balls != b.design.balls) continue;
      const double ta = a.design.profile.duration_s(), tb = b.design.profile.duration_s();
      const double fa = mean_ir(a.design.in_sample), fb = mean_ir(b.design.in_sample);
      if (tb <= ta && fb <= fa && (tb < ta || fb < fa)) a.dominated = true;
    }
  }
  if (stage.seeds.empty() || c.stop()) return;
  // out of sample: every front point and the baseline on the stage's fresh samples
  front.seeds = stage.seeds;
  std::vector<std::vector<double>> ir(front.points.size());
  std::vector<bool> all(front.points.size(), true);
  std::vector<double> base;
  for (std::uint64_t seed : stage.seeds) {
    for (std::size_t i = 0; i < front.points.size(); ++i) {
      if (c.stop()) return;
      FrontPoint& p = front.points[i];
      StudyContext::Fresh fr = c.fresh(p.design.balls, seed, stage.runs);
      if (i == 0) base.push_back(mean_ir(fr.baseline));
      front.runs = fr.settings.study.runs;
      fr.settings.constraints.max_startup_time_s = p.bound_s;
      const opt::Evaluation e = c.evaluate_profile(fr.settings, p.design.profile);
      ir[i].push_back(mean_ir(e));
      all[i] = all[i] && feasible(e);
    }
  }
  for (std::size_t i = 0; i < front.points.size(); ++i) {
    front.points[i].out_of_sample_ir = interval_of(ir[i]);
    front.points[i].feasible_out_of_sample = all[i];
  }
  front.baseline_out_of_sample_ir = interval_of(base);
  c.log("stage " + stage.name + ": " + std::to_string(front.points.size()) + " front points and the baseline on " +
        std::to_string(stage.seeds.size()) + " fresh samples of " + std::to_string(front.runs) + " runs");
}

}  // namespace abuopt::studies::detail
