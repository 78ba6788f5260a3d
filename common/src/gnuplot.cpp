#include "abuopt/common/gnuplot.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "abuopt/common/output_file.hpp"
#include "abuopt/common/plot_style.hpp"

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

extern "C" char** environ;

// Runs argv[0] with the argument vector `argv` (no shell: nothing in the arguments is
// interpreted), in `cwd` when not empty, with stdin from /dev/null and stdout and stderr to
// `out_fd` (a file or a pipe; -1: /dev/null). Returns the exit status, or -1 with `why` set.
int spawn_and_wait(const std::vector<std::string>& argv, const std::string& cwd, int out_fd, std::string& why) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  if (out_fd >= 0) {
    posix_spawn_file_actions_adddup2(&fa, out_fd, 1);
    posix_spawn_file_actions_adddup2(&fa, out_fd, 2);
  } else {
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  }
  if (!cwd.empty()) posix_spawn_file_actions_addchdir_np(&fa, cwd.c_str());
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = ::posix_spawn(&pid, args[0], &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    why = std::string("cannot start ") + argv[0] + ": " + std::strerror(rc);
    return -1;
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) {
      why = std::string("waitpid: ") + std::strerror(errno);
      return -1;
    }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  why = "gnuplot was ended by signal " + std::to_string(WTERMSIG(status));
  return -1;
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
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) == 0) {
    std::string why;
    // The child gets the write end as stdout/stderr (dup2 clears close-on-exec there; the
    // originals close at exec). The list is a few kB: it fits the pipe, so waiting first is safe.
    spawn_and_wait({executable_, "-e", "set terminal"}, "", fds[1], why);
    ::close(fds[1]);
    std::string out;
    std::array<char, 4096> buf{};
    ssize_t got = 0;
    while ((got = ::read(fds[0], buf.data(), buf.size())) > 0) out.append(buf.data(), static_cast<std::size_t>(got));
    ::close(fds[0]);
    if (out.find("pngcairo") != std::string::npos) terminal_ = "pngcairo";
  }
  return terminal_;
}

std::string Gnuplot::quote(const std::string& text) {
  std::string out = "'";
  for (char c : text) {
    if (c == '\'') out += "''";
    else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) out += ' ';  // newline, CR, tab, ...: one line
    else out += c;
  }
  return out + "'";
}

std::string Gnuplot::beside_csv(const PlotFiles& f, const std::string& suffix) {
  const fs::path csv(f.csv_path);
  const fs::path png(f.png_path);
  return (csv.parent_path() / (png.stem().string() + suffix)).string();
}

std::string Gnuplot::relative_to(const std::string& path, const std::string& dir) {
  std::error_code ec;
  const fs::path base = fs::absolute(dir.empty() ? fs::path(".") : fs::path(dir), ec);
  const fs::path rel = fs::absolute(path, ec).lexically_normal().lexically_relative(base.lexically_normal());
  return rel.empty() ? path : rel.string();
}

PlotStatus Gnuplot::run(const std::string& script_body, const std::string& script_path, const std::string& png_path,
                        int width_px, int height_px) const {
  PlotStatus st;
  st.script_path = script_path;
  st.png_path = png_path;
  st.pdf_path = fs::path(png_path).replace_extension(".pdf").string();
  const std::string dir = fs::path(script_path).parent_path().string();
  const std::string png_rel = relative_to(png_path, dir);
  const std::string stem = fs::path(png_rel).replace_extension("").string();
  write_file_atomic(script_path, plot_style::figure_script(stem, script_body, width_px, height_px,
                                                           available() ? terminal() : std::string("pngcairo")));
  if (!available()) {
    st.state = PlotStatus::State::Skipped;
    st.message = "skipped: gnuplot not found (script written to " + script_path + ")";
    return st;
  }
  const std::string log_path = (fs::path(script_path).replace_extension(".log")).string();
  std::error_code ec;
  fs::remove(png_path, ec);
  fs::remove(st.pdf_path, ec);
  // In the script's folder, by its file name: the script's relative paths are what runs.
  const int rc = run_script(fs::path(script_path).filename().string(), dir, fs::absolute(log_path, ec).string());
  const bool made = fs::is_regular_file(png_path, ec) && fs::file_size(png_path, ec) > 0 &&
                    fs::is_regular_file(st.pdf_path, ec) && fs::file_size(st.pdf_path, ec) > 0;
  if (rc != 0 || !made) {
    st.state = PlotStatus::State::Failed;
    st.message = "failed: gnuplot " + std::string(rc == -1 ? "could not be run" : rc != 0 ? "exited with status " + std::to_string(rc) : "made no PNG and PDF") +
                 " (" + log_path + "): " + read_text(log_path, 400);
    return st;
  }
  st.state = PlotStatus::State::Ran;
  st.message = "ok";
  return st;
}

int Gnuplot::run_script(const std::string& script_path, const std::string& working_dir,
                        const std::string& log_path) const {
  if (!available()) return -1;
  const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  std::string why;
  const int rc = spawn_and_wait({executable_, script_path}, working_dir, log, why);
  if (log >= 0) {
    if (!why.empty()) {
      const std::string line = why + "\n";
      (void)!::write(log, line.data(), line.size());
    }
    ::close(log);
  }
  // gnuplot says nothing when all is well: an empty log is removed, so that only a log with
  // something to read (a warning, an error) is left beside the figures.
  std::error_code ec;
  if (std::filesystem::is_regular_file(log_path, ec) && std::filesystem::file_size(log_path, ec) == 0 && !ec)
    std::filesystem::remove(log_path, ec);
  return rc;
}

std::string Gnuplot::xy_lines_body(const XYLinesPlot& p) {
  if (p.series.empty()) throw std::invalid_argument("gnuplot helper: an XY plot needs at least one series");
  std::ostringstream s;
  s << "set datafile separator ','\n";
  labels_lines(s, p.labels);
  s << "set grid\nset key " << p.key << "\n";
  if (p.angle_x) s << plot_style::angle_axis("x");
  if (p.angle_y) s << plot_style::angle_axis("y");
  if (p.log_x) s << "set logscale x\n";
  if (p.log_y) s << "set logscale y\n";
  s << "plot ";
  for (std::size_t k = 0; k < p.series.size(); ++k) {
    const auto& se = p.series[k];
    require_column(se.x_column, "x_column");
    require_column(se.y_column, "y_column");
    s << (k ? ", \\\n     " : "") << quote(p.csv_path) << " skip " << p.header_lines << " using "
      << se.x_column << ":" << se.y_column;
    if (se.error_column > 0) s << ":" << se.error_column;
    // The series' colour (lt) right after the style's name, so options in the style (pt, ps)
    // override the linetype's defaults.
    const std::size_t sp = se.style.find(' ');
    s << " with " << se.style.substr(0, sp) << " lt " << k + 1
      << (sp == std::string::npos ? std::string() : se.style.substr(sp)) << " "
      << (se.title.empty() ? "notitle" : "title " + plot_style::literal(se.title));
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
  if (p.angle_axes) s << plot_style::angle_axis("x") << plot_style::angle_axis("y") << "set size square\n";
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
  // The key centred below the plot.
  s << "set autoscale fix\nset tics out\nset key at screen 0.5, 0.1 center center horizontal maxcols 3\nset bmargin 7\n";
  // One turn on each axis (the image ends half a cell before 2 pi: a sliver of the background).
  if (p.angle_axes) s << plot_style::angle_axis("x") << plot_style::angle_axis("y");
  std::string key_entries;  // the categories' key: a filled square each (splot draws no NaN boxes)
  if (!p.categories.empty()) {
    int lo = p.categories.front().value, hi = lo;
    for (const auto& c : p.categories) lo = std::min(lo, c.value), hi = std::max(hi, c.value);
    s << "set palette defined (";
    for (int v = lo; v <= hi; ++v) {
      std::string colour = "#ffffff";
      for (const auto& c : p.categories)
        if (c.value == v) colour = c.colour;
      s << (v > lo ? ", " : "") << v - 0.5 << " '" << colour << "', " << v + 0.5 << " '" << colour << "'";
    }
    s << ")\nset cbrange [" << lo - 0.5 << ":" << hi + 0.5 << "]\nunset colorbox\n";
    for (const auto& c : p.categories)
      key_entries += ", \\\n      NaN with points pt 5 ps 2.5 lc rgb '" + c.colour + "' title " + quote(c.label);
  } else {
    if (!p.palette.empty()) s << "set palette " << p.palette << "\n";
    if (p.cb_max > p.cb_min) s << "set cbrange [" << p.cb_min << ":" << p.cb_max << "]\n";
    if (!p.cb_tics.empty()) s << "set cbtics " << p.cb_tics << "\n";
    if (!p.fill_label.empty()) s << "set cblabel " << quote(p.fill_label) << "\n";
  }
  const std::string data = quote(grid_data_path);
  const std::string xy = std::to_string(p.x_column) + ":" + std::to_string(p.y_column) + ":";
  if (p.contour_column > 0) {
    s << "set contour base\nset cntrparam levels auto " << p.contour_levels << "\n"
      << "set cntrlabel onecolor format '%.3g' font ',8' start 5 interval 80\n";
    s << "splot " << data << " using " << xy << p.fill_column << " with image nocontour notitle, \\\n"
      << "      " << data << " using " << xy << p.contour_column << " nosurface with lines lc rgb 'black' lw 1 "
      << (p.contour_title.empty() ? "notitle" : "title " + quote(p.contour_title)) << ", \\\n"
      << "      " << data << " using " << xy << p.contour_column << " nosurface with labels notitle" << key_entries
      << "\n";
  } else {
    s << "splot " << data << " using " << xy << p.fill_column << " with image notitle" << key_entries << "\n";
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
    << "set boxwidth w * 0.9\nset style fill solid 0.6 border lc rgb '#404040'\nset grid ytics\nunset key\nset yrange [0:*]\n"
    << "plot " << quote(p.csv_path) << " skip " << p.header_lines << " using (bin(" << col(p.column)
    << ")):(1.0) smooth frequency with boxes lc rgb '" << plot_style::kBlue << "'\n";
  return s.str();
}

// The bodies name the data relative to the script's folder (the script runs there).
template <class P>
P with_relative_data(const P& p) {
  P q = p;
  q.csv_path = Gnuplot::relative_to(p.csv_path, fs::path(Gnuplot::beside_csv(p, ".gp")).parent_path().string());
  return q;
}

PlotStatus Gnuplot::xy_lines(const XYLinesPlot& p) const {
  return run(xy_lines_body(with_relative_data(p)), beside_csv(p, ".gp"), p.png_path, p.width_px, p.height_px);
}

PlotStatus Gnuplot::scatter(const ScatterPlot& p) const {
  return run(scatter_body(with_relative_data(p)), beside_csv(p, ".gp"), p.png_path, p.width_px, p.height_px);
}

PlotStatus Gnuplot::histogram(const HistogramPlot& p) const {
  return run(histogram_body(with_relative_data(p)), beside_csv(p, ".gp"), p.png_path, p.width_px, p.height_px);
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
  const std::string script = beside_csv(p, ".gp");
  return run(grid_body(with_relative_data(p), relative_to(dat, fs::path(script).parent_path().string())), script,
             p.png_path, p.width_px, p.height_px);
}

}  // namespace abuopt
