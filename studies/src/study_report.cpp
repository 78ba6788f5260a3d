// The study's outputs: summary.json (with provenance), report.md, report.html (study_report_html.cpp)
// and designs/<label>.yaml, each a config ready for `abuopt montecarlo` (the design's ABU and
// profile, the study's drive and simulation, the envelope and the validation's run count).
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "abuopt/common/output_file.hpp"
#include "abuopt/common/provenance.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "study_report_text.hpp"

namespace abuopt::studies {

namespace detail {

std::string sig3(double v) {
  if (!std::isfinite(v)) return "n/a";
  std::ostringstream os;
  os << std::setprecision(3) << v;
  return os.str();
}

std::string profile_text(const StartupProfile& p) {
  std::ostringstream os;
  double f = p.start_frequency_hz();
  for (std::size_t i = 0; i < p.segments().size(); ++i) {
    const auto& s = p.segments()[i];
    os << (i ? ", " : "") << sig3(f) << " -> " << sig3(s.end_frequency_hz) << " Hz in " << sig3(s.duration_s) << " s";
    f = s.end_frequency_hz;
  }
  os << " (" << sig3(p.duration_s()) << " s)";
  return os.str();
}

std::string interval_text(const Interval& i) {
  if (i.samples < 2) return sig3(i.mean);
  return sig3(i.mean) + " [" + sig3(i.lo) + ", " + sig3(i.hi) + "]";
}

double metric(const opt::Evaluation& e, const std::string& key) {
  auto it = e.metrics.find(key);
  return it == e.metrics.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
}

std::string drive_text(const MotorModel& m) {
  if (m.kind == MotorKind::Ideal) return "ideal motor (the disc follows the profile exactly)";
  std::string t = "PI drive (omega_m " + sig3(m.omega_m_rad_s) + " rad/s, xi " + sig3(m.xi);
  if (m.quantize_setpoint_1hz) t += ", 1 Hz setpoints";
  if (m.setpoint_mismatch) t += ", setpoint mismatch";
  return t + ")";
}

std::string verdict_text(const ValidationResult& v) {
  const Interval& q = v.ratio_mean_ir;
  const std::string n = std::to_string(q.samples) + " fresh samples";
  if (q.samples < 2) return "One fresh sample: no interval; the ratio " + sig3(q.mean) + " is a single estimate.";
  if (q.hi < 1.0)
    return "Better than the baseline: the mean |I_r| is " + sig3(100 * (1 - q.mean)) + " % lower (95 % interval of the ratio below 1 on " + n + ").";
  if (q.lo > 1.0)
    return "Worse than the baseline: the mean |I_r| is " + sig3(100 * (q.mean - 1)) + " % higher (95 % interval of the ratio above 1 on " + n + ").";
  return "No difference from the baseline that " + n + " can tell (the 95 % interval of the ratio contains 1).";
}

// Why the headline says what it says (after the headline's design).
std::string headline_reason(Verdict v) {
  switch (v) {
    case Verdict::Recommended: return "feasible on every fresh sample and better than the baseline on fresh samples";
    case Verdict::NoBetter:
      return "no better than the baseline that the fresh samples can tell: the baseline is as good";
    case Verdict::Worse: return "worse than the baseline on fresh samples: keep the baseline";
    case Verdict::Candidate:
      return "it did not meet the constraints on every fresh sample: a candidate to check, not an answer";
    case Verdict::Unvalidated: return "in sample only (no validate stage): not checked on fresh samples";
    case Verdict::None: return "";
  }
  return "";
}

std::string choices_sentence(const StudyFile& f, const StudyResult& r) {
  std::ostringstream os;
  const std::string won = r.recommended ? choice_name(f.choices[r.designs[*r.recommended].choice]) : "";
  if (f.ball_count_variable) {
    os << "The ball count was a variable of the global stages (";
    for (std::size_t i = 0; i < r.choice_summary.size(); ++i)
      os << (i ? ", " : "") << r.choice_summary[i].balls;
    os << " balls at " << sig3(f.total_ball_mass_kg.value_or(0)) << " kg in all); they chose";
    bool any = false;
    for (const auto& cs : r.choice_summary)
      if (cs.chosen) {
        os << (any ? " and " : " ") << cs.balls << " balls";
        any = true;
      }
    if (!any) os << " none";
    os << ", which the later stages polished.";
  } else {
    os << "Every choice was optimised with the same stages";
    if (f.total_ball_mass_kg) os << " (counts at " << sig3(*f.total_ball_mass_kg) << " kg in all)";
    os << ".";
  }
  if (!won.empty()) os << " The best design has " << won << ".";
  return os.str();
}

}  // namespace detail

Verdict verdict_of(const StudyResult& r) {
  if (!r.recommended) return Verdict::None;
  if (r.candidate) return Verdict::Candidate;
  const ValidationResult& v = r.validation;
  if (!v.done || v.ratio_mean_ir.samples < 2) return Verdict::Unvalidated;
  if (v.ratio_mean_ir.hi < 1.0) return Verdict::Recommended;
  if (v.ratio_mean_ir.lo > 1.0) return Verdict::Worse;
  return Verdict::NoBetter;
}

std::string to_string(Verdict v) {
  switch (v) {
    case Verdict::Recommended: return "recommended";
    case Verdict::NoBetter: return "no_better";
    case Verdict::Worse: return "worse";
    case Verdict::Candidate: return "candidate";
    case Verdict::Unvalidated: return "unvalidated";
    case Verdict::None: return "none";
  }
  return "none";
}

std::string headline_of(Verdict v) {
  switch (v) {
    case Verdict::Recommended: return "Recommended design";
    case Verdict::Candidate: return "Candidate design";
    case Verdict::NoBetter:
    case Verdict::Worse:
    case Verdict::Unvalidated: return "Best design found";
    case Verdict::None: return "No design is recommended";
  }
  return "";
}

namespace {

using namespace detail;
namespace fs = std::filesystem;

nlohmann::json evaluation_json(const opt::Evaluation& e, const std::vector<std::string>& g_names) {
  nlohmann::json j = {{"ok", e.ok}, {"objective", e.objective}, {"feasible", feasible(e)}};
  nlohmann::json g = nlohmann::json::object();
  for (std::size_t i = 0; i < e.inequality.size() && i < g_names.size(); ++i) g[g_names[i]] = e.inequality[i];
  j["constraints"] = g;
  nlohmann::json m = nlohmann::json::object();
  for (const auto& [k, v] : e.metrics)
    if (std::isfinite(v)) m[k] = v;
  j["metrics"] = m;
  if (!e.message.empty()) j["message"] = e.message;
  return j;
}

nlohmann::json interval_json(const Interval& i) {
  return {{"mean", i.mean}, {"lo95", i.lo}, {"hi95", i.hi}, {"samples", i.samples}};
}

nlohmann::json profile_json(const StartupProfile& p) {
  nlohmann::json segs = nlohmann::json::array();
  for (const auto& s : p.segments()) segs.push_back({{"end_frequency_hz", s.end_frequency_hz}, {"duration_s", s.duration_s}});
  return {{"start_frequency_hz", p.start_frequency_hz()}, {"segments", segs}, {"duration_s", p.duration_s()}};
}

std::string indent(const std::string& text, const std::string& pad) {
  std::istringstream in(text);
  std::ostringstream out;
  for (std::string line; std::getline(in, line);) out << (line.empty() ? "" : pad) << line << "\n";
  return out.str();
}

std::string design_yaml(const StudyFile& f, const StudyResult& r, const StudyDesign& d) {
  SimulationSetup setup = f.base.setup;
  setup.abu = abu_of_choice(f, d.choice);
  setup.profile = d.profile;
  MonteCarloConfig mc;
  mc.study = f.base;
  mc.study.setup = setup;
  mc.study.design.balls = d.balls;
  mc.study.runs = r.validation.done ? r.validation.runs : f.base.runs;
  mc.study.seed = mc.study.design.seed = r.validation.done ? r.validation.seeds.front() + 1 : f.base.seed + 1;
  mc.threads = 0;
  std::ostringstream os;
  os << "# Design " << d.label << " of `abuopt study " << f.path << "` (" << f.title << ").\n"
     << "# " << d.balls << " balls; profile " << profile_text(d.profile) << "\n"
     << "# In sample: objective " << sig3(d.in_sample.objective) << (feasible(d.in_sample) ? " (feasible)" : " (NOT feasible)")
     << "; mean |I_r| " << sig3(metric(d.in_sample, "ir_magnitude_mean")) << " x 1e-7 kg m; peak amplitude "
     << sig3(metric(d.in_sample, "amplitude_max_mm")) << " mm.\n"
     << "# The montecarlo section is the study's envelope on a fresh seed.\n"
     << "# Run it: abuopt montecarlo " << "designs/" << d.label << ".yaml\n"
     << to_yaml(setup) << "montecarlo:\n"
     << indent(write_fields(mc), "  ");
  return os.str();
}

std::string markdown(const StudyFile& f, const StudyResult& r) {
  std::ostringstream md;
  md << "# Study: " << f.title << "\n\n";
  const StudyDesign* rec = r.recommended ? &r.designs[*r.recommended] : nullptr;
  md << "## Answer\n\n";
  const Verdict verdict = verdict_of(r);
  if (!rec) {
    md << "**No design is recommended.**";
    for (const auto& n : r.notes) md << " " << n << ".";
    md << "\n\n";
  } else {
    md << headline_of(verdict) << ": **" << rec->label << "** (" << headline_reason(verdict) << ") - " << rec->balls
       << " balls, " << drive_text(f.base.setup.motor)
       << ", profile " << profile_text(rec->profile) << ", peak angular acceleration "
       << sig3(problems::peak_angular_acceleration_rad_s2(rec->profile)) << " rad/s^2 (baseline "
       << sig3(r.baseline_peak_acceleration) << ").\n\n";
    const ValidationResult& v = r.validation;
    if (v.done) {
      md << "On " << v.seeds.size() << " fresh samples of " << v.runs
         << " runs over the envelope (mean and 95 % interval over the samples):\n\n"
         << "| | " << rec->label << " | baseline |\n|---|---|---|\n";
      const std::pair<const char*, const char*> rows[] = {{"ir_magnitude_mean", "mean \\|I_r\\| [1e-7 kg m]"},
                                                         {"ir_magnitude_max", "max \\|I_r\\| [1e-7 kg m]"},
                                                         {"pct_mi", "%MI"},
                                                         {"amplitude_max_mm", "peak amplitude [mm]"}};
      for (const auto& [k, label] : rows)
        md << "| " << label << " | " << interval_text(v.design.at(k)) << " | " << interval_text(v.baseline.at(k)) << " |\n";
      md << "\nRatio of mean |I_r| (" << rec->label << " / baseline): " << interval_text(v.ratio_mean_ir) << ". "
         << verdict_text(v) << "\n\n";
      if (!v.final_design.angles_deg.empty() && !v.final_baseline.angles_deg.empty()) {
        const auto balls = [](const FinalPositions& p) {
          return sig3(100.0 * p.early_share) + " % early, mean depth |U|/r_lock " +
                 sig3(p.depth_mean) + " [" + sig3(p.depth_lo) + ", " + sig3(p.depth_hi) + "]";
        };
        md << "Where the balls stopped (first fresh sample, settled runs; early: stuck for good below "
           << sig3(v.early_edge_hz) << " Hz, where the set has narrowed to 2 r_lock): " << rec->label << " "
           << balls(v.final_design) << "; baseline " << balls(v.final_baseline) << ".\n\n";
      }
    }
  }
  if (r.choice_summary.size() > 1) {
    md << "## Ball choices\n\n" << choices_sentence(f, r) << "\n\n| choice | balls | total ball mass [kg] | diameters [mm] | "
       << "evaluations | best feasible objective in sample |" << (f.ball_count_variable ? " polished |" : "")
       << "\n|---|---|---|---|---|---|" << (f.ball_count_variable ? "---|" : "") << "\n";
    for (std::size_t i = 0; i < r.choice_summary.size(); ++i) {
      const auto& cs = r.choice_summary[i];
      double mass = 0;
    for (const Ball& b : f.choices[i].balls) mass += b.mass_kg;
      md << "| " << cs.label << " | " << cs.balls << " | " << sig3(mass) << " | " << diameters_mm(f.choices[i].balls) << " | "
         << cs.evaluations << " | " << (std::isfinite(cs.best_feasible) ? sig3(cs.best_feasible) : "none feasible")
         << " |" << (f.ball_count_variable ? (cs.chosen ? " yes |" : " no |") : "") << "\n";
    }
    md << "\n";
  }
  if (!r.notes.empty()) {
    md << "## Notes\n\n";
    for (const auto& n : r.notes) md << "- " << n << "\n";
    md << "\n";
  }
  md << "## Designs\n\n| design | balls | stage | objective (in sample) | objective (replicated) | feasible | mean \\|I_r\\| | "
        "%MI | peak amplitude [mm] | T [s] | profile |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  md << "| baseline | " << f.base.setup.abu.balls.size() << " | - | " << sig3(r.baseline.objective) << " | - | "
     << (feasible(r.baseline) ? "yes" : "no") << " | " << sig3(metric(r.baseline, "ir_magnitude_mean")) << " | "
     << sig3(metric(r.baseline, "pct_mi")) << " | " << sig3(metric(r.baseline, "amplitude_max_mm")) << " | "
     << sig3(f.base.setup.profile.duration_s()) << " | " << profile_text(f.base.setup.profile) << " |\n";
  for (const auto& d : r.designs)
    md << "| " << d.label << " | " << d.balls << " | " << d.stage << " | " << sig3(d.in_sample.objective) << " | "
       << (d.replications.empty() ? "-" : sig3(d.replicated_objective)) << " | "
       << (d.replications.empty() ? (feasible(d.in_sample) ? "yes" : "no") : (d.robust_feasible ? "yes (all samples)" : "no"))
       << " | " << sig3(metric(d.in_sample, "ir_magnitude_mean")) << " | " << sig3(metric(d.in_sample, "pct_mi"))
       << " | " << sig3(metric(d.in_sample, "amplitude_max_mm")) << " | " << sig3(d.profile.duration_s()) << " | "
       << profile_text(d.profile) << " |\n";
  if (!r.front.points.empty()) {
    const ParetoFront& fr = r.front;
    const bool oos = !fr.seeds.empty();
    md << "\n## Pareto front (stage " << fr.stage << ")\n\n"
       << (fr.method == "epsilon_constraint"
               ? std::string("The least objective at each bound on the startup time T (epsilon-constraint)")
               : std::string("The front of one ") + (fr.method == "moead" ? "MOEA/D" : "NSGA-II") +
                     " run on the objective and T at once (the bound column is each point's own T)")
       << ", mean |I_r| in 1e-7 kg m; "
       << (oos ? "in sample and on " + std::to_string(fr.seeds.size()) + " fresh samples of " + std::to_string(fr.runs) +
                     " runs (mean and 95 % interval).\n\n"
               : "in sample only (biased low: the optimiser chose on that sample).\n\n")
       << "| bound on T [s] | balls | T [s] | mean \\|I_r\\| in sample | " << (oos ? "mean \\|I_r\\| fresh | feasible fresh | " : "")
       << "%MI | feasible | dominated | config |\n|---|---|---|---|" << (oos ? "---|---|" : "") << "---|---|---|---|\n";
    for (const FrontPoint& p : fr.points) {
      md << "| " << sig3(p.bound_s) << " | " << p.design.balls << " | " << sig3(p.design.profile.duration_s()) << " | "
         << sig3(metric(p.design.in_sample, "ir_magnitude_mean")) << " | ";
      if (oos) md << interval_text(p.out_of_sample_ir) << " | " << (p.feasible_out_of_sample ? "yes" : "no") << " | ";
      md << sig3(metric(p.design.in_sample, "pct_mi")) << " | " << (p.feasible ? "yes" : "no") << " | "
         << (p.dominated ? "yes" : "no") << " | designs/" << p.design.label << ".yaml |\n";
    }
    md << "| baseline | " << f.base.setup.abu.balls.size() << " | " << sig3(f.base.setup.profile.duration_s()) << " | "
       << sig3(metric(r.baseline, "ir_magnitude_mean")) << " | ";
    if (oos) md << interval_text(fr.baseline_out_of_sample_ir) << " | - | ";
    md << sig3(metric(r.baseline, "pct_mi")) << " | - | - | - |\n";
  }
  md << "\n## Stages\n\n| stage | choice | algorithm | reason | evaluations | from archive |\n|---|---|---|---|---|---|\n";
  for (const auto& t : r.traces)
    md << "| " << t.stage << " | " << (t.balls ? t.choice : std::string("ball count a variable")) << " | " << t.algorithm << " | " << t.reason << " | " << t.evaluations
       << " | " << t.archive_hits << " |\n";
  md << "\nObjective: " << to_string(f.objective.kind) << " (I_r in 1e-7 kg m); " << f.base.runs
     << " runs per evaluation on the same initial angles (common random numbers), seed " << f.base.seed
     << ". Wall time " << sig3(r.wall_time_s) << " s" << (r.interrupted ? " (interrupted: rerun to resume)" : "")
     << ".\n";
  return md.str();
}

nlohmann::json summary(const StudyFile& f, const StudyResult& r) {
  const Provenance prov = provenance_of(f.path);
  nlohmann::json j;
  j["study"] = f.path;
  j["title"] = f.title;
  j["provenance"] = {{"abuopt_version", prov.abuopt_version}, {"git_commit", prov.git_commit}, {"config_hash", prov.config_hash}};
  j["interrupted"] = r.interrupted;
  j["wall_time_s"] = r.wall_time_s;
  j["evaluations"] = r.evaluations;
  j["archive_hits"] = r.archive_hits;
  j["constraints"] = r.constraint_names;
  j["notes"] = r.notes;
  j["baseline"] = evaluation_json(r.baseline, {});
  j["baseline"]["profile"] = profile_json(f.base.setup.profile);
  j["baseline"]["peak_angular_acceleration_rad_s2"] = r.baseline_peak_acceleration;
  nlohmann::json designs = nlohmann::json::array();
  for (const auto& d : r.designs) {
    nlohmann::json x = nlohmann::json::object();
    for (std::size_t i = 0; i < d.x.size() && i < d.variable_names.size(); ++i) x[d.variable_names[i]] = d.x[i];
    nlohmann::json reps = nlohmann::json::array();
    for (const auto& e : d.replications) reps.push_back(evaluation_json(e, r.constraint_names));
    designs.push_back({{"label", d.label},
                       {"balls", d.balls},
                       {"stage", d.stage},
                       {"x", x},
                       {"profile", profile_json(d.profile)},
                       {"peak_angular_acceleration_rad_s2", problems::peak_angular_acceleration_rad_s2(d.profile)},
                       {"in_sample", evaluation_json(d.in_sample, r.constraint_names)},
                       {"replications", reps},
                       {"robust_feasible", d.robust_feasible},
                       {"replicated_objective", d.replicated_objective},
                       {"file", "designs/" + d.label + ".yaml"}});
  }
  j["designs"] = designs;
  j["recommended"] = r.recommended ? nlohmann::json(r.designs[*r.recommended].label) : nlohmann::json(nullptr);
  j["verdict"] = to_string(verdict_of(r));
  if (r.validation.done) {
    const ValidationResult& v = r.validation;
    nlohmann::json dv = nlohmann::json::object(), bv = nlohmann::json::object();
    for (const auto& [k, i] : v.design) dv[k] = interval_json(i);
    for (const auto& [k, i] : v.baseline) bv[k] = interval_json(i);
    j["validation"] = {{"runs", v.runs}, {"seeds", v.seeds}, {"design", dv}, {"baseline", bv},
                       {"ratio_mean_abs_ir", interval_json(v.ratio_mean_ir)}};
    if (!v.map_ratio.empty())
      j["validation"]["map"] = {{"friction_mu", v.map_mu}, {"imbalance_mass_factor", v.map_imbalance},
                                {"runs", v.map_runs}, {"ratio_mean_abs_ir", v.map_ratio}};
    if (!v.final_design.angles_deg.empty() || !v.final_baseline.angles_deg.empty()) {
      const auto fp = [](const FinalPositions& p) {
        return nlohmann::json{{"settled", p.angles_deg.size()}, {"not_settled", p.not_settled},
                              {"early_share", p.early_share}, {"early_depth_mean", p.early_depth_mean},
                              {"late_depth_mean", p.late_depth_mean},
                              {"depth_mean", {{"mean", p.depth_mean}, {"lo95", p.depth_lo}, {"hi95", p.depth_hi}}}};
      };
      j["validation"]["final_positions"] = {{"design", fp(v.final_design)}, {"baseline", fp(v.final_baseline)},
                                            {"lock_band_hz", {v.lock_band_lo_hz, v.lock_band_hi_hz}},
                                            {"early_edge_hz", v.early_edge_hz}, {"lock_mu", v.lock_mu}};
    }
  }
  if (!r.front.points.empty()) {
    const ParetoFront& fr = r.front;
    nlohmann::json pts = nlohmann::json::array();
    for (const FrontPoint& p : fr.points) {
      nlohmann::json x = nlohmann::json::object();
      for (std::size_t i = 0; i < p.design.x.size() && i < p.design.variable_names.size(); ++i)
        x[p.design.variable_names[i]] = p.design.x[i];
      nlohmann::json jp = {{"bound_s", p.bound_s},
                           {"label", p.design.label},
                           {"balls", p.design.balls},
                           {"startup_time_s", p.design.profile.duration_s()},
                           {"x", x},
                           {"profile", profile_json(p.design.profile)},
                           {"in_sample", evaluation_json(p.design.in_sample, r.constraint_names)},
                           {"feasible", p.feasible},
                           {"dominated", p.dominated},
                           {"evaluations", p.evaluations},
                           {"file", "designs/" + p.design.label + ".yaml"}};
      if (!fr.seeds.empty()) {
        jp["out_of_sample_mean_abs_ir"] = interval_json(p.out_of_sample_ir);
        jp["feasible_out_of_sample"] = p.feasible_out_of_sample;
      }
      pts.push_back(jp);
    }
    j["pareto"] = {{"stage", fr.stage}, {"method", fr.method}, {"points", pts}};
    if (!fr.seeds.empty()) {
      j["pareto"]["seeds"] = fr.seeds;
      j["pareto"]["runs"] = fr.runs;
      j["pareto"]["baseline_out_of_sample_mean_abs_ir"] = interval_json(fr.baseline_out_of_sample_ir);
    }
  }
  j["choices"] = nlohmann::json::array();
  for (std::size_t i = 0; i < r.choice_summary.size(); ++i) {
    const auto& cs = r.choice_summary[i];
    nlohmann::json balls = nlohmann::json::array();
    for (const Ball& b : f.choices[i].balls) balls.push_back({{"mass_kg", b.mass_kg}, {"diameter_m", b.diameter_m}});
    j["choices"].push_back({{"label", cs.label}, {"balls", balls}, {"evaluations", cs.evaluations},
                            {"best_feasible_objective", std::isfinite(cs.best_feasible) ? nlohmann::json(cs.best_feasible)
                                                                                        : nlohmann::json(nullptr)},
                            {"chosen", cs.chosen}});
  }
  j["ball_count_variable"] = f.ball_count_variable;
  j["traces"] = nlohmann::json::array();
  for (const auto& t : r.traces) {
    nlohmann::json best = nlohmann::json::array();
    for (double b : t.best_feasible) best.push_back(std::isfinite(b) ? nlohmann::json(b) : nlohmann::json(nullptr));
    j["traces"].push_back({{"stage", t.stage}, {"choice", t.choice}, {"balls", t.balls}, {"algorithm", t.algorithm}, {"reason", t.reason},
                           {"evaluations", t.evaluations}, {"archive_hits", t.archive_hits}, {"best_feasible", best}});
  }
  return j;
}

}  // namespace

std::vector<std::string> write_study_report(const StudyFile& f, const StudyResult& r, const std::string& out_dir) {
  const fs::path out(out_dir);
  std::vector<std::string> files;
  fs::create_directories(out / "designs");
  for (const auto& d : r.designs) {
    const fs::path p = out / "designs" / (d.label + ".yaml");
    write_file_atomic(p, design_yaml(f, r, d));
    files.push_back(p.string());
  }
  for (const auto& fp : r.front.points) {
    const fs::path p = out / "designs" / (fp.design.label + ".yaml");
    write_file_atomic(p, design_yaml(f, r, fp.design));
    files.push_back(p.string());
  }
  write_file_atomic(out / "summary.json", summary(f, r).dump(2) + "\n");
  write_file_atomic(out / "report.md", markdown(f, r));
  write_file_atomic(out / "report.html", study_html(f, r));
  for (const char* n : {"summary.json", "report.md", "report.html"}) files.push_back((out / n).string());
  return files;
}

}  // namespace abuopt::studies
