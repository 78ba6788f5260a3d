// report.html of a study: one self-contained page (inline CSS and SVG, no script, no network) that
// answers first (the recommended design against the baseline, with intervals, and its conditions),
// then shows the profiles, the ratio to the baseline over the envelope, the convergence of every
// stage and every design's table.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "abuopt/common/provenance.hpp"
#include "study_report_text.hpp"
#include "study_svg.hpp"

namespace abuopt::studies::detail {

namespace {

std::string esc(const std::string& s) { return xml_escape(s); }

// Speed [Hz] against time for a profile, sampled finely enough to show every segment's shape.
SvgSeries speed_series(const StartupProfile& p, const std::string& name, const std::string& colour, double width,
                       bool dashed) {
  SvgSeries s;
  s.name = name;
  s.color = colour;
  s.width = width;
  s.dashed = dashed;
  const int n = 600;
  for (int i = 0; i <= n; ++i) {
    const double t = p.duration_s() * i / n;
    s.x.push_back(t);
    s.y.push_back(p.frequency_hz(t));
  }
  return s;
}

const char* const kStyle = R"(
body{font-family:sans-serif;max-width:1100px;margin:1em auto;padding:0 1em;color:#222}
h1{font-size:1.5em} h2{font-size:1.2em;margin-top:1.6em;border-bottom:1px solid #ccc}
.answer{border:2px solid #2a7;background:#f3fbf6;padding:0.8em 1.2em;border-radius:6px}
.answer.caution{border-color:#d80;background:#fff8ec}
.warn{border:2px solid #d80;background:#fff8ec;padding:0.6em 1.2em;border-radius:6px}
table{border-collapse:collapse;margin:0.6em 0;font-size:0.9em} td,th{border:1px solid #bbb;padding:3px 7px;text-align:left}
th{background:#eee} td.num{text-align:right;font-variant-numeric:tabular-nums}
figure{margin:1em 0} figcaption{font-size:0.9em;color:#444;max-width:720px}
.small{font-size:0.85em;color:#555}
.panels{display:flex;flex-wrap:wrap;gap:1em} .panels p{font-size:0.9em;max-width:500px;margin:0.2em 0}
)";

// "2 balls", a set's name, or "ball count a variable" (a global stage over the count)
std::string trace_who(const StageTrace& t) {
  if (t.balls == 0) return "ball count a variable";
  return t.choice == "balls" + std::to_string(t.balls) ? std::to_string(t.balls) + " balls" : t.choice;
}

std::string choices_html(const StudyFile& f, const StudyResult& r) {
  std::ostringstream h;
  h << "<h2>Ball choices</h2>\n<p>" << esc(choices_sentence(f, r)) << "</p>\n<table><tr><th>choice</th><th>balls</th>"
    << "<th>total ball mass [kg]</th><th>diameters [mm]</th><th>"
    << (f.ball_count_variable ? "evaluations of the global stages" : "optimiser evaluations")
    << "</th><th>best feasible objective<br>in sample</th>" << (f.ball_count_variable ? "<th>polished</th>" : "")
    << "</tr>\n";
  for (std::size_t i = 0; i < r.choice_summary.size(); ++i) {
    const auto& cs = r.choice_summary[i];
    double mass = 0;
    for (const Ball& b : f.choices[i].balls) mass += b.mass_kg;
    const bool won = r.recommended && r.designs[*r.recommended].choice == i;
    h << "<tr" << (won ? " style=\"font-weight:bold\"" : "") << "><td>" << esc(cs.label) << (won ? " (the best design)" : "")
      << "</td><td class=\"num\">" << cs.balls << "</td><td class=\"num\">" << sig3(mass)
      << "</td><td class=\"num\">" << diameters_mm(f.choices[i].balls) << "</td><td class=\"num\">" << cs.evaluations
      << "</td><td class=\"num\">" << (std::isfinite(cs.best_feasible) ? sig3(cs.best_feasible) : "none feasible")
      << "</td>";
    if (f.ball_count_variable) h << "<td>" << (cs.chosen ? "yes" : "no") << "</td>";
    h << "</tr>\n";
  }
  h << "</table>\n";
  return h.str();
}

std::string pareto_html(const StudyFile& f, const StudyResult& r) {
  const ParetoFront& fr = r.front;
  const bool oos = !fr.seeds.empty();
  std::ostringstream h;
  std::vector<SvgSeries> series;
  std::vector<std::size_t> counts;
  for (const FrontPoint& p : fr.points)
    if (std::find(counts.begin(), counts.end(), p.design.choice) == counts.end()) counts.push_back(p.design.choice);
  for (std::size_t k = 0; k < counts.size(); ++k) {
    SvgSeries in, out;
    const std::string who = counts.size() > 1 ? f.choices[counts[k]].label + ", " : "";
    in.name = who + "in sample (" + std::to_string(f.base.runs) + " runs)";
    out.name = who + "fresh samples (mean of " + std::to_string(fr.seeds.size()) + " x " + std::to_string(fr.runs) +
               " runs)";
    in.color = out.color = palette(k == 0 ? 0 : k + 1);
    in.markers = out.markers = true;
    out.dashed = true;
    for (const FrontPoint& p : fr.points) {
      if (p.design.choice != counts[k] || !p.feasible) continue;
      in.x.push_back(p.design.profile.duration_s());
      in.y.push_back(metric(p.design.in_sample, "ir_magnitude_mean"));
      if (oos) {
        out.x.push_back(p.design.profile.duration_s());
        out.y.push_back(p.out_of_sample_ir.mean);
      }
    }
    series.push_back(in);
    if (oos) series.push_back(out);
  }
  SvgSeries base;
  base.name = "baseline, in sample";
  base.color = "#d62728";
  base.width = 0;
  base.x = {f.base.setup.profile.duration_s()};
  base.y = {metric(r.baseline, "ir_magnitude_mean")};
  series.push_back(base);
  if (oos) {
    SvgSeries b2 = base;
    b2.name = "baseline, fresh samples";
    b2.markers = b2.dashed = true;
    b2.y = {fr.baseline_out_of_sample_ir.mean};
    series.push_back(b2);
  }
  h << "<h2>Pareto front: mean |I<sub>r</sub>| against startup time</h2>\n<figure>"
    << svg_line_chart("Least mean |I_r| at each bound on the startup time", "startup time T [s]",
                      "mean |I_r| [1e-7 kg m]", series, 900, 420)
    << "<figcaption>Stage " << esc(fr.stage) << ": "
    << (fr.method == "epsilon_constraint"
            ? std::string("for each bound on T, the study's objective minimised with T &le; the bound and the study's "
                          "other constraints (epsilon-constraint; each bound starts from the previous bound's best). ")
            : std::string("one ") + (fr.method == "moead" ? "MOEA/D" : "NSGA-II") +
                  " run on the study's objective and T at once under the study's other constraints; its non-dominated "
                  "feasible designs (the bound column is each point's own T). ")
    << (oos ? "Filled dots: in sample (the sample the optimiser chose on, biased low); hollow dots: the same designs and "
              "the baseline on fresh samples."
            : "In sample only (the sample the optimiser chose on, biased low): give the stage seeds to check the front "
              "on fresh samples.")
    << " Infeasible bounds are left out of the figure.</figcaption></figure>\n";
  h << "<table><tr><th>bound on T [s]</th><th>balls</th><th>T [s]</th><th>mean |I<sub>r</sub>|<br>in sample</th>"
    << (oos ? "<th>mean |I<sub>r</sub>|<br>fresh samples</th><th>feasible on<br>every fresh sample</th>" : "")
    << "<th>%MI</th><th>peak amplitude [mm]</th><th>feasible</th><th>dominated</th><th>profile</th><th>config</th></tr>\n";
  for (const FrontPoint& p : fr.points) {
    const StudyDesign& d = p.design;
    h << "<tr><td class=\"num\">" << sig3(p.bound_s) << "</td><td class=\"num\">" << d.balls << "</td><td class=\"num\">"
      << sig3(d.profile.duration_s()) << "</td><td class=\"num\">" << sig3(metric(d.in_sample, "ir_magnitude_mean"))
      << "</td>";
    if (oos)
      h << "<td class=\"num\">" << interval_text(p.out_of_sample_ir) << "</td><td>"
        << (p.feasible_out_of_sample ? "yes" : "no") << "</td>";
    h << "<td class=\"num\">" << sig3(metric(d.in_sample, "pct_mi")) << "</td><td class=\"num\">"
      << sig3(metric(d.in_sample, "amplitude_max_mm")) << "</td><td>" << (p.feasible ? "yes" : "no") << "</td><td>"
      << (p.dominated ? "yes" : "no") << "</td><td class=\"small\">" << esc(profile_text(d.profile))
      << "</td><td class=\"small\">designs/" << esc(d.label) << ".yaml</td></tr>\n";
  }
  h << "<tr><td>baseline</td><td class=\"num\">" << f.base.setup.abu.balls.size() << "</td><td class=\"num\">"
    << sig3(f.base.setup.profile.duration_s()) << "</td><td class=\"num\">"
    << sig3(metric(r.baseline, "ir_magnitude_mean")) << "</td>";
  if (oos) h << "<td class=\"num\">" << interval_text(fr.baseline_out_of_sample_ir) << "</td><td>-</td>";
  h << "<td class=\"num\">" << sig3(metric(r.baseline, "pct_mi")) << "</td><td class=\"num\">"
    << sig3(metric(r.baseline, "amplitude_max_mm")) << "</td><td>-</td><td>-</td><td class=\"small\">"
    << esc(profile_text(f.base.setup.profile)) << "</td><td>-</td></tr>\n</table>\n";
  return h.str();
}

}  // namespace

std::string study_html(const StudyFile& f, const StudyResult& r) {
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Study: " << esc(f.title)
    << "</title><style>" << kStyle << "</style></head><body>\n<h1>Study: " << esc(f.title) << "</h1>\n";
  const StudyDesign* rec = r.recommended ? &r.designs[*r.recommended] : nullptr;

  // ---- the answer ----
  const Verdict verdict = verdict_of(r);
  if (rec) {
    // green only for a design to build; amber for one to check or to drop
    h << "<div class=\"" << (verdict == Verdict::Recommended ? "answer" : "answer caution") << "\"><p><b>"
      << esc(headline_of(verdict)) << ": " << esc(rec->label) << "</b> &mdash; " << esc(headline_reason(verdict))
      << ".</p><p>" << rec->balls
 << " balls, " << esc(drive_text(f.base.setup.motor)) << ".<br>Profile: " << esc(profile_text(rec->profile))
      << "<br>Peak angular acceleration " << sig3(problems::peak_angular_acceleration_rad_s2(rec->profile))
      << " rad/s&sup2; (baseline " << sig3(r.baseline_peak_acceleration) << ").</p>\n";
    const ValidationResult& v = r.validation;
    if (v.done) {
      h << "<p>On " << v.seeds.size() << " fresh samples of " << v.runs
        << " runs over the envelope (mean and 95&nbsp;% interval over the samples):</p>\n"
        << "<table><tr><th></th><th>" << esc(rec->label) << "</th><th>baseline</th></tr>\n";
      const std::pair<const char*, const char*> rows[] = {{"ir_magnitude_mean", "mean |I<sub>r</sub>| [10<sup>-7</sup> kg m]"},
                                                         {"ir_magnitude_max", "max |I<sub>r</sub>| [10<sup>-7</sup> kg m]"},
                                                         {"pct_mi", "%MI"},
                                                         {"amplitude_max_mm", "peak amplitude [mm]"}};
      for (const auto& [k, label] : rows)
        h << "<tr><td>" << label << "</td><td class=\"num\">" << interval_text(v.design.at(k))
          << "</td><td class=\"num\">" << interval_text(v.baseline.at(k)) << "</td></tr>\n";
      h << "<tr><td><b>ratio of mean |I<sub>r</sub>|</b></td><td class=\"num\" colspan=\"2\"><b>"
        << interval_text(v.ratio_mean_ir) << "</b> (" << esc(rec->label) << " / baseline)</td></tr></table>\n<p><b>"
        << esc(verdict_text(v)) << "</b></p>\n";
    } else {
      h << "<p>In sample: objective " << sig3(rec->in_sample.objective) << " against the baseline's "
        << sig3(r.baseline.objective) << " (no validate stage: no intervals on fresh samples).</p>\n";
    }
    h << "</div>\n";
  } else {
    h << "<div class=\"warn\"><p><b>No design is recommended.</b></p></div>\n";
  }
  // the figures name the headline's design as the headline does
  const std::string who = verdict == Verdict::Recommended ? "recommended" : verdict == Verdict::Candidate ? "candidate" : "best";
  if (!r.notes.empty() || r.interrupted) {
    h << "<div class=\"warn\"><ul>";
    if (r.interrupted) h << "<li>The study was interrupted: rerun the same command to resume from the archive.</li>";
    for (const auto& n : r.notes) h << "<li>" << esc(n) << "</li>";
    h << "</ul></div>\n";
  }

  // ---- how each ball choice did ----
  if (r.choice_summary.size() > 1) h << choices_html(f, r);

  // ---- the profiles ----
  std::vector<SvgSeries> prof;
  {  // the natural frequency of the ABU as given, as a dotted level
    const double fn = f.base.setup.abu.natural_frequency_hz();
    double t_end = f.base.setup.profile.duration_s();
    for (const auto& d : r.designs) t_end = std::max(t_end, d.profile.duration_s());
    SvgSeries level;
    level.name = "natural frequency " + sig3(fn) + " Hz";
    level.color = "#999999";
    level.width = 1.0;
    level.dashed = true;
    level.x = {0.0, t_end};
    level.y = {fn, fn};
    prof.push_back(level);
  }
  prof.push_back(speed_series(f.base.setup.profile, "baseline", "#444444", 2.0, true));
  std::size_t colour = 0;
  for (std::size_t i = 0; i < r.designs.size(); ++i) {
    if (r.recommended && *r.recommended == i) continue;  // drawn last, on top (a stage may end on the same design)
    prof.push_back(speed_series(r.designs[i].profile, r.designs[i].label, palette(colour == 0 ? 0 : colour + 1), 1.2,
                                false));
    ++colour;  // palette(1) is the recommended design's red
  }
  if (r.recommended)
    prof.push_back(speed_series(r.designs[*r.recommended].profile, r.designs[*r.recommended].label + " (" + who + ")",
                                "#d62728", 3.0, false));
  h << "<h2>Profiles</h2>\n<figure>" << svg_line_chart("Disc speed against time", "time [s]", "speed [Hz]", prof, 900, 420)
    << "<figcaption>The " << who << " design (thick red), the baseline (dashed grey) and every stage's best design. "
    << "Natural frequency of the ABU as given: " << sig3(f.base.setup.abu.natural_frequency_hz()) << " Hz.</figcaption></figure>\n";

  // ---- the envelope map ----
  if (!r.validation.map_ratio.empty()) {
    const ValidationResult& v = r.validation;
    h << "<h2>Ratio to the baseline over the envelope</h2>\n<figure>"
      << svg_heatmap("mean |I_r| of the " + who + " design / the baseline's", "friction mu",
                     "imbalance mass factor", v.map_mu, v.map_imbalance, v.map_ratio, 1.0, 720,
                     std::max(220, 80 + 50 * static_cast<int>(v.map_imbalance.size())))
      << "<figcaption>Each cell: a Monte Carlo of " << v.map_runs
      << " runs with the friction and the imbalance fixed at that point (same initial angles for both profiles). "
      << "Below 1 (blue): the design is better than the baseline there.</figcaption></figure>\n";
  }

  // ---- final positions over the lock set ----
  if (!r.validation.final_design.angles_deg.empty() || !r.validation.final_baseline.angles_deg.empty()) {
    const ValidationResult& v = r.validation;
    const auto pct = [](double share) { return sig3(100.0 * share) + " %"; };
    const auto panel = [&](const std::string& name, const FinalPositions& fp) {
      SvgPointGroup early{"", "#ff7f0e", {}, false}, late{"", "#1f77b4", {}, false};
      for (std::size_t k = 0; k < fp.angles_deg.size(); ++k) (fp.early[k] ? early : late).points.push_back(fp.angles_deg[k]);
      early.name = "early (" + std::to_string(early.points.size()) + " runs)";
      late.name = "late (" + std::to_string(late.points.size()) + " runs)";
      std::ostringstream o;
      o << "<div>"
        << svg_points_over_set(name + ": final angles of the two balls", "beta_1 [deg]", "beta_2 [deg]", v.lock_n,
                               v.lock_in_set, "lock set (mu " + sig3(v.lock_mu) + ")", {early, late}, 350, 165)
        << "<p>" << xml_escape(name) << ": " << fp.angles_deg.size() << " settled runs";
      if (fp.not_settled) o << " (" << fp.not_settled << " not settled, not drawn)";
      o << "; early " << pct(fp.early_share) << " (mean depth " << sig3(fp.early_depth_mean) << "), late "
        << pct(1.0 - fp.early_share) << " (" << sig3(fp.late_depth_mean) << "); mean depth |U|/r_lock "
        << sig3(fp.depth_mean) << " [" << sig3(fp.depth_lo) << ", " << sig3(fp.depth_hi) << "]</p></div>";
      return o.str();
    };
    h << "<h2>Where the balls stopped</h2>\n<figure><div class=\"panels\">"
      << panel("baseline", v.final_baseline) << panel(who + " design", v.final_design)
      << "</div><figcaption>The final angles of the two balls on the first fresh sample of the validation (the "
         "envelope's draws per run, the same initial angles for both profiles), over the lock set of the nominal "
         "ABU: shaded, the configurations held at every constant speed (lock gauge &le; 1, docs/equilibrium_sets.md "
         "section 6), the equilibrium set where it is narrowest, in the lock band "
      << sig3(v.lock_band_lo_hz) << " - " << sig3(v.lock_band_hi_hz)
      << " Hz around the resonance; balls stuck inside it are never moved again. Early runs stuck for good below "
      << sig3(v.early_edge_hz)
      << " Hz (where the set has narrowed to 2 r_lock), wherever they were; late runs were collected in the band. Depth: the residual imbalance |U| over r_lock, "
         "the radius of the narrowest set (each run with its own friction and imbalance); the balancing positions "
         "(depth 0) lie inside the shaded lobes, one for each order of the two balls. A better profile leaves fewer runs early and its late runs "
         "deeper.</figcaption></figure>\n";
  } else if (r.validation.done && r.recommended) {
    h << "<p>Where the balls stopped is drawn when the design and the baseline both have two balls (this design has "
      << r.designs[*r.recommended].balls << ", the baseline " << f.base.setup.abu.balls.size() << ").</p>\n";
  }

  // ---- the Pareto front ----
  if (!r.front.points.empty()) h << pareto_html(f, r);

  // ---- convergence ----
  h << "<h2>Convergence of every stage</h2>\n";
  std::vector<SvgSeries> conv;
  double offset = 0;
  for (std::size_t i = 0; i < r.traces.size(); ++i) {
    const StageTrace& t = r.traces[i];
    SvgSeries all, best;
    all.name = t.stage + " (" + trace_who(t) + "): every evaluation";
    best.name = t.stage + " (" + trace_who(t) + "): best feasible";
    all.color = best.color = palette(i);
    all.width = 0.8;
    best.width = 2.5;
    for (std::size_t k = 0; k < t.objective.size(); ++k) {
      all.x.push_back(offset + k + 1);
      all.y.push_back(t.objective[k]);
      best.x.push_back(offset + k + 1);
      best.y.push_back(t.best_feasible[k]);
    }
    offset += static_cast<double>(t.objective.size());
    conv.push_back(all);
    conv.push_back(best);
  }
  if (offset > 0 && std::isfinite(r.baseline.objective)) {  // the level to beat
    SvgSeries level;
    level.name = "baseline, in sample";
    level.color = "#444444";
    level.width = 1.5;
    level.dashed = true;
    level.x = {1.0, offset};
    level.y = {r.baseline.objective, r.baseline.objective};
    conv.push_back(level);
  }
  h << "<figure>" << svg_line_chart("Objective of every evaluation, stages one after another", "evaluation",
                                    "objective (" + to_string(f.objective.kind) + ")", conv, 900, 460)
    << "<figcaption>Stages run in order; each optimiser stage starts from the previous best. Dashed grey: the "
       "baseline's objective in sample, "
    << sig3(r.baseline.objective) << ".</figcaption></figure>\n<table><tr><th>stage</th><th>choice</th><th>algorithm</th>"
       "<th>reason</th><th>evaluations</th><th>from archive</th></tr>\n";
  for (const auto& t : r.traces)
    h << "<tr><td>" << esc(t.stage) << "</td><td class=\"num\">" << esc(trace_who(t)) << "</td><td>" << esc(t.algorithm)
      << "</td><td>" << esc(t.reason) << "</td><td class=\"num\">" << t.evaluations << "</td><td class=\"num\">"
      << t.archive_hits << "</td></tr>\n";
  h << "</table>\n";

  // ---- every design ----
  h << "<h2>Every design</h2>\n<table><tr><th>design</th><th>balls</th><th>objective<br>in sample</th>"
       "<th>objective<br>replicated</th><th>feasible</th><th>mean |I<sub>r</sub>|</th><th>%MI</th>"
       "<th>peak amplitude [mm]</th><th>T [s]</th><th>peak accel. [rad/s&sup2;]</th><th>profile</th><th>config</th></tr>\n";
  const auto row = [&](const std::string& label, std::size_t balls, const opt::Evaluation& e, const std::string& rep,
                       const std::string& feas, const StartupProfile& p, const std::string& file) {
    h << "<tr><td>" << esc(label) << "</td><td class=\"num\">" << balls << "</td><td class=\"num\">" << sig3(e.objective)
      << "</td><td class=\"num\">" << rep << "</td><td>" << feas << "</td><td class=\"num\">"
      << sig3(metric(e, "ir_magnitude_mean")) << "</td><td class=\"num\">" << sig3(metric(e, "pct_mi"))
      << "</td><td class=\"num\">" << sig3(metric(e, "amplitude_max_mm")) << "</td><td class=\"num\">"
      << sig3(p.duration_s()) << "</td><td class=\"num\">" << sig3(problems::peak_angular_acceleration_rad_s2(p))
      << "</td><td class=\"small\">" << esc(profile_text(p)) << "</td><td class=\"small\">" << esc(file) << "</td></tr>\n";
  };
  row("baseline", f.base.setup.abu.balls.size(), r.baseline, "-", feasible(r.baseline) ? "yes" : "no",
      f.base.setup.profile, "-");
  for (const auto& d : r.designs)
    row(d.label, d.balls, d.in_sample, d.replications.empty() ? "-" : sig3(d.replicated_objective),
        d.replications.empty() ? (feasible(d.in_sample) ? "yes" : "no")
                               : (d.robust_feasible ? "yes, every sample" : "no"),
        d.profile, "designs/" + d.label + ".yaml");
  h << "</table>\n<p class=\"small\">In sample: " << f.base.runs
    << " runs on the same initial angles for every design (common random numbers), the envelope's parameters drawn "
       "per run. Constraints: ";
  for (std::size_t i = 0; i < r.constraint_names.size(); ++i) h << (i ? ", " : "") << esc(r.constraint_names[i]);
  if (r.constraint_names.empty()) h << "none";
  const Provenance prov = provenance_of(f.path);
  h << ".</p>\n<p class=\"small\">abuopt " << esc(prov.abuopt_version) << " (" << esc(prov.git_commit) << "), study file "
    << esc(f.path) << " (" << esc(prov.config_hash) << "), " << r.evaluations << " optimiser evaluations ("
    << r.archive_hits << " from the archive), wall time " << sig3(r.wall_time_s) << " s.</p>\n</body></html>\n";
  return h.str();
}

}  // namespace abuopt::studies::detail
