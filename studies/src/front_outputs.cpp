// Two-objective problems of `abuopt compare`: the table, the CSVs and the front plots
// (front_comparison.hpp).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/gnuplot.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/plot_style.hpp"
#include "abuopt/common/text.hpp"
#include "abuopt/studies/front_comparison.hpp"
#include "abuopt/studies/sweep.hpp"

namespace abuopt {

namespace {

namespace fs = std::filesystem;

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size();
  return m % 2 ? v[m / 2] : 0.5 * (v[m / 2 - 1] + v[m / 2]);
}

std::string fixed(double v, int digits) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(digits) << v;
  return os.str();
}

std::vector<std::string> methods_of(const FrontProblem& fp) {
  std::vector<std::string> out;
  for (const FrontMethod& m : fp.methods) out.push_back(m.label);
  return out;
}

std::string x_text(const std::vector<double>& x) {
  std::string s;
  for (double v : x) {
    if (!s.empty()) s += ' ';
    s += format_number(v);
  }
  return s;
}

}  // namespace

std::string format_front_table(const FrontComparison& c) {
  std::ostringstream os;
  for (const FrontProblem& fp : c.problems) {
    os << "\nfront " << fp.label << ": objective against " << fp.second_objective << ", " << fp.max_evaluations
       << " evaluations per run, " << fp.seeds << (fp.seeds == 1 ? " run" : " runs") << " per method; hypervolume against ("
       << format_number(fp.reference.first) << ", " << format_number(fp.reference.second) << ")\n";
    os << std::left << std::setw(18) << "method" << std::right << std::setw(6) << "runs" << std::setw(8) << "evals"
       << std::setw(28) << "hv in sample [range]" << std::setw(28) << "hv out of sample [range]" << std::setw(14)
       << "points out/in" << "\n";
    for (const std::string& method : methods_of(fp)) {
      std::vector<double> in, out, evals;
      std::size_t points_in = 0, points_out = 0;
      bool validated = false;
      for (const FrontRun& r : c.runs) {
        if (r.problem != fp.label || r.method != method) continue;
        in.push_back(r.hv_in);
        out.push_back(r.hv_out);
        evals.push_back(static_cast<double>(r.evaluations));
        points_in += r.points.size();
        points_out += r.points_out;
        validated = validated || r.validated;
      }
      if (in.empty()) continue;
      auto cell = [](const std::vector<double>& v) {
        return fixed(median(v), 2) + " [" + fixed(*std::min_element(v.begin(), v.end()), 2) + " - " +
               fixed(*std::max_element(v.begin(), v.end()), 2) + "]";
      };
      os << std::left << std::setw(18) << method << std::right << std::setw(6) << in.size() << std::setw(8)
         << static_cast<long>(std::lround(median(evals))) << std::setw(28) << cell(in) << std::setw(28)
         << (validated ? cell(out) : std::string("-")) << std::setw(14)
         << ((validated ? std::to_string(points_out) : std::string("-")) + "/" + std::to_string(points_in)) << "\n";
    }
  }
  return os.str();
}

void write_front_outputs(const FrontComparison& c, const std::string& directory, opt::WrittenFiles& written,
                         bool make_plots) {
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec) throw ConfigError("output directory '" + directory + "' cannot be created: " + ec.message());
  const fs::path dir(directory);
  auto commit = [&](AtomicFile& f) {
    f.commit();
    written.files.push_back(f.path().string());
  };
  {
    AtomicFile f(dir / "fronts.csv");
    f << "problem,method,run,point,objective,second,non_dominated,validated_objective,validated_second,"
         "validated_feasible,x\n";
    for (const FrontRun& r : c.runs)
      for (std::size_t i = 0; i < r.points.size(); ++i) {
        const FrontPoint& p = r.points[i];
        f << csv_field(r.problem) << "," << csv_field(r.method) << "," << r.run << "," << i << ","
          << csv_number(p.objective) << "," << csv_number(p.second) << "," << (p.non_dominated ? 1 : 0) << ",";
        if (p.validation)
          f << (p.validation->ok ? csv_number(p.validation->objective) : std::string()) << ","
            << csv_number(p.validated_second) << "," << (p.validated_feasible ? 1 : 0) << ",";
        else
          f << ",,,";
        f << x_text(p.x) << "\n";
      }
    commit(f);
  }
  {
    AtomicFile f(dir / "hypervolume.csv");
    f << "problem,method,run,evaluations,budget,inner_budget,hv_in,hv_out,points_in,points_out,"
         "reference_objective,reference_second,validated,reason,wall_time_s\n";
    for (const FrontRun& r : c.runs) {
      const auto fp = std::find_if(c.problems.begin(), c.problems.end(),
                                   [&](const FrontProblem& p) { return p.label == r.problem; });
      f << csv_field(r.problem) << "," << csv_field(r.method) << "," << r.run << "," << r.evaluations << ","
        << r.budget << "," << r.inner_budget << "," << csv_number(r.hv_in) << ","
        << (r.validated ? csv_number(r.hv_out) : std::string()) << "," << r.points.size() << ","
        << (r.validated ? std::to_string(r.points_out) : std::string()) << "," << csv_number(fp->reference.first) << ","
        << csv_number(fp->reference.second) << "," << (r.validated ? 1 : 0) << "," << csv_field(r.reason) << ","
        << csv_number(r.wall_time_s) << "\n";
    }
    commit(f);
  }

  // Per problem: each method's in-sample fronts (a line per run through its non-dominated points,
  // by the second objective) and its points feasible out of sample (open markers), the reference
  // point marked. Data blocks: two per method (in, out), a run per blank-line-separated segment; an
  // empty block is not written (gnuplot's `index` counts the blocks that are there).
  const Gnuplot gp;
  const bool plots = make_plots && gp.available();
  if (plots && written.gnuplot.empty()) written.gnuplot = gp.executable();
  const bool cairo = !gp.available() || gp.terminal() == "pngcairo";
  for (const FrontProblem& fp : c.problems) {
    const std::string stem = "front_" + file_safe(fp.label);
    AtomicFile dat(dir / (stem + ".dat"));
    std::ostringstream body;
    body << "set key top left box opaque\nset grid\n"
         << "set title " << plot_style::literal("Fronts on " + fp.label + ": " + std::to_string(fp.seeds) +
                                                (fp.seeds == 1 ? " run" : " runs") + " per method, " + std::to_string(fp.max_evaluations) +
                                                " evaluations each")
         << "\nset xlabel "
         << plot_style::literal(fp.second_objective == "startup_time_s" ? "startup time T [s]" : fp.second_objective)
         << "\nset ylabel " << plot_style::literal(objective_label(fp.settings)) << "\n"
         << "set offsets graph 0.03, graph 0.03, graph 0.03, graph 0.03\nplot ";
    long block = 0;
    bool first_curve = true;
    auto curve = [&](const std::string& text) {
      body << (first_curve ? "" : ", \\\n     ") << text;
      first_curve = false;
    };
    const auto methods = methods_of(fp);
    for (std::size_t m = 0; m < methods.size(); ++m) {
      const std::string colour = plot_style::colour(static_cast<int>(m));
      for (int side = 0; side < 2; ++side) {
        std::ostringstream b;
        for (const FrontRun& r : c.runs) {
          if (r.problem != fp.label || r.method != methods[m]) continue;
          std::vector<std::pair<double, double>> pts;
          for (const FrontPoint& p : r.points) {
            if (side == 0 && p.non_dominated) pts.emplace_back(p.second, p.objective);
            if (side == 1 && p.validated_feasible) pts.emplace_back(p.validated_second, p.validation->objective);
          }
          if (pts.empty()) continue;
          std::sort(pts.begin(), pts.end());
          for (const auto& [s, o] : pts) b << format_number(s) << " " << format_number(o) << "\n";
          b << "\n";
        }
        const std::string title =
            methods[m] + (side == 0 ? ", in sample (a line per run)" : ", feasible out of sample");
        if (b.str().empty()) {
          curve("NaN with points lc rgb '" + colour + "' title " + plot_style::literal(title + ": no point"));
          continue;
        }
        dat << "# " << methods[m] << (side == 0 ? " in sample" : " out of sample") << "\n" << b.str() << "\n\n";
        const std::string index = "'" + stem + ".dat' index " + std::to_string(block++) + " using 1:2 ";
        curve(index + (side == 0 ? "with linespoints pt 7 ps 0.6 lw 1 lc rgb '" + colour + "'"
                                 : "with points pt 6 ps 1.1 lw 1.5 lc rgb '" + colour + "'") +
              " title " + plot_style::literal(title));
      }
    }
    dat << "# hypervolume reference point\n"
        << format_number(fp.reference.second) << " " << format_number(fp.reference.first) << "\n\n\n";
    curve("'" + stem + ".dat' index " + std::to_string(block++) + " using 1:2 with points pt 3 ps 2 lw 2 lc rgb '" +
          plot_style::kGrey + "' title " + plot_style::literal("hypervolume reference point"));
    body << "\n";
    dat.commit();
    written.files.push_back((dir / (stem + ".dat")).string());
    const fs::path script = dir / (stem + ".gp");
    write_file_atomic(script, plot_style::figure_script(stem, body.str(), 1000, 650, cairo ? "pngcairo" : "png"));
    written.files.push_back(script.string());
    if (!plots) {
      written.skipped_plots.push_back(stem + ".png");
      continue;
    }
    fs::remove(dir / (stem + ".png"), ec);
    const int rc = gp.run_script(fs::absolute(script).string(), fs::absolute(dir).string(),
                                 fs::absolute(dir / (stem + ".log")).string());
    if (rc == 0 && fs::is_regular_file(dir / (stem + ".png"), ec)) {
      written.files.push_back((dir / (stem + ".png")).string());
      if (fs::is_regular_file(dir / (stem + ".pdf"), ec)) written.files.push_back((dir / (stem + ".pdf")).string());
    } else {
      written.skipped_plots.push_back(stem + ".png");
    }
  }
}

}  // namespace abuopt
