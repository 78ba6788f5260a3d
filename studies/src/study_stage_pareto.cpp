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
//
// With `method: nsga2` or `moead` instead: per choice one run of pagmo's NSGA-II / MOEA/D
// (opt::minimize_two_objectives) on the objective and T at once, from the best design so far and
// seeded random designs, budget optimizer.max_evaluations (within what the study's budget has
// left), the study's own bound on T dropped (T is the second objective). The front is the run's
// non-dominated feasible evaluations; at most `points` of them are kept, spread evenly over T
// (the shortest and the longest always), each a design `pareto_T<its T>`, its bound_s its own T,
// and checked on the seeds as above.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include "abuopt/common/text.hpp"
#include "abuopt/optimizer/multi_objective.hpp"
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

// Indices of at most k of n points sorted by T, spread evenly (the first and the last always).
std::vector<std::size_t> spread(std::size_t n, std::size_t k) {
  std::vector<std::size_t> out;
  if (n <= k) {
    for (std::size_t i = 0; i < n; ++i) out.push_back(i);
    return out;
  }
  for (std::size_t j = 0; j < k; ++j) {
    const auto i = static_cast<std::size_t>(std::lround(static_cast<double>(j) * static_cast<double>(n - 1) /
                                                        static_cast<double>(k - 1)));
    if (out.empty() || out.back() != i) out.push_back(i);
  }
  return out;
}

// method nsga2 / moead: one population run per choice (see the file's head).
void run_population_fronts(StudyContext& c, const StageSpec& stage, bool several) {
  ParetoFront& front = c.result.front;
  const bool moead = stage.pareto_method == "moead";
  const char* name = moead ? "MOEA/D" : "NSGA-II";
  for (ChoiceContext& ch : c.choices) {
    if (!ch.active) continue;
    if (c.stop()) return;
    const long remaining = c.file.max_evaluations - c.used;
    if (remaining < stage.pareto_population) {
      c.result.notes.push_back("stage " + stage.name + " skipped for " + ch.label + ": the budget (budget.max_evaluations = " +
                               std::to_string(c.file.max_evaluations) + ") has " + std::to_string(std::max(0L, remaining)) +
                               " evaluations left, fewer than one population (" +
                               std::to_string(stage.pareto_population) + ")");
      c.log(c.result.notes.back());
      continue;
    }
    problems::StartupProfileSettings s = settings_of_choice(c.file, ch.index, c.result.baseline.metrics);
    if (c.options.threads) s.threads = *c.options.threads;
    s.constraints.max_startup_time_s.reset();  // T is the second objective
    problems::StartupProfileProblem problem(s);
    if (c.options.runner) problem.set_monte_carlo_runner(c.options.runner);
    opt::EvaluationArchive archive(c.archive_path, problem.identity());
    opt::ArchivedProblem archived(problem, archive);
    opt::OptimizerOptions o = stage.optimizer;
    o.max_evaluations = std::min(o.max_evaluations, remaining);
    o.population = stage.pareto_population;

    StageTrace tr;
    tr.stage = stage.name;
    tr.choice = ch.label;
    tr.balls = ch.balls;
    double best = std::numeric_limits<double>::infinity();
    const opt::EvaluationCallback cb = [&](const opt::Progress& pr) {
      const opt::EvaluationRecord& rec = pr.last;
      tr.objective.push_back(rec.ok ? rec.objective : std::numeric_limits<double>::quiet_NaN());
      if (rec.feasible && rec.objective < best) best = rec.objective;
      tr.best_feasible.push_back(std::isfinite(best) ? best : std::numeric_limits<double>::quiet_NaN());
      c.tick();
      return !c.stop();
    };
    c.log("stage " + stage.name + " (" + choice_name(c.file.choices[ch.index]) + "): " + name + " (population " +
          std::to_string(o.population) + "), " + std::to_string(o.max_evaluations) +
          " evaluations on the objective and T at once, from the best so far");
    const opt::TwoObjectiveResult r = opt::minimize_two_objectives(
        archived, "startup_time_s", o, ch.x, moead ? opt::TwoObjectiveMethod::Moead : opt::TwoObjectiveMethod::Nsga2,
        cb);
    c.used += r.run.evaluations;
    if (r.run.reason == opt::TerminationReason::Interrupted) c.interrupted = true;
    tr.algorithm = r.run.algorithm;
    tr.reason = to_string(r.run.reason);
    tr.evaluations = r.run.evaluations;
    tr.archive_hits = r.run.archive_hits;
    c.result.evaluations += r.run.evaluations;
    c.result.archive_hits += r.run.archive_hits;
    c.result.traces.push_back(tr);

    // r.front is sorted by the objective, so by T descending: keep at most `points`, by T ascending
    std::vector<std::size_t> by_t(r.front.rbegin(), r.front.rend());
    const std::vector<std::size_t> kept = spread(by_t.size(), stage.pareto_points);
    std::set<std::string> labels;
    for (std::size_t j : kept) {
      const std::vector<double>& x = r.run.history[by_t[j]].x;
      FrontPoint p;
      p.bound_s = problem.startup_time_s(x);
      std::string base = bound_label(std::round(p.bound_s * 100) / 100);
      base.insert(base.begin(), 'T');  // (not "T" + ...: GCC 12 flags that as -Wrestrict)
      std::string tag = base;
      for (int k = 2; labels.count(tag); ++k) {
        tag = base;
        tag.push_back('_');
        tag.append(std::to_string(k));
      }
      labels.insert(tag);
      p.design = design_at(ch, problem, archived, (several ? ch.label + "_" : std::string()) + "pareto_" + tag,
                           stage.name, x);
      p.feasible = feasible(p.design.in_sample);
      p.evaluations = r.run.evaluations;
      p.archive_hits = r.run.archive_hits;
      front.points.push_back(p);
    }
    std::ostringstream os;
    os << "  " << name << ": " << r.front.size() << " non-dominated feasible designs in " << r.run.evaluations
       << " evaluations; kept " << kept.size();
    if (!kept.empty())
      os << ", T " << format_number(std::round(front.points[front.points.size() - kept.size()].bound_s * 100) / 100)
         << " - " << format_number(std::round(front.points.back().bound_s * 100) / 100) << " s";
    c.log(os.str());
  }
}

}  // namespace

void run_pareto_stage(StudyContext& c, const StageSpec& stage) {
  ParetoFront& front = c.result.front;
  front.stage = stage.name;
  front.method = stage.pareto_method;
  front.points.clear();
  std::size_t active = 0;
  for (const ChoiceContext& ch : c.choices) active += ch.active;
  const bool several = active > 1;
  if (stage.pareto_method != "epsilon_constraint") run_population_fronts(c, stage, several);
  for (ChoiceContext& ch : c.choices) {
    if (stage.pareto_method != "epsilon_constraint") break;
    if (!ch.active) continue;
    std::vector<double> x0 = ch.x;  // the best so far
    std::optional<std::size_t> previous;  // index of the previous bound's point (feasible)
    for (double bound : stage.pareto_bounds) {
      if (c.stop()) return;
      std::string tag = bound_label(bound);
      tag.insert(tag.begin(), 'T');
      const long remaining = c.file.max_evaluations - c.used;
      if (remaining <= 0) {
        c.result.notes.push_back("stage " + stage.name + ": the bound " + tag + " skipped for " +
                                 ch.label + ": the budget (budget.max_evaluations = " +
                                 std::to_string(c.file.max_evaluations) + ") is spent");
        c.log(c.result.notes.back());
        continue;
      }
      problems::StartupProfileSettings s = settings_of_choice(c.file, ch.index, c.result.baseline.metrics);
      if (c.options.threads) s.threads = *c.options.threads;
      s.constraints.max_startup_time_s = bound;
      problems::StartupProfileProblem problem(s);
      if (c.options.runner) problem.set_monte_carlo_runner(c.options.runner);
      opt::EvaluationArchive archive(c.archive_path, problem.identity());
      opt::ArchivedProblem archived(problem, archive);
      std::vector<double> least(problem.inequality_names().size(), std::numeric_limits<double>::infinity());
      OptimiserRun run = run_archived_optimiser(c, stage, stage.name + "_" + tag, &ch, problem, archived,
                                                remaining, x0, least);
      c.result.traces.push_back(run.trace);
      if (run.best_x.empty()) continue;
      FrontPoint p;
      p.bound_s = bound;
      p.design = design_at(ch, problem, archived,
                           (several ? ch.label + "_" : std::string()) + "pareto_" + tag,
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
      if (&a == &b || !b.feasible || a.design.choice != b.design.choice) continue;
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
      StudyContext::Fresh fr = c.fresh(p.design.choice, seed, stage.runs);
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
