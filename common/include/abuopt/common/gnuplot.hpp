#pragma once
// A small gnuplot driver: writes a script beside the data CSV and runs `gnuplot script.gp` in that
// folder to make a PNG and a PDF (the look comes from plot_style.hpp; the script names its data
// and outputs relative to its folder, so it can be rerun there by hand). gnuplot is started with posix_spawn and an argument vector: no shell sees any path or
// text. A script that cannot be written throws OutputError (output_file.hpp). Plotting is optional: without gnuplot the script is still written and the status says
// "skipped: gnuplot not found", so a study never fails for want of a plot.
//
//   Gnuplot gp;                                   // finds gnuplot (see find())
//   XYLinesPlot p;
//   p.csv_path = "out/scan.csv"; p.png_path = "out/scan.png";
//   p.labels = {"coverage", "frequency [Hz]", "fraction"};
//   p.series = {{1, 2, "coverage"}};
//   PlotStatus s = gp.xy_lines(p);                // s.ran(), s.message, s.script_path
//
// Data files are CSV with `header_lines` header rows (default 1); columns are 1-based, as in
// gnuplot's `using`. The script goes to <csv dir>/<png stem>.gp; gnuplot's output to <...>.log.
// Labels (PlotLabels, colour-box labels) are typeset (enhanced text: beta_1 shows a subscript; use
// plot_style::escape for literal pieces); series titles are shown literally.
#include <string>
#include <vector>

namespace abuopt {

struct PlotLabels {
  std::string title;
  std::string xlabel;
  std::string ylabel;
};

struct PlotSeries {
  int x_column = 1;
  int y_column = 2;
  std::string title;
  std::string style = "lines";  // gnuplot style: lines, points, linespoints, steps, yerrorbars, ...,
                                // optionally with options ("points pt 6 ps 1.5")
  int error_column = 0;         // > 0: a third `using` column (e.g. the half-width for yerrorbars)
};

// Common to every plot: where the data and the picture are.
struct PlotFiles {
  std::string csv_path;
  std::string png_path;
  int header_lines = 1;
  int width_px = 900;
  int height_px = 650;
};

// Several series as lines (each its own x and y column).
struct XYLinesPlot : PlotFiles {
  PlotLabels labels;
  std::vector<PlotSeries> series;
  bool log_x = false, log_y = false;
  bool angle_x = false, angle_y = false;  // axis over [0, 2 pi] with pi tics
  std::string key = "top left";           // gnuplot `set key` position, e.g. "outside below"
};

// Points, optionally coloured by a third column (0: one colour).
struct ScatterPlot : PlotFiles {
  PlotLabels labels;
  int x_column = 1, y_column = 2;
  int color_column = 0;
  std::string color_label;
  double point_size = 0.6;
  bool angle_axes = false;  // both axes over [0, 2 pi] with pi tics, square
};

// A regular grid in CSV rows (x changes slowest, as written by nested loops): a heat map of
// `fill_column` and, optionally, contour lines with value labels of `contour_column`.
// The helper writes a gnuplot-ready copy (blank line between x scans) to <png stem>.grid.dat.
struct GridPlot : PlotFiles {
  PlotLabels labels;
  int x_column = 1, y_column = 2;
  int fill_column = 3;
  std::string fill_label;        // colour-box label
  std::string palette;           // gnuplot palette spec, e.g. "defined (0 '#f4cccc', 1 '#b6d7a8')"; empty: default
  std::string cb_tics;           // e.g. "('outside' 0, 'in set' 1)"; empty: automatic
  double cb_min = 0, cb_max = 0; // colour range; equal: automatic
  int contour_column = 0;        // 0: no contours
  int contour_levels = 8;        // automatic levels (approximate count)
  std::string contour_title;     // key entry of the contour lines
  bool square = true;            // equal-size axes box
  bool angle_axes = false;       // both axes over [0, 2 pi] with pi tics
  // A categorical fill: each value of fill_column its colour and a key entry (the colour box,
  // palette and cb_* settings above are then not used).
  struct Category {
    int value;
    std::string colour;  // "#rrggbb"
    std::string label;   // typeset
  };
  std::vector<Category> categories;
};

// Counts of one column in `bins` equal bins between its min and max.
struct HistogramPlot : PlotFiles {
  PlotLabels labels;
  int column = 1;
  int bins = 20;
};

struct PlotStatus {
  enum class State { Ran, Skipped, Failed };
  State state = State::Skipped;
  std::string message;      // "ok", "skipped: gnuplot not found ...", or why gnuplot failed
  std::string script_path;  // written in every state (except when the directory is unwritable)
  std::string png_path;
  std::string pdf_path;     // the PNG's path with .pdf
  bool ran() const { return state == State::Ran; }
};

std::string to_string(PlotStatus::State s);

class Gnuplot {
 public:
  // `executable`: a path or a name looked up on PATH; empty: find() decides.
  explicit Gnuplot(const std::string& executable = "");

  // $ABUOPT_GNUPLOT if set, else /usr/bin/gnuplot if executable, else `gnuplot` on PATH; "" if none.
  static std::string find();

  bool available() const { return !executable_.empty(); }
  const std::string& executable() const { return executable_; }
  // "pngcairo" when this gnuplot has it, else "png" (asked once, lazily).
  const std::string& terminal() const;

  // Writes `script_body` (everything after the terminal/output lines and the style preamble) to
  // script_path as plot_style::figure_script (PNG, then PDF by replot) and runs gnuplot on it in the
  // script's folder. Data paths in the body must be relative to that folder (relative_to()).
  PlotStatus run(const std::string& script_body, const std::string& script_path, const std::string& png_path,
                 int width_px = 900, int height_px = 650) const;

  // Runs gnuplot on an existing script (argument vector, no shell), in `working_dir` when not
  // empty, with its output in `log_path`. Returns gnuplot's exit status; -1 when it could not be
  // started or was killed (the reason is in the log) or when no gnuplot is available.
  int run_script(const std::string& script_path, const std::string& working_dir, const std::string& log_path) const;

  PlotStatus xy_lines(const XYLinesPlot& p) const;
  PlotStatus scatter(const ScatterPlot& p) const;
  PlotStatus grid(const GridPlot& p) const;
  PlotStatus histogram(const HistogramPlot& p) const;

  // The script bodies (no terminal/output lines), for tests and for users who plot elsewhere.
  static std::string xy_lines_body(const XYLinesPlot& p);
  static std::string scatter_body(const ScatterPlot& p);
  static std::string grid_body(const GridPlot& p, const std::string& grid_data_path);
  static std::string histogram_body(const HistogramPlot& p);

  // `path` relative to the folder `dir` ("a.csv" for "out/plots/a.csv" and "out/plots").
  static std::string relative_to(const std::string& path, const std::string& dir);
  // <csv dir>/<png stem><suffix>
  static std::string beside_csv(const PlotFiles& f, const std::string& suffix);
  // A gnuplot single-quoted string literal ('it''s'). Every text that reaches a script (labels,
  // titles, file names) goes through it: quotes are doubled and control characters (newline, CR,
  // tab, ...) become spaces, so no text can end the string or the line and add a command.
  static std::string quote(const std::string& text);

 private:
  std::string executable_;
  mutable std::string terminal_;
};

}  // namespace abuopt
