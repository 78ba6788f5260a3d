#include "abuopt/common/gnuplot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
using abuopt::Gnuplot;
using abuopt::PlotStatus;

namespace {

// A fresh directory per test (with a space in its name: paths must be quoted everywhere).
fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(ABUOPT_BINARY_DIR) / "test-output" / ("gnuplot " + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// x, sin x, cos x (header + 50 rows) and an 12 x 12 grid x, y, in, amplitude.
fs::path write_lines_csv(const fs::path& dir) {
  const fs::path p = dir / "lines.csv";
  std::ofstream f(p);
  f << "x,sin_x,cos_x\n";
  for (int k = 0; k < 50; ++k) f << k * 0.1 << "," << std::sin(k * 0.1) << "," << std::cos(k * 0.1) << "\n";
  return p;
}

fs::path write_grid_csv(const fs::path& dir, int n) {
  const fs::path p = dir / "grid.csv";
  std::ofstream f(p);
  f << "beta1,beta2,in_set,amplitude\n";
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = 2 * M_PI * i / n, y = 2 * M_PI * j / n, a = std::abs(std::cos(x) + std::cos(y));
      f << x << "," << y << "," << (a < 1 ? 1 : 0) << "," << a << "\n";
    }
  return p;
}

bool is_png(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  char sig[8] = {};
  f.read(sig, 8);
  return f && sig[1] == 'P' && sig[2] == 'N' && sig[3] == 'G' && fs::file_size(p) > 100;
}

bool is_pdf(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  char sig[5] = {};
  f.read(sig, 5);
  return f && std::string(sig, 5) == "%PDF-" && fs::file_size(p) > 100;
}

}  // namespace

TEST(Gnuplot, QuotesStringsForGnuplot) {
  EXPECT_EQ(Gnuplot::quote("it's"), "'it''s'");
  EXPECT_EQ(Gnuplot::quote("a_b"), "'a_b'");
  // No text can end the string or the line: control characters become spaces (issue 12).
  EXPECT_EQ(Gnuplot::quote("x'\nsystem \"touch y\"\r\t'"), "'x'' system \"touch y\"  '''");
}

// The script goes beside the CSV, named after the PNG.
TEST(Gnuplot, ScriptPathIsBesideTheCsv) {
  abuopt::XYLinesPlot p;
  p.csv_path = "/data/run/scan.csv";
  p.png_path = "/elsewhere/coverage.png";
  EXPECT_EQ(Gnuplot::beside_csv(p, ".gp"), "/data/run/coverage.gp");
}

// Told gnuplot lives at a path that does not exist: not available, the script is still written,
// and every helper reports "skipped: gnuplot not found" instead of failing.
TEST(Gnuplot, MissingExecutableIsSkippedButScriptIsWritten) {
  const fs::path d = fresh_dir("missing");
  const Gnuplot gp("/nonexistent/dir/gnuplot");
  EXPECT_FALSE(gp.available());
  abuopt::XYLinesPlot p;
  p.csv_path = write_lines_csv(d).string();
  p.png_path = (d / "lines.png").string();
  p.labels = {"it's sin", "x", "y"};
  p.series = {{1, 2, "sin", "lines"}, {1, 3, "cos", "points"}};
  const PlotStatus s = gp.xy_lines(p);
  EXPECT_EQ(s.state, PlotStatus::State::Skipped);
  EXPECT_FALSE(s.ran());
  EXPECT_EQ(s.message.rfind("skipped: gnuplot not found", 0), 0u) << s.message;
  ASSERT_TRUE(fs::exists(s.script_path));
  EXPECT_EQ(s.script_path, (d / "lines.gp").string());
  const std::string script = slurp(s.script_path);
  // Outputs and data relative to the script's folder; PNG, then the same figure as PDF.
  EXPECT_NE(script.find("set output 'lines.png'"), std::string::npos) << script;
  EXPECT_NE(script.find("set output 'lines.pdf'\nreplot\nunset output"), std::string::npos) << script;
  EXPECT_EQ(script.find(d.string()), std::string::npos) << "an absolute path in the script:\n" << script;
  EXPECT_NE(script.find("'lines.csv' skip 1 using 1:2 with lines lt 1 title 'sin' noenhanced"), std::string::npos) << script;
  EXPECT_NE(script.find("'lines.csv' skip 1 using 1:3 with points lt 2"), std::string::npos) << script;
  EXPECT_NE(script.find("set title 'it''s sin'"), std::string::npos) << script;
  EXPECT_FALSE(fs::exists(p.png_path));
  // A name that is not on PATH is missing too.
  EXPECT_FALSE(Gnuplot("abuopt-no-such-gnuplot-binary").available());
}

// With gnuplot installed: all four helpers make a non-empty PNG (signature checked).
TEST(Gnuplot, MakesPngsWhenGnuplotExists) {
  const Gnuplot gp;
  if (!gp.available()) GTEST_SKIP() << "gnuplot not installed";
  EXPECT_TRUE(gp.terminal() == "pngcairo" || gp.terminal() == "png");
  const fs::path d = fresh_dir("plots");
  const std::string lines = write_lines_csv(d).string();
  const std::string grid = write_grid_csv(d, 12).string();

  abuopt::XYLinesPlot xy;
  xy.csv_path = lines;
  xy.png_path = (d / "xy.png").string();
  xy.labels = {"sin and cos", "x [rad]", "value"};
  xy.series = {{1, 2, "sin_x"}, {1, 3, "cos_x", "linespoints"}};
  abuopt::ScatterPlot sc;
  sc.csv_path = lines;
  sc.png_path = (d / "scatter.png").string();
  sc.x_column = 2;
  sc.y_column = 3;
  sc.color_column = 1;
  sc.color_label = "x";
  abuopt::GridPlot gr;
  gr.csv_path = grid;
  gr.png_path = (d / "grid.png").string();
  gr.labels = {"membership", "beta1", "beta2"};
  gr.fill_column = 3;
  gr.palette = "defined (0 '#f4cccc', 1 '#b6d7a8')";
  gr.cb_min = 0;
  gr.cb_max = 1;
  gr.cb_tics = "('outside' 0, 'in set' 1)";
  gr.contour_column = 4;
  gr.contour_title = "amplitude";
  abuopt::HistogramPlot hi;
  hi.csv_path = lines;
  hi.png_path = (d / "hist.png").string();
  hi.column = 2;
  hi.bins = 10;

  for (const PlotStatus& s : {gp.xy_lines(xy), gp.scatter(sc), gp.grid(gr), gp.histogram(hi)}) {
    EXPECT_TRUE(s.ran()) << s.message;
    EXPECT_EQ(s.message, "ok");
    EXPECT_TRUE(fs::exists(s.script_path));
    EXPECT_TRUE(is_png(s.png_path)) << s.png_path;
    EXPECT_TRUE(is_pdf(s.pdf_path)) << s.pdf_path;
  }
  // The grid copy has the 12 scans separated by 11 blank lines, 144 data rows.
  const std::string dat = slurp(d / "grid.grid.dat");
  std::istringstream in(dat);
  std::string line;
  int blank = 0, rows = 0;
  while (std::getline(in, line)) (line.empty() ? blank : rows)++;
  EXPECT_EQ(blank, 11);
  EXPECT_EQ(rows, 144);
}

// A script gnuplot rejects: status Failed, the message quotes gnuplot's complaint, no crash.
TEST(Gnuplot, ReportsGnuplotErrors) {
  const Gnuplot gp;
  if (!gp.available()) GTEST_SKIP() << "gnuplot not installed";
  const fs::path d = fresh_dir("error");
  const PlotStatus s = gp.run("plot no_such_function_abc(x)\n", (d / "bad.gp").string(), (d / "bad.png").string());
  EXPECT_EQ(s.state, PlotStatus::State::Failed);
  EXPECT_NE(s.message.find("no_such_function_abc"), std::string::npos) << s.message;
}

// A script the helper wrote runs by hand from its own folder (data and outputs are relative): with
// the outputs removed, `gnuplot NAME.gp` in that folder makes both the PNG and the PDF again, also
// for the grid plot with its derived data file and a categorical key.
TEST(Gnuplot, ScriptsRunFromTheirOwnFolder) {
  const Gnuplot gp;
  if (!gp.available()) GTEST_SKIP() << "gnuplot not installed";
  const fs::path d = fresh_dir("own folder");
  abuopt::XYLinesPlot xy;
  xy.csv_path = write_lines_csv(d).string();
  xy.png_path = (d / "xy.png").string();
  xy.labels = {"sin", "β_1 [rad]", "I_{r,x} [10^{-7} kg m]"};
  xy.series = {{1, 2, "sin_x", "lines"}};
  xy.angle_x = true;
  abuopt::GridPlot gr;
  gr.csv_path = write_grid_csv(d, 12).string();
  gr.png_path = (d / "grid.png").string();
  gr.labels = {"membership", "β_1 [rad]", "β_2 [rad]"};
  gr.angle_axes = true;
  gr.fill_column = 3;
  gr.categories = {{1, "#9ecae1", "in the set"}, {0, "#f2f2f2", "outside it"}};
  for (const PlotStatus& s : {gp.xy_lines(xy), gp.grid(gr)}) {
    ASSERT_TRUE(s.ran()) << s.message;
    const std::string script = slurp(s.script_path);
    EXPECT_EQ(script.find(d.string()), std::string::npos) << script;
    EXPECT_EQ(script.find(ABUOPT_BINARY_DIR), std::string::npos) << script;
    fs::remove(s.png_path);
    fs::remove(s.pdf_path);
    const int rc = gp.run_script(fs::path(s.script_path).filename().string(), d.string(), (d / "rerun.log").string());
    EXPECT_EQ(rc, 0) << slurp(d / "rerun.log");
    EXPECT_TRUE(is_png(s.png_path)) << s.png_path;
    EXPECT_TRUE(is_pdf(s.pdf_path)) << s.pdf_path;
  }
  // The angle axis has its pi tics; the categorical key has one entry per category.
  const std::string grid_script = slurp(d / "grid.gp");
  EXPECT_NE(grid_script.find("'π' pi"), std::string::npos) << grid_script;
  EXPECT_NE(grid_script.find("title 'in the set'"), std::string::npos) << grid_script;
  EXPECT_NE(grid_script.find("title 'outside it'"), std::string::npos) << grid_script;
  EXPECT_NE(grid_script.find("unset colorbox"), std::string::npos) << grid_script;
}
