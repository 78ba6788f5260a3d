#include "reproduction_plots.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "abuopt/common/plot_style.hpp"
#include "abuopt/core/equilibrium_set.hpp"
#include "output_dir.hpp"
#include "study_text.hpp"

namespace abuopt::studies_detail {

namespace fs = std::filesystem;

namespace {

const MonteCarloResult* find_result(const TableResult& t, const std::string& case_id) {
  for (std::size_t i = 0; i < t.table.cases.size() && i < t.results.size(); ++i)
    if (t.table.cases[i].id == case_id) return &t.results[i];
  return nullptr;
}

PlotNote finish_note(PlotNote n, const PlotStatus& st) {
  n.made = st.ran();
  n.png = st.png_path;
  n.message = st.message;
  return n;
}

// The studied parameter as a typeset axis label: the report's symbols where known.
std::string parameter_label(const ReproductionTable& t) {
  const std::string& n = t.parameter_name;
  const std::string unit = t.parameter_unit.empty() ? "" : " [" + plot_style::escape(t.parameter_unit) + "]";
  if (n == "mu") return plot_style::kMu;
  if (n == "dt") return "Δt" + unit;
  if (n == "dt2") return "Δt_2" + unit;
  if (n == "dt3") return "Δt_3" + unit;
  if (n == "total") return "total startup time" + unit;
  return plot_style::escape(n) + unit;
}

}  // namespace

PlotNote plot_trend(const Gnuplot& gp, const TableResult& t, const PlotRequest& req, const fs::path& dir) {
  PlotNote note;
  note.name = req.name;
  note.csv = (dir / (req.name + ".csv")).string();
  std::ostringstream csv;
  csv << "value,mean_x_1e7,pct_mi_x,pct_mi_x_ci_lo,pct_mi_x_ci_hi,ref_mean_1e7,ref_pct_mi,mean_mag_1e7,pct_mi_mag,"
         "mean_x_ci_lo_1e7,mean_x_ci_hi_1e7\n";
  std::size_t points = 0, reference_points = 0;
  for (const CaseSummary& s : t.rows) {
    if (!s.value || s.ok == 0) continue;
    ++points;
    if (s.reference.mean_1e7 || s.reference.pct_mi) ++reference_points;
    // 95 % interval of the mean: mean +- 1.96 standard errors (the tables' "+-").
    csv << csv_num(*s.value) << ',' << csv_num(s.mean_x) << ',' << csv_num(s.pct_mi_x) << ',' << csv_num(s.ci_x[0])
        << ',' << csv_num(s.ci_x[1]) << ',' << csv_opt(s.reference.mean_1e7) << ',' << csv_opt(s.reference.pct_mi)
        << ',' << csv_num(s.mean_mag) << ',' << csv_num(s.pct_mi_mag) << ',' << csv_num(s.mean_x - 1.96 * s.sem_x)
        << ',' << csv_num(s.mean_x + 1.96 * s.sem_x) << '\n';
  }
  write_text_file(note.csv, csv.str());
  if (points == 0) {
    note.message = "skipped: no case with a value";
    return note;
  }
  // The two series side by side at each value (their error bars would overlap where the axes'
  // scales put them at the same height): shifted by +-12 % of the closest spacing of the values.
  std::vector<double> values;
  for (const CaseSummary& s : t.rows)
    if (s.value && s.ok > 0) values.push_back(*s.value);
  std::sort(values.begin(), values.end());
  double spacing = 0;
  for (std::size_t i = 1; i < values.size(); ++i)
    if (values[i] > values[i - 1] && (spacing == 0 || values[i] - values[i - 1] < spacing)) spacing = values[i] - values[i - 1];
  const std::string dx = csv_num(0.12 * spacing);
  const std::string data = Gnuplot::quote(req.name + ".csv");
  // Which axis is which is said in words and by line and marker, not by colour alone: left axis
  // mean I_r,x (solid line, filled circles), right axis %MI (dashed line, filled squares).
  std::ostringstream b;
  b << "set datafile separator ','\n"
    << "set datafile missing ''\n"
    << "set title " << plot_style::literal(table_heading(t.table)) << "\n"
    << "set xlabel " << plot_style::typeset(parameter_label(t.table)) << "\n"
    << "set ylabel '← left axis: mean " << plot_style::kIrx << " (solid, ●)' tc lt 1\n"
    << "set y2label 'right axis: " << plot_style::kPctMi << " (dashed, ■) →' tc lt 4\n"
    << "set ytics nomirror tc lt 1\nset y2tics tc lt 4\nset yrange [0:*]\nset y2range [0:*]\nset grid\n"
    << "set key outside below maxrows 2\n"
    << "set offsets graph 0.04, graph 0.04, 0, 0\n"
    << "plot " << data << " skip 1 using ($1-" << dx << "):2:10:11 with yerrorlines lt 1 pt 7 "
    << "title 'mean I_{r,x} (left axis), 95 % interval', \\\n"
    << "     " << data << " skip 1 using ($1+" << dx << "):3:4:5 axes x1y2 with yerrorlines lt 4 dt 2 pt 5 "
    << "title '%MI (right axis), 95 % Wilson interval'";
  if (reference_points > 0)
    b << ", \\\n     " << data << " skip 1 using ($1-" << dx << "):6 with points lt 1 pt 6 ps 1.8 title 'mean (2003 report, left)', \\\n"
      << "     " << data << " skip 1 using ($1+" << dx << "):7 axes x1y2 with points lt 4 pt 4 ps 1.8 title '%MI (2003 report, right)'";
  b << "\n";
  const std::string png = (dir / (req.name + ".png")).string();
  return finish_note(note, gp.run(b.str(), (dir / (req.name + ".gp")).string(), png, 900, 650));
}

PlotNote plot_final_positions(const Gnuplot& gp, const TableResult& t, const PlotRequest& req, const fs::path& dir) {
  PlotNote note;
  note.name = req.name;
  note.csv = (dir / (req.name + ".csv")).string();
  std::vector<const MonteCarloResult*> res;
  std::vector<std::string> labels;
  std::size_t rows = 0;
  for (const std::string& id : req.case_ids) {
    const MonteCarloResult* r = find_result(t, id);
    if (!r) continue;
    res.push_back(r);
    labels.push_back(t.table.find_case(id)->label);
    rows = std::max(rows, r->samples.size());
  }
  std::ostringstream csv;
  for (std::size_t k = 0; k < res.size(); ++k)
    csv << (k ? "," : "") << "beta1_" << req.case_ids[k] << "_rad,beta2_" << req.case_ids[k] << "_rad";
  csv << '\n';
  for (std::size_t i = 0; i < rows; ++i) {
    for (std::size_t k = 0; k < res.size(); ++k) {
      if (k) csv << ',';
      const auto& smp = res[k]->samples;
      if (i < smp.size() && smp[i].outcome.ok() && smp[i].outcome.beta_final.size() >= 2)
        csv << csv_num(smp[i].outcome.beta_final[0]) << ',' << csv_num(smp[i].outcome.beta_final[1]);
      else
        csv << ',';
    }
    csv << '\n';
  }
  write_text_file(note.csv, csv.str());
  XYLinesPlot p;
  p.csv_path = note.csv;
  p.png_path = (dir / (req.name + ".png")).string();
  p.width_px = 800;
  p.labels = {"Final ball positions (cf. report fig. 4.7)", plot_style::kBeta1, plot_style::kBeta2};
  p.angle_x = p.angle_y = true;
  p.key = "outside below";
  p.height_px = 860;
  for (std::size_t k = 0; k < res.size(); ++k)
    p.series.push_back({static_cast<int>(2 * k + 1), static_cast<int>(2 * k + 2), labels[k], "points"});
  return finish_note(note, gp.xy_lines(p));
}

PlotNote plot_settling(const Gnuplot& gp, const TableResult& t, const PlotRequest& req, const fs::path& dir) {
  PlotNote note;
  note.name = req.name;
  note.csv = (dir / (req.name + ".csv")).string();
  const MonteCarloResult* r = find_result(t, req.case_ids.front());
  std::ostringstream csv;
  csv << "settling_time_s\n";
  std::size_t n = 0;
  if (r)
    for (const MonteCarloSample& s : r->samples)
      if (s.outcome.ok() && s.outcome.settled) {
        csv << csv_num(s.outcome.settling_time_s) << '\n';
        ++n;
      }
  write_text_file(note.csv, csv.str());
  if (n < 2) {
    note.message = "skipped: fewer than two settled runs";
    return note;
  }
  HistogramPlot p;
  p.csv_path = note.csv;
  p.png_path = (dir / (req.name + ".png")).string();
  p.labels = {"Settling time, " + plot_style::escape(t.table.find_case(req.case_ids.front())->label) + " (" +
                  std::to_string(n) + " settled runs)",
              "settling time [s]", "runs per bin"};
  p.bins = 40;
  return finish_note(note, gp.histogram(p));
}

PlotNote plot_equilibrium(const Gnuplot& gp, const TableResult& t, const PlotRequest& req, const fs::path& dir) {
  PlotNote note;
  note.name = req.name;
  note.csv = (dir / (req.name + ".csv")).string();
  const ReproductionCase* c = t.table.find_case(req.case_ids.front());
  const MonteCarloResult* r = find_result(t, req.case_ids.front());
  if (!c || !r || c->study.setup.abu.balls.size() != 2) {
    note.message = "skipped: needs a two-ball case that ran";
    return note;
  }
  const double f = c->study.setup.profile.final_frequency_hz();
  const EquilibriumSet set(c->study.setup.abu);
  const std::size_t n = 96;
  const EquilibriumGrid g = set.grid(f, n);
  // Grid data for gnuplot's image style: one scan per beta_1, blank line between scans.
  const std::string grid_csv = (dir / (req.name + ".grid.csv")).string();
  {
    std::ostringstream os;
    os << "beta1_rad,beta2_rad,in_set,steady_amplitude_mm\n";
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j)
        os << csv_num(g.beta(i)) << ',' << csv_num(g.beta(j)) << ',' << int(g.in_set[g.index(i, j)]) << ','
           << csv_num(g.amplitude_mm[g.index(i, j)]) << '\n';
      os << '\n';
    }
    write_text_file(grid_csv, os.str());
  }
  {
    std::ostringstream os;
    os << "beta1_final_rad,beta2_final_rad,ir_x_1e7\n";
    for (const MonteCarloSample& s : r->samples)
      if (s.outcome.ok() && s.outcome.beta_final.size() == 2)
        os << csv_num(s.outcome.beta_final[0]) << ',' << csv_num(s.outcome.beta_final[1]) << ','
           << csv_num(s.outcome.residual_imbalance_x_kgm * 1e7) << '\n';
    write_text_file(note.csv, os.str());
  }
  // Frictionless balancing positions: beta = +- arccos(-m_I e / (2 m L)).
  const AbuParameters& a = c->study.setup.abu;
  const double ratio = a.imbalance_kgm() / (2.0 * a.balls[0].mass_kg * a.ball_track_radius_m);
  const std::string grid_data = Gnuplot::quote(req.name + ".grid.csv");
  const std::string final_data = Gnuplot::quote(req.name + ".csv");
  std::ostringstream b;
  b << "set datafile separator ','\n"
    << "set title 'Final positions and the equilibrium set at " << num(f, 1) << " Hz (μ = " << short_num(a.friction_mu)
    << ", set covers " << num(100.0 * g.coverage(), 1) << " % of the square)'\n"
    << "set xlabel '" << plot_style::kBeta1 << "'\nset ylabel '" << plot_style::kBeta2 << "'\nset size square\n"
    << plot_style::angle_axis("x") << plot_style::angle_axis("y")
    << "set palette defined (0 '" << plot_style::kOutOfSet << "', 1 '" << plot_style::kInSet << "')\n"
    << "set cbrange [0:1]\nunset colorbox\nset grid front\n"
    << "set key outside below\n";
  if (ratio < 1.0) {
    const double bb = std::acos(-ratio);
    b << "$balancing << EOD\n" << csv_num(bb) << "," << csv_num(2 * M_PI - bb) << "\n"
      << csv_num(2 * M_PI - bb) << "," << csv_num(bb) << "\nEOD\n";
  }
  b << "plot " << grid_data << " skip 1 using 1:2:3 with image notitle, \\\n"
    << "     NaN with boxes fs solid 1.0 lc rgb '" << plot_style::kInSet << "' title 'in the equilibrium set', \\\n"
    << "     NaN with boxes fs solid 1.0 border lc rgb '#bbbbbb' lc rgb '" << plot_style::kOutOfSet
    << "' title 'outside it', \\\n"
    << "     " << final_data << " skip 1 using 1:2 with points pt 7 ps 0.5 lc rgb '#000000' title 'final positions'";
  if (ratio < 1.0)
    b << ", \\\n     $balancing using 1:2 with points pt 3 ps 3 lw 2 lc rgb '" << plot_style::kRed
      << "' title 'frictionless balancing positions'";
  b << "\n";
  const std::string png = (dir / (req.name + ".png")).string();
  return finish_note(note, gp.run(b.str(), (dir / (req.name + ".gp")).string(), png, 820, 900));
}

}  // namespace abuopt::studies_detail
