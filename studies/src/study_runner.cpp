// run_study: the baseline, one archived problem per choice, the stages in order (each optimiser
// stage starts from the previous best), the recommendation, and the notes a designer needs (the
// family cannot reach the resonance, a constraint cannot be met). Every Monte Carlo goes through
// OUT/archive.sqlite, so a rerun after an interruption recomputes nothing it stored.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>

#include "abuopt/common/stop.hpp"
#include "abuopt/common/config_error.hpp"
#include "abuopt/common/provenance.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/optimizer/algorithms.hpp"
#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/penalty_problem.hpp"
#include "study_context.hpp"

namespace abuopt::studies {

namespace detail {

namespace {
constexpr double kTolerance = 1e-6;  // on the relative constraints g = value / bound - 1
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// 4 significant digits for the log
std::string g4(double v) {
  std::ostringstream os;
  os << std::setprecision(4) << v;
  return os.str();
}

std::string hex16(std::uint64_t v) {
  std::ostringstream os;
  os << std::hex << std::setw(16) << std::setfill('0') << v;
  return os.str();
}
}  // namespace

bool feasible(const opt::Evaluation& e) { return opt::is_feasible(e, kTolerance); }

void StudyContext::log(const std::string& line) const {
  if (options.log) options.log(line);
}
bool StudyContext::stop() const { return interrupted || (options.stop_requested && options.stop_requested()); }
void StudyContext::tick(long n) {
  done += n;
  if (options.progress) options.progress(done, std::max(done, total));
}

problems::StartupProfileSettings StudyContext::baseline_sample(std::uint64_t seed, std::size_t runs) const {
  problems::StartupProfileSettings s = baseline_settings();
  s.study.seed = seed;
  s.study.design.seed = seed;
  if (runs > 0) s.study.runs = runs;
  return s;
}

StudyContext::Fresh StudyContext::fresh(std::size_t balls, std::uint64_t seed, std::size_t runs) {
  Fresh r;
  r.baseline = evaluate_profile(baseline_sample(seed, runs), file.base.setup.profile);
  r.settings = settings_of_choice(file, balls, r.baseline.metrics);
  r.settings.study.seed = seed;
  r.settings.study.design.seed = seed;
  if (runs > 0) r.settings.study.runs = runs;
  if (options.threads) r.settings.threads = *options.threads;
  return r;
}

problems::StartupProfileSettings StudyContext::baseline_settings() const {
  problems::StartupProfileSettings s = settings_of_choice(file, file.ball_counts.front(), {});
  s.study.setup.abu = file.base.setup.abu;  // the ABU as given
  s.study.design.balls = s.study.setup.abu.balls.size();
  s.constraints = file.constraints;  // absolute bounds only (the relative ones are relative to it)
  if (options.threads) s.threads = *options.threads;
  return s;
}

opt::Evaluation StudyContext::evaluate_profile(const problems::StartupProfileSettings& s, const StartupProfile& p) {
  problems::StartupProfileProblem problem(s);
  const std::string id = problem.identity() + "/profile-" + hex16(problems::fnv1a64(write_fields(p)));
  opt::EvaluationArchive archive(archive_path, id);
  const std::vector<double> key = {0.0};
  if (auto hit = archive.find(key)) {
    tick();
    return *hit;
  }
  const auto t0 = std::chrono::steady_clock::now();
  opt::Evaluation e = problem.evaluate_profile(p);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  archive.store(key, e, wall);
  tick();
  return e;
}

OptimiserRun run_archived_optimiser(StudyContext& c, const StageSpec& stage, const std::string& trace_name,
                                    std::size_t balls, problems::StartupProfileProblem& problem,
                                    opt::ArchivedProblem& archived, long max_evaluations, const std::vector<double>& x0,
                                    std::vector<double>& least_violation) {
  OptimiserRun run;
  opt::OptimizerOptions o = stage.optimizer;
  o.max_evaluations = std::min(o.max_evaluations, max_evaluations);
  const opt::AlgorithmInfo& info = opt::find_algorithm(o.algorithm, "stages." + stage.name + ".optimizer.algorithm");
  const std::vector<std::string> g_names = problem.inequality_names();
  std::optional<opt::PenaltyProblem> pen;
  if (!info.inequality_constraints && !g_names.empty()) pen.emplace(archived, stage.penalty_weight);
  opt::Problem& p = pen ? static_cast<opt::Problem&>(*pen) : static_cast<opt::Problem&>(archived);

  StageTrace& tr = run.trace;
  tr.stage = trace_name;
  tr.balls = balls;
  double best = std::numeric_limits<double>::infinity();
  least_violation.resize(g_names.size(), std::numeric_limits<double>::infinity());
  const opt::EvaluationCallback cb = [&](const opt::Progress& pr) {
    const opt::EvaluationRecord& rec = pr.last;
    double obj = rec.objective;
    std::vector<double> g = rec.inequality;
    if (pen) {  // the real objective and constraints, from the penalty form's metrics
      auto it = rec.metrics.find("objective_without_penalty");
      if (it != rec.metrics.end()) obj = it->second;
      g.clear();
      for (const auto& n : g_names) {
        auto gi = rec.metrics.find("g_" + n);
        g.push_back(gi == rec.metrics.end() ? kNaN : gi->second);
      }
    }
    bool feas = rec.ok && std::isfinite(obj);
    for (std::size_t i = 0; i < g.size() && i < g_names.size(); ++i) {
      if (rec.ok && std::isfinite(g[i])) least_violation[i] = std::min(least_violation[i], g[i]);
      feas = feas && std::isfinite(g[i]) && g[i] <= kTolerance;
    }
    tr.objective.push_back(rec.ok ? obj : kNaN);
    if (feas && obj < best) {
      best = obj;
      run.best_x = rec.x;
    }
    tr.best_feasible.push_back(std::isfinite(best) ? best : kNaN);
    c.tick();
    return !c.stop();
  };
  std::ostringstream head;
  head << "stage " << trace_name << " (" << balls << " balls): " << o.algorithm << (pen ? " (penalty form)" : "")
       << ", at most " << o.max_evaluations << " evaluations, from "
       << (x0.empty() ? "the family's starting point" : "the previous best");
  c.log(head.str());
  const opt::OptimizationResult r = opt::minimize(p, o, x0, cb);
  c.used += r.evaluations;
  if (r.reason == opt::TerminationReason::Interrupted) c.interrupted = true;
  tr.algorithm = r.algorithm;
  tr.reason = to_string(r.reason);
  tr.evaluations = r.evaluations;
  tr.archive_hits = r.archive_hits;
  c.result.evaluations += r.evaluations;
  c.result.archive_hits += r.archive_hits;
  run.feasible = !run.best_x.empty();
  if (run.best_x.empty()) run.best_x = r.x;  // nothing feasible: the optimiser's least bad point
  return run;
}

StudyDesign design_at(const ChoiceContext& ch, problems::StartupProfileProblem& problem, opt::ArchivedProblem& archived,
                      const std::string& label, const std::string& stage, const std::vector<double>& x) {
  StudyDesign d;
  d.label = label;
  d.balls = ch.balls;
  d.stage = stage;
  for (const auto& v : problem.variables()) d.variable_names.push_back(v.name);
  d.x = x;
  d.profile = problem.profile_at(x);
  d.in_sample = archived.evaluate(x);  // an archive hit
  d.robust_feasible = feasible(d.in_sample);
  d.replicated_objective = d.in_sample.objective;
  return d;
}

void run_optimiser_stage(StudyContext& c, const StageSpec& stage, bool from_best) {
  for (ChoiceContext& ch : c.choices) {
    if (c.stop()) return;
    const long remaining = c.file.max_evaluations - c.used;
    if (remaining <= 0) {
      c.result.notes.push_back("stage " + stage.name + " skipped for " + std::to_string(ch.balls) +
                               " balls: the budget (budget.max_evaluations = " +
                               std::to_string(c.file.max_evaluations) + ") is spent");
      c.log(c.result.notes.back());
      continue;
    }
    const std::vector<double> x0 = from_best ? ch.x : std::vector<double>{};
    OptimiserRun run = run_archived_optimiser(c, stage, stage.name, ch.balls, *ch.problem, *ch.archived, remaining,
                                              x0, ch.least_violation);
    c.result.traces.push_back(run.trace);
    if (run.best_x.empty()) continue;  // no evaluation at all (interrupted at once)
    const StudyDesign d = design_at(ch, *ch.problem, *ch.archived, "balls" + std::to_string(ch.balls) + "_" + stage.name,
                                    stage.name, run.best_x);
    // the next stage starts from the best design so far (a stage that found nothing better keeps it)
    const auto better = [](const StudyDesign& a, const StudyDesign& b) {
      const bool fa = feasible(a.in_sample), fb = feasible(b.in_sample);
      if (fa != fb) return fa;
      if (fa) return a.in_sample.objective < b.in_sample.objective;
      return opt::max_constraint_violation(a.in_sample) < opt::max_constraint_violation(b.in_sample);
    };
    if (!ch.last_design || better(d, c.result.designs[*ch.last_design])) {
      ch.x = run.best_x;
      ch.last_design = c.result.designs.size();
    } else {
      c.log("  not better than " + c.result.designs[*ch.last_design].label + ": the next stage starts from that one");
    }
    c.result.designs.push_back(d);
    std::ostringstream done;
    done << "  " << run.trace.reason << " after " << run.trace.evaluations << " evaluations ("
         << run.trace.archive_hits << " from the archive): objective " << g4(d.in_sample.objective)
         << (d.robust_feasible ? " (feasible)" : " (NOT feasible)");
    c.log(done.str());
  }
}

void recommend_in_sample(StudyContext& c) {
  for (const ChoiceContext& ch : c.choices) {
    if (!ch.last_design) continue;
    const StudyDesign& d = c.result.designs[*ch.last_design];
    if (!feasible(d.in_sample)) continue;
    if (!c.result.recommended || d.in_sample.objective < c.result.designs[*c.result.recommended].in_sample.objective)
      c.result.recommended = *ch.last_design;
  }
}

}  // namespace detail

StudyResult run_study(const StudyFile& f, const StudyRunOptions& o) {
  using namespace detail;
  namespace fs = std::filesystem;
  const auto t0 = std::chrono::steady_clock::now();
  StudyResult result;
  fs::create_directories(o.out);
  StudyContext c{f, o, result, (fs::path(o.out) / "archive.sqlite").string(), 0, 0, 0, {}};
  const Provenance prov = provenance_of(f.path);

  // the plan, for the progress line: optimiser budgets, fresh samples, map points
  long optimiser = 0, other = 1;  // 1: the baseline
  for (const StageSpec& s : f.stages) {
    if (s.kind == StageKind::Global || s.kind == StageKind::Local)
      optimiser += s.optimizer.max_evaluations * static_cast<long>(f.ball_counts.size());
    else if (s.kind == StageKind::Pareto) {
      optimiser += s.optimizer.max_evaluations * static_cast<long>(f.ball_counts.size() * s.pareto_bounds.size());
      other += static_cast<long>(s.seeds.size() * (f.ball_counts.size() * s.pareto_bounds.size() + 1));
    } else if (s.kind == StageKind::Replicate)
      other += static_cast<long>(s.seeds.size() * (f.ball_counts.size() + 1));
    else
      other += static_cast<long>(2 * s.seeds.size() + 2 * s.map_friction_mu.size() * s.map_imbalance_factor.size());
  }
  c.total = std::min(optimiser, f.max_evaluations) + other;

  // the baseline on the in-sample initial conditions (its metrics fix the relative constraints)
  result.baseline = c.evaluate_profile(c.baseline_settings(), f.base.setup.profile);
  result.baseline_peak_acceleration = problems::peak_angular_acceleration_rad_s2(f.base.setup.profile);
  if (!result.baseline.ok)
    throw ConfigError("baseline", "<profile>", "its Monte Carlo failed (" + result.baseline.message + ")");
  {
    std::ostringstream os;
    os << "baseline: objective " << g4(result.baseline.objective) << ", mean |I_r| "
       << g4(result.baseline.metrics.at("ir_magnitude_mean")) << " x 1e-7 kg m, peak amplitude "
       << g4(result.baseline.metrics.at("amplitude_max_mm")) << " mm, %MI "
       << g4(result.baseline.metrics.at("pct_mi")) << " (" << f.base.runs << " runs)";
    c.log(os.str());
  }

  for (std::size_t n : f.ball_counts) {
    ChoiceContext ch;
    ch.balls = n;
    problems::StartupProfileSettings s = settings_of_choice(f, n, result.baseline.metrics);
    if (o.threads) s.threads = *o.threads;
    const double fn = s.study.setup.abu.natural_frequency_hz();
    ch.problem = std::make_unique<problems::StartupProfileProblem>(s);
    ch.archive = std::make_unique<opt::EvaluationArchive>(c.archive_path, ch.problem->identity());
    ch.archive->record_metadata("study", f.path, prov.config_hash);
    ch.archived = std::make_unique<opt::ArchivedProblem>(*ch.problem, *ch.archive);
    result.constraint_names = ch.problem->inequality_names();
    std::ostringstream os;
    os << n << " balls: natural frequency " << format_number(std::round(fn * 100) / 100) << " Hz, "
       << ch.problem->variables().size() << " variables, " << ch.archive->count() << " stored evaluations";
    c.log(os.str());
    const std::string reach = resonance_reach_text(s.design, fn);
    if (!reach.empty()) {
      result.notes.push_back(std::to_string(n) + " balls: " + reach);
      c.log("note: " + result.notes.back());
    }
    c.choices.push_back(std::move(ch));
  }

  bool replicated = false;
  for (const StageSpec& s : f.stages) {
    if (c.stop()) break;
    try {
      switch (s.kind) {
        case StageKind::Global: run_global_stage(c, s); break;
        case StageKind::Local: run_local_stage(c, s); break;
        case StageKind::Pareto: run_pareto_stage(c, s); break;
        case StageKind::Replicate:
          run_replicate_stage(c, s);
          replicated = true;
          break;
        case StageKind::Validate:
          if (!replicated) recommend_in_sample(c);
          replicated = true;
          run_validate_stage(c, s);
          break;
      }
    } catch (const Interrupted&) {
      // a stop request (common/stop.hpp) cut a Monte Carlo outside an optimiser: what is archived
      // stays, the report is written from what is complete
      c.interrupted = true;
      break;
    }
  }
  if (!replicated) recommend_in_sample(c);
  result.interrupted = c.stop();

  // a constraint that no evaluation met, named with its least value
  if (!result.interrupted && !result.recommended) {
    for (const ChoiceContext& ch : c.choices)
      for (std::size_t i = 0; i < ch.least_violation.size() && i < result.constraint_names.size(); ++i)
        if (ch.least_violation[i] > kTolerance) {
          std::ostringstream os;
          os << "constraint " << result.constraint_names[i] << " cannot be met with " << ch.balls
             << " balls: its least value over every evaluation is g = " << g4(ch.least_violation[i])
             << " (the bound exceeded by " << format_number(std::round(ch.least_violation[i] * 1000) / 10) << " %)";
          result.notes.push_back(os.str());
          c.log("note: " + os.str());
        }
    if (result.notes.empty() || result.notes.back().rfind("constraint", 0) != 0)
      result.notes.push_back("no design met every constraint together (each one alone was met by some design)");
  }
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace abuopt::studies
