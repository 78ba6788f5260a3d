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
.warn{border:2px solid #d80;background:#fff8ec;padding:0.6em 1.2em;border-radius:6px}
table{border-collapse:collapse;margin:0.6em 0;font-size:0.9em} td,th{border:1px solid #bbb;padding:3px 7px;text-align:left}
th{background:#eee} td.num{text-align:right;font-variant-numeric:tabular-nums}
figure{margin:1em 0} figcaption{font-size:0.9em;color:#444;max-width:720px}
.small{font-size:0.85em;color:#555}
)";

std::string pareto_html(const StudyFile& f, const StudyResult& r) {
  const ParetoFront& fr = r.front;
  const bool oos = !fr.seeds.empty();
  std::ostringstream h;
  std::vector<SvgSeries> series;
  std::vector<std::size_t> counts;
  for (const FrontPoint& p : fr.points)
    if (std::find(counts.begin(), counts.end(), p.design.balls) == counts.end()) counts.push_back(p.design.balls);
  for (std::size_t k = 0; k < counts.size(); ++k) {
    SvgSeries in, out;
    const std::string who = counts.size() > 1 ? std::to_string(counts[k]) + " balls, " : "";
    in.name = who + "in sample (" + std::to_string(f.base.runs) + " runs)";
    out.name = who + "fresh samples (mean of " + std::to_string(fr.seeds.size()) + " x " + std::to_string(fr.runs) +
               " runs)";
    in.color = out.color = palette(k == 0 ? 0 : k + 1);
    in.markers = out.markers = true;
    out.dashed = true;
    for (const FrontPoint& p : fr.points) {
      if (p.design.balls != counts[k] || !p.feasible) continue;
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
    << "<figcaption>Stage " << esc(fr.stage) << ": for each bound on T, the study's objective minimised with T &le; the "
       "bound and the study's other constraints (epsilon-constraint; each bound starts from the previous bound's best). "
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
  if (rec) {
    h << "<div class=\"answer\"><p><b>Recommended design: " << esc(rec->label) << "</b> &mdash; " << rec->balls
      << " balls, " << esc(drive_text(f.base.setup.motor)) << ".</p><p>Profile: " << esc(profile_text(rec->profile))
      << "<br>Peak angular acceleration " << sig3(problems::peak_angular_acceleration_rad_s2(rec->profile))
      << " rad/s&sup2; (baseline " << sig3(r.baseline_peak_acceleration) << ").</p>\n";
    const ValidationResult& v = r.validation;
    if (v.done) {
      h << "<p>On " << v.seeds.size() << " fresh samples of " << v.runs
        << " runs over the envelope (mean and 95&nbsp;% interval over the samples):</p>\n"
        << "<table><tr><th></th><th>recommended</th><th>baseline</th></tr>\n";
      const std::pair<const char*, const char*> rows[] = {{"ir_magnitude_mean", "mean |I<sub>r</sub>| [10<sup>-7</sup> kg m]"},
                                                         {"ir_magnitude_max", "max |I<sub>r</sub>| [10<sup>-7</sup> kg m]"},
                                                         {"pct_mi", "%MI"},
                                                         {"amplitude_max_mm", "peak amplitude [mm]"}};
      for (const auto& [k, label] : rows)
        h << "<tr><td>" << label << "</td><td class=\"num\">" << interval_text(v.design.at(k))
          << "</td><td class=\"num\">" << interval_text(v.baseline.at(k)) << "</td></tr>\n";
      h << "<tr><td><b>ratio of mean |I<sub>r</sub>|</b></td><td class=\"num\" colspan=\"2\"><b>"
        << interval_text(v.ratio_mean_ir) << "</b> (recommended / baseline)</td></tr></table>\n<p><b>"
        << esc(verdict_text(v)) << "</b></p>\n";
    } else {
      h << "<p>In sample: objective " << sig3(rec->in_sample.objective) << " against the baseline's "
        << sig3(r.baseline.objective) << " (no validate stage: no intervals on fresh samples).</p>\n";
    }
    h << "</div>\n";
  } else {
    h << "<div class=\"warn\"><p><b>No design is recommended.</b></p></div>\n";
  }
  if (!r.notes.empty() || r.interrupted) {
    h << "<div class=\"warn\"><ul>";
    if (r.interrupted) h << "<li>The study was interrupted: rerun the same command to resume from the archive.</li>";
    for (const auto& n : r.notes) h << "<li>" << esc(n) << "</li>";
    h << "</ul></div>\n";
  }

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
    prof.push_back(speed_series(r.designs[*r.recommended].profile, r.designs[*r.recommended].label + " (recommended)",
                                "#d62728", 3.0, false));
  h << "<h2>Profiles</h2>\n<figure>" << svg_line_chart("Disc speed against time", "time [s]", "speed [Hz]", prof, 900, 420)
    << "<figcaption>The recommended design (thick red), the baseline (dashed grey) and every stage's best design. "
    << "Natural frequency of the ABU as given: " << sig3(f.base.setup.abu.natural_frequency_hz()) << " Hz.</figcaption></figure>\n";

  // ---- the envelope map ----
  if (!r.validation.map_ratio.empty()) {
    const ValidationResult& v = r.validation;
    h << "<h2>Ratio to the baseline over the envelope</h2>\n<figure>"
      << svg_heatmap("mean |I_r| of the recommended design / the baseline's", "friction mu",
                     "imbalance mass factor", v.map_mu, v.map_imbalance, v.map_ratio, 1.0, 720,
                     std::max(220, 80 + 50 * static_cast<int>(v.map_imbalance.size())))
      << "<figcaption>Each cell: a Monte Carlo of " << v.map_runs
      << " runs with the friction and the imbalance fixed at that point (same initial angles for both profiles). "
      << "Below 1 (blue): the design is better than the baseline there.</figcaption></figure>\n";
  }

  // ---- final positions over the equilibrium set ----
  if (!r.validation.final_design.empty()) {
    const ValidationResult& v = r.validation;
    std::vector<SvgPointGroup> groups = {
        {"baseline (" + std::to_string(v.final_baseline.size()) + " runs)", "#555555", v.final_baseline, true},
        {"recommended (" + std::to_string(v.final_design.size()) + " runs)", "#d62728", v.final_design, false}};
    h << "<h2>Final ball positions over the equilibrium set</h2>\n<figure>"
      << svg_points_over_set("Final angles of the two balls", "beta_1 [deg]", "beta_2 [deg]", v.eq_n, v.eq_in_set,
                             "equilibrium set (" + sig3(v.eq_frequency_hz) + " Hz, mu " + sig3(v.eq_mu) + ")",
                             groups)
      << "<figcaption>Where the balls stop, on the first fresh sample of the validation (the envelope's draws per run). "
         "Shaded: the configurations in which both balls can stay stuck at the last frequency with the nominal "
         "friction (report section 4.2), "
      << sig3(100.0 * static_cast<double>(std::count(v.eq_in_set.begin(), v.eq_in_set.end(), 1)) /
              static_cast<double>(std::max<std::size_t>(1, v.eq_in_set.size())))
      << " % of the torus; the balancing positions lie where the residual imbalance vanishes."
         "</figcaption></figure>\n";
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
    all.name = t.stage + " (" + std::to_string(t.balls) + " balls): every evaluation";
    best.name = t.stage + " (" + std::to_string(t.balls) + " balls): best feasible";
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
  h << "<figure>" << svg_line_chart("Objective of every evaluation, stages one after another", "evaluation",
                                    "objective (" + to_string(f.objective.kind) + ")", conv, 900, 460)
    << "<figcaption>Stages run in order; each optimiser stage starts from the previous best. The baseline's objective "
       "in sample is "
    << sig3(r.baseline.objective) << ".</figcaption></figure>\n<table><tr><th>stage</th><th>balls</th><th>algorithm</th>"
       "<th>reason</th><th>evaluations</th><th>from archive</th></tr>\n";
  for (const auto& t : r.traces)
    h << "<tr><td>" << esc(t.stage) << "</td><td class=\"num\">" << t.balls << "</td><td>" << esc(t.algorithm)
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
