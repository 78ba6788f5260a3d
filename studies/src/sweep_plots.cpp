// The plots of a design sweep (sweep.hpp): gnuplot scripts that write PNG and PDF and run from
// their own folder (every file name in them is relative to it).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>

#include "abuopt/common/gnuplot.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/plot_style.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/studies/sweep.hpp"

namespace abuopt {

namespace {

namespace fs = std::filesystem;

// Writes <dir>/<stem>.gp (PNG, then PDF when this gnuplot has the cairo terminals) and runs it in dir.
std::string run_plot(const Gnuplot& gp, const fs::path& dir, const std::string& stem, const std::string& body,
                     int width_px, int height_px) {
  const bool cairo = !gp.available() || gp.terminal() == "pngcairo";
  // The one plot style (common/plot_style.hpp): its terminals, fonts and line styles. The body is
  // written twice (PNG, then PDF) rather than `replot`, which does not repeat a multiplot.
  std::ostringstream s;
  s << "# written by abuopt; run from this folder: gnuplot " << stem << ".gp\n"
    << plot_style::png_terminal_line(cairo ? "pngcairo" : "png", width_px, height_px)
    << "set output " << Gnuplot::quote(stem + ".png") << "\n"
    << plot_style::preamble() << body;
  if (cairo)
    s << plot_style::pdf_terminal_line(width_px, height_px) << "set output " << Gnuplot::quote(stem + ".pdf") << "\n"
      << body;
  s << "set output\n";
  const fs::path script = dir / (stem + ".gp");
  write_file_atomic(script, s.str());
  if (!gp.available()) return stem + ": skipped: gnuplot not found (script " + script.string() + ")";
  const fs::path png = dir / (stem + ".png"), log = dir / (stem + ".log");
  std::error_code ec;
  fs::remove(png, ec);
  const int rc = gp.run_script(fs::absolute(script).string(), fs::absolute(dir).string(), fs::absolute(log).string());
  if (rc != 0 || !fs::is_regular_file(png, ec) || fs::file_size(png, ec) == 0) {
    std::ifstream in(log);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.size() > 400) text.resize(400);
    return stem + ": failed: gnuplot " + (rc != 0 ? "exited with status " + std::to_string(rc) : "made no PNG") +
           " (" + log.string() + "): " + text;
  }
  return "wrote " + png.string() + (cairo ? " and " + (dir / (stem + ".pdf")).string() : std::string());
}

// 1-based column numbers of sweep.csv (write_sweep_csv's layout).
struct Columns {
  int objective = 5, hw = 6;
  int feasible = 4;
  int first_variable = 8;
};

std::string runs_text(const SweepResult& r) {
  for (const auto& p : r.points) {
    auto it = p.e.metrics.find("runs");
    if (it != p.e.metrics.end()) return format_number(it->second) + " Monte Carlo runs per point";
  }
  return "Monte Carlo per point";
}

bool any_half_width(const problems::StartupProfileProblem& problem, const SweepResult& r) {
  for (const auto& p : r.points)
    if (std::isfinite(objective_half_width(problem.settings(), p.e))) return true;
  return false;
}

// Objective against one variable column, error bars when there are half-widths, infeasible marked.
std::string curve_plot(const std::string& csv, int xcol, bool bars, bool lines) {
  const Columns c;
  std::ostringstream s;
  const std::string q = Gnuplot::quote(csv);
  s << "plot ";
  if (lines)
    s << q << " skip 1 using " << xcol << ":" << c.objective << " with lines lc rgb '#3b6fb6' lw 1.5 notitle, \\\n     ";
  if (bars)
    s << q << " skip 1 using " << xcol << ":" << c.objective << ":" << c.hw
      << " with yerrorbars pt 7 ps 0.6 lc rgb '#3b6fb6' title 'mean +- 95 % half-width' noenhanced, \\\n     ";
  else
    s << q << " skip 1 using " << xcol << ":" << c.objective << " with points pt 7 ps 0.6 lc rgb '#3b6fb6' title 'objective', \\\n     ";
  s << q << " skip 1 using " << xcol << ":($" << c.feasible << " == 0 ? $" << c.objective
    << " : NaN) with points pt 6 ps 1.4 lc rgb '#d62728' title 'infeasible (a constraint violated): open red circle' noenhanced\n";
  return s.str();
}

void write_map_data(const fs::path& path, const SweepResult& r, const std::vector<std::size_t>& swept) {
  AtomicFile f(path);
  f << "# x y objective pct_mi feasible (blank line between scans of the first variable; NaN: failed / not feasible)\n";
  double last = std::numeric_limits<double>::quiet_NaN();
  for (const auto& p : r.points) {
    const double x = p.x[swept[0]], y = p.x[swept[1]];
    if (!std::isnan(last) && x != last) f << "\n";
    last = x;
    auto pm = p.e.metrics.find("pct_mi");
    f << format_number(x) << " " << format_number(y) << " " << (p.e.ok ? format_number(p.e.objective) : "NaN") << " "
      << (pm != p.e.metrics.end() ? format_number(pm->second) : "NaN") << " " << (p.feasible ? "1" : "NaN") << "\n";
  }
  f.commit();
}

// The axis range of a grid variable with half a cell beyond each end (image cells are centred on
// the points).
std::string cell_range(const opt::Variable& v, std::size_t levels) {
  const double half = (v.upper - v.lower) / static_cast<double>(levels - 1) / 2;
  std::ostringstream s;
  s << '[' << format_number(v.lower - half) << ':' << format_number(v.upper + half) << ']';
  return s.str();
}

// The colour range of one map column: the finite minimum and maximum over the feasible points, the
// region a reader looks for (infeasible cells, often far worse, saturate at the top colour and are
// greyed); over every point when fewer than two are feasible ("[*:*]" when none has a value).
std::string value_range(const SweepResult& r, bool pct_mi) {
  std::size_t feasible = 0;
  for (const auto& p : r.points) feasible += p.feasible && p.e.ok;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& p : r.points) {
    if (feasible >= 2 && !p.feasible) continue;
    double v = p.e.objective;
    if (pct_mi) {
      auto it = p.e.metrics.find("pct_mi");
      v = it == p.e.metrics.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
    } else if (!p.e.ok) {
      continue;
    }
    if (!std::isfinite(v)) continue;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (!(lo <= hi)) return "[*:*]";
  if (lo == hi) hi = lo + 1;
  std::ostringstream s;
  s << '[' << format_number(lo) << ':' << format_number(hi) << ']';
  return s.str();
}

// A point marked on a map: its coordinates and the key entry.
struct MapMark {
  double x = 0, y = 0;
  std::string title;
  std::string style;  // gnuplot point style
};

// The map of one column: cells coloured by the value (viridis), contours, the value in each cell;
// infeasible cells greyed (a translucent grey veil over the colour), the best feasible point and
// the 2003 report's design marked.
std::string map_body(const std::string& dat, const std::string& title, const std::string& xl, const std::string& yl,
                     const std::string& cbl, int zcol, const std::string& xrange, const std::string& yrange,
                     const std::string& cbrange, const std::vector<MapMark>& marks) {
  std::ostringstream s;
  const std::string q = Gnuplot::quote(dat);
  // the cells' colour clamped to the colour range (cells beyond it take the end colour)
  const std::string lo = cbrange.substr(1, cbrange.find(':') - 1), hi = cbrange.substr(cbrange.find(':') + 1);
  const std::string hi_v = hi.substr(0, hi.size() - 1);
  const std::string clamp = lo == "*" ? std::string("($" + std::to_string(zcol) + ")")
                                      : "(cl($" + std::to_string(zcol) + "))";
  s << "reset\n" << plot_style::preamble() << "unset grid\nset title " << plot_style::literal(title) << "\nset xlabel " << plot_style::literal(xl)
    << "\nset ylabel " << plot_style::literal(yl) << "\nset cblabel " << plot_style::literal(cbl) << "\n"
    << "set view map\nset xrange " << xrange << "\nset yrange " << yrange << "\nset cbrange " << cbrange
    << "\nset tics out\n"
    // viridis (perceptually uniform, readable in grey and by colour-blind readers)
    << "set palette defined (0 '#440154', 0.25 '#3b528b', 0.5 '#21918c', 0.75 '#5ec962', 1 '#fde725')\n"
    << "set key at screen 0.5, 0.06 center horizontal maxrows 2 box opaque samplen 1.5\nset bmargin 8\n"
    << "set contour base\nset cntrparam levels auto 6\nset cntrlabel onecolor format '%.3g' font ',8' start 5 interval 60\n"
    << "set style textbox opaque noborder fillcolor rgb '#ffffff'\n";
  if (lo != "*") s << "cl(v) = v > " << hi_v << " ? " << hi_v << " : (v < " << lo << " ? " << lo << " : v)\n";
  for (std::size_t k = 0; k < marks.size(); ++k)
    s << "$mark" << k << " << EOD\n" << format_number(marks[k].x) << " " << format_number(marks[k].y) << " 0\nEOD\n";
  s << "splot " << q << " using 1:2:" << clamp << " with image nocontour notitle, \\\n"
    // infeasible cells (column 5 NaN) under a nearly opaque light-grey veil: their value is the label
    << "      " << q << " using 1:2:(0):(225):(225):(225):(valid(5) ? 0 : 235) with rgbalpha nocontour notitle, \\\n"
    << "      " << q << " using 1:2:" << zcol << " nosurface with lines lc rgb 'black' lw 1 notitle, \\\n"
    << "      " << q << " using 1:2:(0):(valid(" << zcol << ") ? sprintf('%.3g', $" << zcol
    << ") : 'failed') nocontour with labels boxed font ',8' notitle, \\\n"
    << "      keyentry with boxes fs solid 1.0 lc rgb '#e1e1e1' title 'infeasible (a constraint violated): grey', \\\n"
    << "      keyentry with lines lc rgb 'black' lw 1 title 'contours of the colour value'";
  for (std::size_t k = 0; k < marks.size(); ++k)
    s << ", \\\n      $mark" << k << " using 1:2:3 nocontour with points " << marks[k].style << " title "
      << plot_style::literal(marks[k].title);
  s << "\n";
  return s.str();
}

// The best feasible point of the sweep and the 2003 report's design (its final profile, when every
// swept variable is a segment's end frequency f<k> or duration dt<k> of a 3-segment template).
std::vector<MapMark> map_marks(const problems::StartupProfileProblem& problem, const SweepResult& r,
                               const std::vector<std::size_t>& swept) {
  std::vector<MapMark> marks;
  const SweepPoint* best = nullptr;
  for (const auto& p : r.points)
    if (p.feasible && p.e.ok && (!best || p.e.objective < best->e.objective)) best = &p;
  if (best)
    marks.push_back({best->x[swept[0]], best->x[swept[1]],
                     "best feasible point (objective " + format_significant(best->e.objective, 4) + ")",
                     "pt 2 ps 2.6 lw 3 lc rgb '#d62728'"});
  const auto vars = problem.variables();
  const StartupProfile report = StartupProfile::report_final();
  const auto& segs = report.segments();
  auto report_value = [&](const std::string& name) -> std::optional<double> {
    const bool f = name.rfind("f", 0) == 0, dt = name.rfind("dt", 0) == 0;
    if (!f && !dt) return std::nullopt;
    const std::string digits = name.substr(dt ? 2 : 1);
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
    const std::size_t k = std::stoul(digits);
    if (k < 1 || k > segs.size()) return std::nullopt;
    return dt ? segs[k - 1].duration_s : segs[k - 1].end_frequency_hz;
  };
  // Another segment count is another family: the 2003 design is no point of it.
  if (problem.settings().design.segments.size() != segs.size()) return marks;
  const auto rx = report_value(vars[swept[0]].name), ry = report_value(vars[swept[1]].name);
  if (rx && ry)
    marks.push_back({*rx, *ry, "2003 report design (" + vars[swept[0]].name + " " + format_number(*rx) + ", " +
                                   vars[swept[1]].name + " " + format_number(*ry) + ")",
                     "pt 6 ps 2.8 lw 3 lc rgb '#ff00ff'"});
  return marks;
}

}  // namespace

std::vector<std::string> write_sweep_plots(const fs::path& dir, const problems::StartupProfileProblem& problem,
                                           const SweepResult& r) {
  std::vector<std::string> out;
  if (r.points.empty()) return {"no plot: no point evaluated"};
  const Gnuplot gp;
  const auto vars = problem.variables();
  const auto& swept = r.plan.swept;
  const Columns c;
  const std::string ylabel = objective_label(problem.settings());
  const bool bars = any_half_width(problem, r);
  const std::string runs = runs_text(r);
  const bool full_grid = r.plan.method == SweepMethod::Grid && r.points.size() == r.plan.x.size();

  if (swept.size() == 2 && full_grid) {
    write_map_data(dir / "sweep_map.dat", r, swept);
    const std::string xl = variable_label(vars[swept[0]].name), yl = variable_label(vars[swept[1]].name);
    const std::string xr = cell_range(vars[swept[0]], r.plan.levels[0]), yr = cell_range(vars[swept[1]], r.plan.levels[1]);
    const std::vector<MapMark> marks = map_marks(problem, r, swept);
    const std::string note = "; colour scale over the feasible points";
    out.push_back(run_plot(gp, dir, "sweep_map",
                           map_body("sweep_map.dat", ylabel + " (" + runs + note + ")", xl, yl, ylabel, 3, xr, yr,
                                    value_range(r, false), marks),
                           900, 800));
    out.push_back(run_plot(gp, dir, "sweep_map_pct_mi",
                           map_body("sweep_map.dat", "%MI (" + runs + note + ")", xl, yl, "%MI [%]", 4, xr, yr,
                                    value_range(r, true), marks),
                           900, 800));
    return out;
  }
  std::ostringstream s;
  s << "set datafile separator ','\nset grid\nset offsets graph 0.03, graph 0.03, graph 0.05, graph 0.05\n"
    << (swept.size() == 1 ? "set key top right\n" : "set key below\n") << "set ylabel " << Gnuplot::quote(ylabel) << "\n";
  if (swept.size() == 1) {
    s << "set title " << Gnuplot::quote(ylabel + " (" + runs + ")") << "\nset xlabel "
      << Gnuplot::quote(variable_label(vars[swept[0]].name)) << "\n"
      << curve_plot("sweep.csv", c.first_variable + static_cast<int>(swept[0]), bars,
                    r.plan.method == SweepMethod::Grid);
    out.push_back(run_plot(gp, dir, "sweep", s.str(), 900, 600));
    return out;
  }
  // Several variables (or a scattered design): one panel per swept variable.
  const int n = static_cast<int>(swept.size());
  const int cols = n <= 3 ? n : 3, rows = (n + cols - 1) / cols;
  s << "set multiplot layout " << rows << "," << cols << " title "
    << Gnuplot::quote(ylabel + " against each swept variable (" + runs + ")") << "\n";
  for (int k = 0; k < n; ++k) {
    s << "set xlabel " << Gnuplot::quote(variable_label(vars[swept[static_cast<std::size_t>(k)]].name)) << "\n"
      << (k == 0 ? "" : "unset key\n")
      << curve_plot("sweep.csv", c.first_variable + static_cast<int>(swept[static_cast<std::size_t>(k)]), bars, false);
  }
  s << "unset multiplot\n";
  out.push_back(run_plot(gp, dir, "sweep", s.str(), 450 * cols, 380 * rows + 40));
  return out;
}

}  // namespace abuopt
