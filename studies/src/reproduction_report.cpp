#include "abuopt/studies/reproduction_report.hpp"

#include "abuopt/studies/terms.hpp"

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <sstream>

#include "abuopt/core/ball_contact.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "study_text.hpp"

namespace abuopt {

namespace fs = std::filesystem;
using namespace studies_detail;

namespace {

std::string local_time_text() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", &tm);
  return buf;
}

std::string md_escape(const std::string& s) { return markdown_cell(s); }

}  // namespace

std::vector<Verdict> ReproductionReport::verdicts() const {
  std::vector<Verdict> out;
  for (const TableResult& t : tables) out.insert(out.end(), t.verdicts.begin(), t.verdicts.end());
  return out;
}

// --- formatting ---------------------------------------------------------------------------------

std::string tables_csv_header() {
  return "table,case,label,value,runs,ok,failed,mean_x_1e7,sem_x_1e7,ref_mean_1e7,max_x_1e7,ref_max_1e7,pct_lc,"
         "ref_pct_lc,pct_mi_x,pct_mi_x_ci_lo,pct_mi_x_ci_hi,ref_pct_mi,ref_pct_mi_inside_ci,mean_mag_1e7,"
         "max_mag_1e7,pct_mi_mag,pct_mi_mag_ci_lo,pct_mi_mag_ci_hi,settling_mean_s,settling_median_s,"
         "settling_max_s,amplitude_max_mm,wall_time_s";
}

std::size_t count_overlapping_final_states(const AbuParameters& p, const MonteCarloResult& r) {
  std::size_t n = 0;
  for (const MonteCarloSample& smp : r.samples)
    if (smp.outcome.beta_final.size() == p.balls.size() && p.balls.size() >= 2 &&
        min_contact_clearance(p, smp.outcome.beta_final) < -kOverlapTolerance_rad)
      ++n;
  return n;
}

std::string tables_contact_csv_header() { return tables_csv_header() + ",ball_contact,overlapping_without,overlapping_with"; }

std::string tables_contact_csv_line(const ContactRow& r, BallContact contact) {
  return tables_csv_line(r.summary) + "," + to_string(contact) + "," + std::to_string(r.overlapping_without) + "," +
         std::to_string(r.overlapping_with);
}

std::string tables_csv_line(const CaseSummary& s) {
  const auto inside = reference_pct_mi_inside(s);
  std::ostringstream os;
  os << csv_field(s.table_id) << ',' << csv_field(s.case_id) << ',' << csv_field(s.label) << ',' << csv_opt(s.value)
     << ',' << s.runs << ',' << s.ok << ',' << s.failed << ',' << csv_num(s.mean_x) << ',' << csv_num(s.sem_x) << ','
     << csv_opt(s.reference.mean_1e7) << ',' << csv_num(s.max_x) << ',' << csv_opt(s.reference.max_1e7) << ','
     << csv_num(s.pct_lc) << ',' << csv_opt(s.reference.pct_lc) << ',' << csv_num(s.pct_mi_x) << ','
     << csv_num(s.ci_x[0]) << ',' << csv_num(s.ci_x[1]) << ',' << csv_opt(s.reference.pct_mi) << ','
     << (inside ? (*inside ? "yes" : "no") : "") << ',' << csv_num(s.mean_mag) << ',' << csv_num(s.max_mag) << ','
     << csv_num(s.pct_mi_mag) << ',' << csv_num(s.ci_mag[0]) << ',' << csv_num(s.ci_mag[1]) << ','
     << csv_num(s.settling_mean_s) << ',' << csv_num(s.settling_median_s) << ',' << csv_num(s.settling_max_s) << ','
     << csv_num(s.amplitude_max_mm) << ',' << csv_num(s.wall_time_s);
  return os.str();
}

namespace {

std::string pair_text(double ours, const std::optional<double>& ref, int digits) {
  return num(ours, digits) + " / " + opt_num(ref, digits);
}


std::size_t table_runs(const TableResult& t) {
  std::size_t runs = 0;
  for (const CaseSummary& r : t.rows) runs = std::max(runs, r.runs);
  return runs;
}

std::string contact_name(const TableResult& t) {
  return t.table.contact_variant ? to_string(*t.table.contact_variant) : std::string("none");
}

// What contact changes, in one sentence per table: every case's mean I_r,x and %MI without -> with.
std::string contact_sentence(const TableResult& t) {
  if (t.contact_rows.empty()) return "";
  std::size_t over = 0, over_with = 0, runs = 0, worse_mean = 0, worse_mi = 0;
  for (std::size_t k = 0; k < t.contact_rows.size() && k < t.rows.size(); ++k) {
    const ContactRow& c = t.contact_rows[k];
    over += c.overlapping_without;
    over_with += c.overlapping_with;
    runs += t.rows[k].runs;
    if (c.summary.mean_x > t.rows[k].mean_x) ++worse_mean;
    if (c.summary.pct_mi_x > t.rows[k].pct_mi_x) ++worse_mi;
  }
  std::ostringstream os;
  os << "What ball contact (" << contact_name(t) << ") changes: without it " << over << " of " << runs
     << " final states overlap (" << num(runs ? 100.0 * over / runs : 0.0, 1) << " %), with it " << over_with
     << "; mean I_r,x is higher with contact in " << worse_mean << " of " << t.contact_rows.size() << " cases and %MI in "
     << worse_mi << " of " << t.contact_rows.size();
  for (const Conclusion& k : t.table.conclusions) {
    if (k.check != ConclusionCheck::BeatsAll) continue;
    std::vector<CaseSummary> rows;
    for (const ContactRow& c : t.contact_rows) rows.push_back(c.summary);
    ReproductionTable tt = t.table;
    tt.conclusions = {k};
    for (const Verdict& v : check_conclusions(tt, rows)) os << "; with contact, conclusion (" << k.id << ") is " << to_string(v.outcome);
  }
  os << ".";
  return os.str();
}

}  // namespace

std::string format_table_text(const TableResult& t) {
  std::ostringstream os;
  os << table_heading(t.table) << "\n  source: " << t.table.source << "; ours: " << table_runs(t)
     << " runs per case\n"
     << "  I_r,x (report's definition) in 1e-7 kg m, as \"ours / report\"; %MI with our 95 % Wilson interval;\n"
     << "  in = the report's %MI lies inside that interval; |I_r| = magnitude (extra, not in the report)\n";
  char line[512];
  std::snprintf(line, sizeof line, "  %-20s %5s  %-15s %-15s %-13s %-28s %-3s  %-7s %-20s %s\n", "case", "runs",
                "mean I_r,x", "max I_r,x", "%LC", "%MI [95% CI] / report", "in", "|I_r|", "|I_r| %MI [CI]", "wall");
  os << line;
  for (const CaseSummary& s : t.rows) {
    const auto inside = reference_pct_mi_inside(s);
    const std::string mi = mi_text(s) + " / " + opt_num(s.reference.pct_mi, 2);
    const std::string mag_mi = num(s.pct_mi_mag, 1) + " [" + num(s.ci_mag[0], 1) + ", " + num(s.ci_mag[1], 1) + "]";
    std::snprintf(line, sizeof line, "  %-20s %5zu  %-15s %-15s %-13s %-28s %-3s  %-7s %-20s %.1f s%s\n",
                  s.label.c_str(), s.runs, pair_text(s.mean_x, s.reference.mean_1e7, 2).c_str(),
                  pair_text(s.max_x, s.reference.max_1e7, 2).c_str(), pair_text(s.pct_lc, s.reference.pct_lc, 2).c_str(),
                  mi.c_str(), inside ? (*inside ? "yes" : "no") : "-", num(s.mean_mag, 2).c_str(), mag_mi.c_str(),
                  s.wall_time_s, s.failed ? (" (" + std::to_string(s.failed) + " failed)").c_str() : "");
    os << line;
  }
  for (const CaseSummary& s : t.rows)
    if (!s.reference.note.empty()) os << "  note (" << s.label << "): " << s.reference.note << "\n";
  if (!t.contact_rows.empty()) {
    os << "  the same starts with ball contact (" << contact_name(t)
       << "); overlap = final states whose balls overlap, without / with contact:\n";
    std::snprintf(line, sizeof line, "  %-20s %5s  %-22s %-26s %-9s %-20s %-11s %s\n", "case", "runs",
                  "mean I_r,x (contact)", "%MI (contact) [95% CI]", "|I_r| (c)", "|I_r| %MI (c) [CI]", "overlap", "wall");
    os << line;
    for (const ContactRow& r : t.contact_rows) {
      const CaseSummary& s = r.summary;
      const std::string mag_mi = num(s.pct_mi_mag, 1) + " [" + num(s.ci_mag[0], 1) + ", " + num(s.ci_mag[1], 1) + "]";
      const std::string ov = std::to_string(r.overlapping_without) + " / " + std::to_string(r.overlapping_with);
      std::snprintf(line, sizeof line, "  %-20s %5zu  %-22s %-26s %-9s %-20s %-11s %.1f s%s\n", s.label.c_str(), s.runs,
                    mean_text(s).c_str(), mi_text(s).c_str(), num(s.mean_mag, 2).c_str(),
                    mag_mi.c_str(), ov.c_str(), s.wall_time_s,
                    s.failed ? (" (" + std::to_string(s.failed) + " failed)").c_str() : "");
      os << line;
    }
    os << "  " << contact_sentence(t) << "\n";
  }
  if (!t.table.expectation.empty()) os << "  expected (report): " << t.table.expectation << "\n";
  for (const Verdict& v : t.verdicts) os << "  " << v.one_line() << "\n";
  return os.str();
}

std::string format_table_markdown(const TableResult& t) {
  std::ostringstream os;
  os << "### " << table_heading(t.table) << "\n\n"
     << "Source: " << t.table.source << ". Ours: " << table_runs(t) << " runs per case, wall time "
     << num(t.wall_time_s, 1) << " s.";
  if (!t.table.expectation.empty()) os << " Expected (report): " << t.table.expectation << ".";
  os << "\n\n"
     << "| case | runs | mean I_r,x | report | max I_r,x | report | %LC | report | %MI | 95 % CI | report | in CI | "
        "mean \\|I_r\\| | %MI \\|I_r\\| (95 % CI) | failed | wall [s] |\n"
     << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|:-:|---:|---|---:|---:|\n";
  for (const CaseSummary& s : t.rows) {
    const auto inside = reference_pct_mi_inside(s);
    os << "| " << md_escape(s.label) << " | " << s.runs << " | " << num(s.mean_x, 2) << " | "
       << opt_num(s.reference.mean_1e7, 2) << " | " << num(s.max_x, 2) << " | " << opt_num(s.reference.max_1e7, 2)
       << " | " << num(s.pct_lc, 2) << " | " << opt_num(s.reference.pct_lc, 2) << " | " << num(s.pct_mi_x, 2) << " | "
       << num(s.ci_x[0], 2) << " .. " << num(s.ci_x[1], 2) << " | " << opt_num(s.reference.pct_mi, 2) << " | "
       << (inside ? (*inside ? "yes" : "**no**") : "-") << " | " << num(s.mean_mag, 2) << " | "
       << num(s.pct_mi_mag, 2) << " (" << num(s.ci_mag[0], 1) << " .. " << num(s.ci_mag[1], 1) << ") | " << s.failed
       << " | " << num(s.wall_time_s, 1) << " |\n";
  }
  os << "\n";
  if (!t.contact_rows.empty()) {
    os << "The same cases and starts with `ball_contact: " << contact_name(t)
       << "` (docs/model.md 11; a grid is mapped onto the feasible set, 11.6). Overlap: final states whose balls "
          "overlap, without / with contact.\n\n"
       << "| case | runs | mean I_r,x | mean I_r,x (contact) | %MI (95 % CI) | %MI (contact) (95 % CI) | "
          "mean \\|I_r\\| (contact) | %MI \\|I_r\\| (contact) (95 % CI) | overlap | failed (contact) | wall (contact) [s] |\n"
       << "|---|---:|---:|---:|---|---|---:|---|---:|---:|---:|\n";
    for (std::size_t k = 0; k < t.contact_rows.size() && k < t.rows.size(); ++k) {
      const CaseSummary& a = t.rows[k];
      const CaseSummary& c = t.contact_rows[k].summary;
      os << "| " << md_escape(a.label) << " | " << c.runs << " | " << num(a.mean_x, 2) << " | " << num(c.mean_x, 2)
         << " | " << num(a.pct_mi_x, 2) << " (" << num(a.ci_x[0], 1) << " .. " << num(a.ci_x[1], 1) << ") | "
         << num(c.pct_mi_x, 2) << " (" << num(c.ci_x[0], 1) << " .. " << num(c.ci_x[1], 1) << ") | "
         << num(c.mean_mag, 2) << " | " << num(c.pct_mi_mag, 2) << " (" << num(c.ci_mag[0], 1) << " .. "
         << num(c.ci_mag[1], 1) << ") | " << t.contact_rows[k].overlapping_without << " / "
         << t.contact_rows[k].overlapping_with << " | " << c.failed << " | " << num(c.wall_time_s, 1) << " |\n";
    }
    os << "\n" << contact_sentence(t) << "\n\n";
  }
  for (const CaseSummary& s : t.rows)
    if (!s.reference.note.empty()) os << "Note (" << s.label << "): " << s.reference.note << ".\n\n";
  for (const Verdict& v : t.verdicts) os << "- " << md_escape(v.one_line()) << "\n";
  if (!t.verdicts.empty()) os << "\n";
  return os.str();
}

std::string format_report_markdown(const ReproductionReport& r, const ReproductionOptions& opt) {
  std::ostringstream os;
  os << "# Reproduction of the 2003 report's tables\n\n"
     << "Generated by `abuopt reproduce` on " << local_time_text() << ".\n\n"
     << "- command: `" << (opt.command_line.empty() ? "abuopt reproduce" : opt.command_line) << "`\n"
     << "- wall time: " << num(r.wall_time_s, 1) << " s on " << r.concurrency << " thread"
     << (r.concurrency == 1 ? "" : "s") << "\n";
  if (!opt.runs_note.empty()) os << "- " << opt.runs_note << "\n";
  os << "- the tables show I_r,x (the report's definition) in 1e-7 kg m; %MI with I_r,x >= m_I e = 2.072e-6 kg m, "
        "with our 95 % Wilson score interval; \"in CI\" says whether the report's %MI lies inside it.\n"
     << "- |I_r| (the magnitude of the residual imbalance vector) is not in the report: extra columns.\n\n"
     << terms_markdown();
  const std::vector<Verdict> verdicts = r.verdicts();
  os << "## Verdicts on the report's conclusions\n\n";
  if (verdicts.empty()) os << "(no conclusion was tested: the tables that carry them were not run)\n";
  for (const Verdict& v : verdicts) os << "- " << md_escape(v.one_line()) << "\n";
  os << "\nCONFIRMED: the claimed direction holds and the intervals separate (Wilson intervals of %MI do not "
        "overlap; means differ by more than 1.96 combined standard errors). WEAK: the direction holds on the "
        "point estimates only. NOT REPRODUCED: it does not hold.\n\n";
  os << "## Tables\n\n";
  for (const TableResult& t : r.tables) os << format_table_markdown(t);
  os << "## Plots\n\n";
  if (r.plots.empty()) os << "(none yet)\n";
  for (const PlotNote& p : r.plots) {
    if (p.made)
      os << "- " << p.name << ": ![" << p.name << "](" << fs::path(p.png).lexically_relative(opt.out_dir).string()
         << ") (PDF: `" << fs::path(p.png).replace_extension(".pdf").lexically_relative(opt.out_dir).string()
         << "`; data: `" << fs::path(p.csv).lexically_relative(opt.out_dir).string() << "`; script: `"
         << fs::path(p.png).replace_extension(".gp").lexically_relative(opt.out_dir).string()
         << "`, run in its folder)\n";
    else
      os << "- " << p.name << ": " << p.message << "\n";
  }
  os << "\n## Settings\n\n";
  if (!r.tables.empty() && !r.tables.front().table.cases.empty()) {
    const MonteCarloStudy& s = r.tables.front().table.cases.front().study;
    const AbuParameters& a = s.setup.abu;
    const SimulationOptions& o = s.setup.options;
    os << "- ABU (first case; a table may vary one of these): M_T " << a.table_mass_kg << " kg, b "
       << a.damping_Ns_per_m << " N s/m, k " << a.stiffness_N_per_m << " N/m, L " << a.ball_track_radius_m
       << " m, m_I " << a.imbalance_mass_kg << " kg, e " << a.eccentricity_m << " m, mu " << a.friction_mu << ", "
       << a.balls.size() << " balls of " << (a.balls.empty() ? 0.0 : a.balls.front().mass_kg) << " kg, natural frequency "
       << num(a.natural_frequency_hz(), 2) << " Hz\n"
       << "- simulation: " << to_string(o.method) << ", integrator " << to_string(o.backend) << " (" << o.erk_table
       << "), rtol " << o.rtol << ", atol " << o.atol << ", end time "
       << (o.end_time_s > 0 ? num(o.end_time_s, 1) + " s" : std::string("twice the profile duration")) << "\n"
       << "- motor: " << (s.setup.motor.kind == MotorKind::Ideal ? "ideal" : "PI") << "\n";
  }
  for (const TableResult& t : r.tables) {
    if (t.table.cases.empty()) continue;
    const InitialConditionDesign d = study_design(t.table.cases.front().study);
    os << "- " << table_heading(t.table) << " (`" << t.table.file << "`): design " << to_string(d.kind);
    if (d.kind == InitialConditionKind::Grid) os << " " << d.grid_points_per_axis << "^" << d.balls;
    os << ", " << t.table.cases.front().study.runs << " runs per case, " << t.table.cases.size() << (t.table.cases.size() == 1 ? " case\n" : " cases\n");
  }
  os << "\nPer-run data: `runs/<table>/<case>.csv` (one line per run); all rows: `tables.csv`.\n";
  if (!r.tables_contact_csv_path.empty())
    os << "With ball contact: `runs/<table>/<case>_contact_<model>.csv`; rows: `tables_contact.csv`.\n";
  return os.str();
}

}  // namespace abuopt
