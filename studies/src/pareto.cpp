// Pareto front by the epsilon-constraint method (pareto.hpp, docs/sweep.md).
#include "abuopt/studies/pareto.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/gnuplot.hpp"
#include "abuopt/common/plot_style.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/optimizer/evaluation_archive.hpp"
#include "abuopt/optimizer/minimize.hpp"
#include "abuopt/optimizer/multi_objective.hpp"
#include "abuopt/optimizer/penalty_problem.hpp"
#include "abuopt/studies/sweep.hpp"

namespace abuopt {

namespace {
namespace fs = std::filesystem;
}

std::string to_string(ParetoSettings::Method m) {
  switch (m) {
    case ParetoSettings::Method::Nsga2: return "nsga2";
    case ParetoSettings::Method::Moead: return "moead";
    default: return "epsilon_constraint";
  }
}

ParetoSettings read_pareto_settings(YamlReader section) {
  if (!section.present())
    throw ConfigError("pareto", "(absent)", "a Pareto front needs a `pareto` section (max_startup_time_s: [...])");
  ParetoSettings s;
  const std::string method = section.get_string_or("method", "epsilon_constraint");
  if (method == "nsga2") s.method = ParetoSettings::Method::Nsga2;
  else if (method == "moead") s.method = ParetoSettings::Method::Moead;
  else if (method != "epsilon_constraint")
    throw ConfigError(section.key_path("method"), method, "must be epsilon_constraint, nsga2 or moead");
  if (s.method != ParetoSettings::Method::EpsilonConstraint) {
    for (const char* key : {"max_startup_time_s", "warm_start"})
      if (section.has(key))
        throw ConfigError(section.key_path(key), yaml_value_text(section.node()[key]),
                          "means nothing for method " + method +
                              ": its front spans every startup time the design allows (the reference bounds the "
                              "hypervolume); bounds belong to method epsilon_constraint");
    s.max_evaluations = section.get_int("max_evaluations", Rule::positive());
    s.population = section.get_int_or("population", 20, Rule::in_range(1, 100000));
    opt::check_two_objective_population(
        s.method == ParetoSettings::Method::Moead ? opt::TwoObjectiveMethod::Moead : opt::TwoObjectiveMethod::Nsga2,
        s.population, s.max_evaluations, section.key_path("population"), section.key_path("max_evaluations"));
    YamlReader ref = section.child("reference");
    if (!ref.present())
      throw ConfigError(section.key_path("reference"), "<missing>",
                        "is required for method " + method +
                            ": {objective: F, second: T_s}, the hypervolume's reference point, beyond the front");
    s.reference.first = ref.get_double("objective", Rule::positive());
    s.reference.second = ref.get_double("second", Rule::positive());
    ref.finish();
    section.finish();
    return s;
  }
  for (const char* key : {"max_evaluations", "population", "reference"})
    if (section.has(key))
      throw ConfigError(section.key_path(key), yaml_value_text(section.node()[key]),
                        "only for method nsga2 or moead (the series' budget per bound is optimizer.max_evaluations)");
  s.max_startup_time_s = section.get_double_list("max_startup_time_s", Rule::positive());
  if (s.max_startup_time_s.size() < 2)
    throw ConfigError(section.key_path("max_startup_time_s"), std::to_string(s.max_startup_time_s.size()) + " values",
                      "a front needs >= 2 bounds");
  std::sort(s.max_startup_time_s.begin(), s.max_startup_time_s.end());
  for (std::size_t i = 1; i < s.max_startup_time_s.size(); ++i)
    if (s.max_startup_time_s[i] == s.max_startup_time_s[i - 1])
      throw ConfigError(section.key_path("max_startup_time_s"), format_number(s.max_startup_time_s[i]), "listed twice");
  s.warm_start = section.get_bool_or("warm_start", true);
  section.finish();
  return s;
}

opt::Evaluation in_sample_evaluation(const ParetoPoint& p) {
  opt::Evaluation e;
  e.ok = !p.x.empty();
  e.objective = p.result.objective;
  e.inequality = p.result.inequality;
  e.metrics = p.result.metrics;
  return e;
}

void mark_dominated(std::vector<ParetoPoint>& points) {
  auto usable = [](const ParetoPoint& p) { return !p.x.empty() && p.result.feasible; };
  for (auto& p : points) {
    p.dominated = false;
    if (!usable(p)) continue;
    for (const auto& q : points) {
      if (&q == &p || !usable(q)) continue;
      const bool no_worse = q.startup_time_s <= p.startup_time_s && q.result.objective <= p.result.objective;
      const bool better = q.startup_time_s < p.startup_time_s || q.result.objective < p.result.objective;
      if (no_worse && better) p.dominated = true;
    }
  }
}

namespace {
// The run was stopped from outside (Ctrl-C, request_stop, a progress callback that returned false):
// the series stops with it.
bool stopped(opt::TerminationReason r) {
  return r == opt::TerminationReason::Interrupted || r == opt::TerminationReason::StoppedByCallback;
}
}  // namespace

ParetoResult run_pareto(const problems::StartupProfileSettings& base, const opt::OptimizerOptions& options,
                        const ParetoSettings& pareto, const std::string& archive_path,
                        const std::string& command_config, const std::string& config_hash,
                        const ParetoProgress& progress, bool validate, const std::vector<double>& x0) {
  if (pareto.method != ParetoSettings::Method::EpsilonConstraint)
    throw ConfigError("pareto.method", to_string(pareto.method),
                      "this runs the epsilon-constraint series only; methods nsga2 and moead run with the command "
                      "`abuopt pareto` (in C++: pareto_front_problem and run_front_comparison)");
  if (base.constraints.max_startup_time_s)
    throw ConfigError("constraints.max_startup_time_s", format_number(*base.constraints.max_startup_time_s),
                      "must be absent for a Pareto front: pareto.max_startup_time_s sets it for each point");
  ParetoResult out;
  std::vector<double> start;  // empty: the problem's x0
  const std::size_t n = pareto.max_startup_time_s.size();
  for (std::size_t k = 0; k < n; ++k) {
    problems::StartupProfileSettings s = base;
    s.constraints.max_startup_time_s = pareto.max_startup_time_s[k];
    problems::StartupProfileProblem problem(s);
    std::optional<opt::PenaltyProblem> penalised;
    if (s.constraints.penalty_weight > 0) penalised.emplace(problem, s.constraints.penalty_weight);
    opt::Problem& optimised = penalised ? static_cast<opt::Problem&>(*penalised) : problem;
    opt::EvaluationArchive archive(archive_path, problem.identity());
    archive.record_metadata("pareto", command_config, config_hash);
    opt::ArchivedProblem archived(optimised, archive);

    ParetoPoint p;
    p.epsilon = pareto.max_startup_time_s[k];
    p.problem_id = problem.identity();
    const opt::EvaluationCallback cb = [&](const opt::Progress& pr) { return progress ? progress(k, n, pr) : true; };
    // From x0, and (warm_start) from the previous bound's best: the better feasible run is kept.
    p.result = opt::minimize(archived, options, x0, cb);
    p.evaluations = p.result.evaluations;
    p.starts = 1;
    if (pareto.warm_start && !start.empty() && !stopped(p.result.reason)) {
      opt::OptimizationResult warm = opt::minimize(archived, options, start, cb);
      p.evaluations += warm.evaluations;
      p.starts = 2;
      const bool better = warm.feasible && (!p.result.feasible || warm.objective < p.result.objective);
      p.warm_start_won = better;
      if (better || stopped(warm.reason)) p.result = std::move(warm);
    }
    p.x = p.result.x;
    if (!p.x.empty()) p.startup_time_s = problem.startup_time_s(p.x);
    if (p.result.feasible) start = p.x;  // feasible for every looser bound that follows
    out.points.push_back(std::move(p));
    if (stopped(out.points.back().result.reason)) {
      out.interrupted = true;
      break;
    }
  }
  mark_dominated(out.points);

  if (validate && !out.interrupted && base.validation.enabled) {
    problems::StartupProfileProblem problem(base);
    for (auto& p : out.points) {
      p.out_of_sample = p.x.empty() ? opt::Evaluation::failed("no best point")
                                    : problem.evaluate_out_of_sample_at(p.x);
    }
    const StartupProfile report = StartupProfile::report_final();
    out.report_in_sample = problem.evaluate_profile(report);
    out.report_out_of_sample = problem.evaluate_out_of_sample(report);
    out.report_startup_time_s = report.duration_s();
  } else {
    for (auto& p : out.points) p.out_of_sample = opt::Evaluation::failed("not validated");
    out.report_in_sample = out.report_out_of_sample = opt::Evaluation::failed("not validated");
    out.report_startup_time_s = StartupProfile::report_final().duration_s();
  }
  return out;
}

namespace {

std::string cell(double v) { return std::isfinite(v) ? csv_number(v) : ""; }

double metric(const opt::Evaluation& e, const std::string& k) {
  auto it = e.metrics.find(k);
  return it == e.metrics.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
}

}  // namespace

std::string write_pareto_outputs(const fs::path& dir, const problems::StartupProfileProblem& shape,
                                 const ParetoResult& r) {
  const auto& st = shape.settings();
  const auto vars = shape.variables();
  {
    AtomicFile f(dir / "pareto.csv");
    f << "epsilon_s,startup_time_s,feasible,dominated,objective,objective_hw95,out_of_sample_objective,"
         "out_of_sample_hw95,pct_mi,out_of_sample_pct_mi,evaluations,starts,kept_start,reason";
    for (const auto& v : vars) f << "," << csv_field(v.name);
    f << "\n";
    for (const auto& p : r.points) {
      const opt::Evaluation in = in_sample_evaluation(p);
      f << csv_number(p.epsilon) << "," << (p.x.empty() ? "" : csv_number(p.startup_time_s)) << ","
        << p.result.feasible << "," << p.dominated << "," << (p.x.empty() ? "" : cell(p.result.objective)) << ","
        << cell(objective_half_width(st, in)) << ","
        << (p.out_of_sample.ok ? cell(p.out_of_sample.objective) : "") << ","
        << (p.out_of_sample.ok ? cell(objective_half_width(st, p.out_of_sample)) : "") << ","
        << cell(metric(in, "pct_mi")) << "," << cell(metric(p.out_of_sample, "pct_mi")) << ","
        << p.evaluations << "," << p.starts << "," << (p.warm_start_won ? "warm" : "x0") << ","
        << csv_field(to_string(p.result.reason));
      for (std::size_t i = 0; i < vars.size(); ++i) f << "," << (i < p.x.size() ? csv_number(p.x[i]) : "");
      f << "\n";
    }
    f.commit();
  }
  {  // the report's profile: one line per sample
    AtomicFile f(dir / "pareto_report_profile.csv");
    f << "sample,startup_time_s,objective,objective_hw95,pct_mi\n";
    const std::pair<const char*, const opt::Evaluation*> rows[] = {{"in_sample", &r.report_in_sample},
                                                                   {"out_of_sample", &r.report_out_of_sample}};
    for (const auto& [name, e] : rows)
      f << name << "," << csv_number(r.report_startup_time_s) << "," << (e->ok ? cell(e->objective) : "") << ","
        << (e->ok ? cell(objective_half_width(st, *e)) : "") << "," << cell(metric(*e, "pct_mi")) << "\n";
    f.commit();
  }

  const Gnuplot gp;
  const std::string ylabel = objective_label(st);
  bool any_dominated = false;
  for (const auto& p : r.points) any_dominated = any_dominated || (p.result.feasible && p.dominated);
  // The one plot style (common/plot_style.hpp); text shown literally (noenhanced: "I_r,x").
  std::ostringstream body;
  body << "set datafile separator ','\nset key top right box opaque\n"
       << "set title " << plot_style::literal("Pareto front: " + ylabel + " against startup time") << "\n"
       << "set xlabel " << plot_style::literal("startup time T [s]") << "\nset ylabel " << plot_style::literal(ylabel) << "\n"
       << "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n"
       << "plot 'pareto.csv' skip 1 using 2:(($3 == 1 && $4 == 0) ? $5 : NaN) with linespoints pt 7 ps 0.9 lw 2 "
          "lc rgb '" << plot_style::kBlue << "' title " << plot_style::literal("front, in-sample (" + std::to_string(st.study.runs) + " runs)") << ", \\\n"
       << "     'pareto.csv' skip 1 using 2:7:8 with yerrorbars pt 5 ps 0.7 lc rgb '" << plot_style::kOrange << "' title "
       << plot_style::literal("front points, out-of-sample (" + std::to_string(st.validation.runs) + " runs, 95 % bars)") << ", \\\n";
  // "dominated" only when a point is (a key entry without a point misleads)
  if (any_dominated)
    body << "     'pareto.csv' skip 1 using 2:(($3 == 1 && $4 == 1) ? $5 : NaN) with points pt 6 ps 1.2 "
            "lc rgb '" << plot_style::kGrey << "' title 'dominated (a local optimum)' noenhanced, \\\n";
  body << "     'pareto_report_profile.csv' skip 1 every ::0::0 using 2:3:4 with yerrorbars pt 6 ps 1.8 lw 2 "
          "lc rgb '" << plot_style::kRed << "' title '2003 report profile, in-sample (open circle)' noenhanced, \\\n"
       << "     'pareto_report_profile.csv' skip 1 every ::1::1 using 2:3:4 with yerrorbars pt 7 ps 1.4 lw 2 "
          "lc rgb '" << plot_style::kRed << "' title '2003 report profile, out-of-sample (filled circle)' noenhanced\n";
  const bool cairo = !gp.available() || gp.terminal() == "pngcairo";
  const fs::path script = dir / "pareto.gp";
  write_file_atomic(script, plot_style::figure_script("pareto", body.str(), 900, 650, cairo ? "pngcairo" : "png"));
  if (!gp.available()) return "pareto plot skipped: gnuplot not found (script " + script.string() + ")";
  std::error_code ec;
  fs::remove(dir / "pareto.png", ec);
  const int rc = gp.run_script(fs::absolute(script).string(), fs::absolute(dir).string(),
                               fs::absolute(dir / "pareto.log").string());
  if (rc != 0 || !fs::is_regular_file(dir / "pareto.png", ec))
    return "pareto plot failed: gnuplot exited with status " + std::to_string(rc) + " (" + (dir / "pareto.log").string() + ")";
  return "wrote " + (dir / "pareto.png").string() + (cairo ? " and " + (dir / "pareto.pdf").string() : std::string());
}

}  // namespace abuopt
