#include "abuopt/common/gnuplot.hpp"

#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace abuopt {

namespace fs = std::filesystem;

namespace {

bool is_executable_file(const std::string& path) {
  std::error_code ec;
  return !path.empty() && fs::is_regular_file(path, ec) && ::access(path.c_str(), X_OK) == 0;
}

// A name without '/' is looked up on PATH; a path is taken as it is.
std::string resolve(const std::string& exe) {
  if (exe.find('/') != std::string::npos) return is_executable_file(exe) ? exe : "";
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::stringstream ss(path);
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    if (dir.empty()) continue;
    const std::string candidate = (fs::path(dir) / exe).string();
    if (is_executable_file(candidate)) return candidate;
  }
  return "";
}

// Single quotes for the shell: 'a'\''b'.
std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') out += "'\\''";
    else out += c;
  }
  return out + "'";
}

std::string read_text(const std::string& path, std::size_t max_chars) {
  std::ifstream f(path);
  std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (text.size() > max_chars) text = text.substr(0, max_chars) + "...";
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  return text;
}

void labels_lines(std::ostringstream& s, const PlotLabels& l) {
  if (!l.title.empty()) s << "set title " << Gnuplot::quote(l.title) << "\n";
  if (!l.xlabel.empty()) s << "set xlabel " << Gnuplot::quote(l.xlabel) << "\n";
  if (!l.ylabel.empty()) s << "set ylabel " << Gnuplot::quote(l.ylabel) << "\n";
}

std::string col(int c) {
  std::string r(1, '$');
  r += std::to_string(c);
  return r;
}

void require_column(int c, const char* what) {
  if (c < 1) throw std::invalid_argument(std::string("gnuplot helper: ") + what + " = " + std::to_string(c) + ": columns are 1-based");
}

// Splits one CSV line (no quoting: numeric data).
std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(item);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

}  // namespace

std::string to_string(PlotStatus::State s) {
  switch (s) {
    case PlotStatus::State::Ran: return "ran";
    case PlotStatus::State::Skipped: return "skipped";
    case PlotStatus::State::Failed: return "failed";
  }
  return "unknown";
}

Gnuplot::Gnuplot(const std::string& executable) : executable_(executable.empty() ? find() : resolve(executable)) {}

std::string Gnuplot::find() {
  if (const char* env = std::getenv("ABUOPT_GNUPLOT"); env && *env) return resolve(env);
  if (is_executable_file("/usr/bin/gnuplot")) return "/usr/bin/gnuplot";
  return resolve("gnuplot");
}

const std::string& Gnuplot::terminal() const {
  if (!terminal_.empty()) return terminal_;
  terminal_ = "png";
  if (!available()) return terminal_;
  // `set terminal` with no argument lists the terminals this build has (on stderr).
  const std::string cmd = shell_quote(executable_) + " -e 'set terminal' 2>&1";
  if (FILE* p = ::popen(cmd.c_str(), "r")) {
    std::array<char, 4096> buf{};
    std::string out;
    while (std::size_t got = std::fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), got);
    ::pclose(p);
    if (out.find("pngcairo") != std::string::npos) terminal_ = "pngcairo";
  }
  return terminal_;
}

std::string Gnuplot::quote(const std::string& text) {
  std::string out = "'";
  for (char c : text) {
    if (c == '\'') out += "''";
    else if (c == '\n') out += ' ';
    else out += c;
  }
  return out + "'";
}

std::string Gnuplot::beside_csv(const PlotFiles& f, const std::string& suffix) {
  const fs::path csv(f.csv_path);
  const fs::path png(f.png_path);
  return (csv.parent_path() / (png.stem().string() + suffix)).string();
}

PlotStatus Gnuplot::run(const std::string& script_body, const std::string& script_path, const std::string& png_path,
                        int width_px, int height_px) const {
  PlotStatus st;
  st.script_path = script_path;
  st.png_path = png_path;
  std::ostringstream s;
  s << "# written by abuopt; run with: gnuplot " << fs::path(script_path).filename().string() << "\n"
    << "set terminal " << (available() ? terminal() : std::string("pngcairo")) << " noenhanced size " << width_px
    << "," << height_px << "\n"
    << "set output " << quote(png_path) << "\n"
    << script_body;
  {
    std::ofstream f(script_path);
    if (!f) {
      st.state = PlotStatus::State::Failed;
      st.message = "failed: cannot write the script " + script_path;
      return st;
    }
    f << s.str();
  }
  if (!available()) {
    st.state = PlotStatus::State::Skipped;
    st.message = "skipped: gnuplot not found (script written to " + script_path + ")";
    return st;
  }
  const std::string log_path = (fs::path(script_path).replace_extension(".log")).string();
  std::error_code ec;
  fs::remove(png_path, ec);
  const std::string cmd = shell_quote(executable_) + " " + shell_quote(script_path) + " > " + shell_quote(log_path) + " 2>&1";
  const int rc = std::system(cmd.c_str());
  const bool made = fs::is_regular_file(png_path, ec) && fs::file_size(png_path, ec) > 0;
  if (rc != 0 || !made) {
    st.state = PlotStatus::State::Failed;
    st.message = "failed: gnuplot " + std::string(rc != 0 ? "exited with status " + std::to_string(rc) : "made no PNG") +
                 " (" + log_path + "): " + read_text(log_path, 400);
    return st;
  }
  st.state = PlotStatus::State::Ran;
  st.message = "ok";
  return st;
}

std::string Gnuplot::xy_lines_body(const XYLinesPlot& p) {
  if (p.series.empty()) throw std::invalid_argument("gnuplot helper: an XY plot needs at least one series");
  std::ostringstream s;
  s << "set datafile separator ','\n";
  labels_lines(s, p.labels);
  s << "set grid\nset key top left\n";
  if (p.log_x) s << "set logscale x\n";
  if (p.log_y) s << "set logscale y\n";
  s << "plot ";
  for (std::size_t k = 0; k < p.series.size(); ++k) {
    const auto& se = p.series[k];
    require_column(se.x_column, "x_column");
    require_column(se.y_column, "y_column");
    s << (k ? ", \\\n     " : "") << quote(p.csv_path) << " skip " << p.header_lines << " using "
      << se.x_column << ":" << se.y_column << " with " << se.style << " lw 2 "
      << (se.title.empty() ? "notitle" : "title " + quote(se.title));
  }
  s << "\n";
  return s.str();
}

std::string Gnuplot::scatter_body(const ScatterPlot& p) {
  require_column(p.x_column, "x_column");
  require_column(p.y_column, "y_column");
  std::ostringstream s;
  s << "set datafile separator ','\n";
  labels_lines(s, p.labels);
  s << "set grid\nunset key\n";
  if (p.color_column > 0 && !p.color_label.empty()) s << "set cblabel " << quote(p.color_label) << "\n";
  s << "plot " << quote(p.csv_path) << " skip " << p.header_lines << " using " << p.x_column << ":" << p.y_column;
  if (p.color_column > 0) s << ":" << p.color_column;
  s << " with points pt 7 ps " << p.point_size << (p.color_column > 0 ? " palette" : "") << "\n";
  return s.str();
}

std::string Gnuplot::grid_body(const GridPlot& p, const std::string& grid_data_path) {
  require_column(p.x_column, "x_column");
  require_column(p.y_column, "y_column");
  require_column(p.fill_column, "fill_column");
  std::ostringstream s;
  s << "# data: " << grid_data_path << " (from " << p.csv_path << ", whitespace separated, blank line between x scans)\n";
  labels_lines(s, p.labels);
  s << "set view map\n";
  if (p.square) s << "set size square\n";
  s << "set autoscale fix\nset tics out\nset key at screen 0.5, 0.03 center horizontal\nset bmargin 5\n";
  if (!p.palette.empty()) s << "set palette " << p.palette << "\n";
  if (p.cb_max > p.cb_min) s << "set cbrange [" << p.cb_min << ":" << p.cb_max << "]\n";
  if (!p.cb_tics.empty()) s << "set cbtics " << p.cb_tics << "\n";
  if (!p.fill_label.empty()) s << "set cblabel " << quote(p.fill_label) << "\n";
  const std::string data = quote(grid_data_path);
  const std::string xy = std::to_string(p.x_column) + ":" + std::to_string(p.y_column) + ":";
  if (p.contour_column > 0) {
    s << "set contour base\nset cntrparam levels auto " << p.contour_levels << "\n"
      << "set cntrlabel onecolor format '%.3g' font ',8' start 5 interval 80\n";
    s << "splot " << data << " using " << xy << p.fill_column << " with image nocontour notitle, \\\n"
      << "      " << data << " using " << xy << p.contour_column << " nosurface with lines lc rgb 'black' lw 1 "
      << (p.contour_title.empty() ? "notitle" : "title " + quote(p.contour_title)) << ", \\\n"
      << "      " << data << " using " << xy << p.contour_column << " nosurface with labels notitle\n";
  } else {
    s << "splot " << data << " using " << xy << p.fill_column << " with image notitle\n";
  }
  return s.str();
}

std::string Gnuplot::histogram_body(const HistogramPlot& p) {
  require_column(p.column, "column");
  if (p.bins < 1) throw std::invalid_argument("gnuplot helper: bins = " + std::to_string(p.bins) + ": must be >= 1");
  std::ostringstream s;
  s << "set datafile separator ','\n";
  labels_lines(s, p.labels);
  s << "stats " << quote(p.csv_path) << " skip " << p.header_lines << " using " << p.column << " nooutput\n"
    << "nbins = " << p.bins << "\n"
    << "lo = STATS_min\n"
    << "w = (STATS_max > STATS_min) ? (STATS_max - STATS_min) / nbins : 1.0\n"
    << "bin(x) = lo + w * ((floor((x - lo) / w) < nbins ? floor((x - lo) / w) : nbins - 1) + 0.5)\n"
    << "set boxwidth w * 0.9\nset style fill solid 0.6 border -1\nset grid ytics\nunset key\nset yrange [0:*]\n"
    << "plot " << quote(p.csv_path) << " skip " << p.header_lines << " using (bin(" << col(p.column)
    << ")):(1.0) smooth frequency with boxes\n";
  return s.str();
}

PlotStatus Gnuplot::xy_lines(const XYLinesPlot& p) const {
  return run(xy_lines_body(p), beside_csv(p, ".gp"), p.png_path, p.width_px, p.height_px);
}

PlotStatus Gnuplot::scatter(const ScatterPlot& p) const {
  return run(scatter_body(p), beside_csv(p, ".gp"), p.png_path, p.width_px, p.height_px);
}

PlotStatus Gnuplot::histogram(const HistogramPlot& p) const {
  return run(histogram_body(p), beside_csv(p, ".gp"), p.png_path, p.width_px, p.height_px);
}

PlotStatus Gnuplot::grid(const GridPlot& p) const {
  // gnuplot's contouring and images need the scans separated by blank lines: write that copy.
  const std::string dat = beside_csv(p, ".grid.dat");
  {
    std::ifstream in(p.csv_path);
    if (!in) {
      PlotStatus st;
      st.state = PlotStatus::State::Failed;
      st.png_path = p.png_path;
      st.message = "failed: cannot read the data " + p.csv_path;
      return st;
    }
    std::ofstream out(dat);
    std::string line, last_x;
    int skipped = 0;
    bool first = true;
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (skipped < p.header_lines) {
        ++skipped;
        continue;
      }
      if (line.empty()) continue;
      const auto cells = split_csv(line);
      const auto x_index = static_cast<std::size_t>(p.x_column - 1);
      const std::string x = x_index < cells.size() ? cells[x_index] : "";
      if (!first && x != last_x) out << "\n";
      first = false;
      last_x = x;
      for (std::size_t k = 0; k < cells.size(); ++k) out << (k ? " " : "") << (cells[k].empty() ? "NaN" : cells[k]);
      out << "\n";
    }
  }
  return run(grid_body(p, dat), beside_csv(p, ".gp"), p.png_path, p.width_px, p.height_px);
}

}  // namespace abuopt
