#pragma once
// Small inline SVG figures for the study's HTML report (self-contained: no script, no network).
#include <string>
#include <vector>

namespace abuopt::studies::detail {

struct SvgSeries {
  std::string name;
  std::vector<double> x, y;  // NaN y: a gap
  std::string color = "#1f77b4";
  double width = 2.0;
  bool dashed = false;
  bool markers = false;  // a dot at every point (the line drawn only with width > 0)
};

// A line chart with axes, ticks, labels and a legend. Series without finite points are left out.
std::string svg_line_chart(const std::string& title, const std::string& x_label, const std::string& y_label,
                           const std::vector<SvgSeries>& series, int width = 720, int height = 360);

// A heat map of values[row][column] over xs (columns) and ys (rows), each cell with its value;
// colours diverge around `centre` (below: blue, above: red).
std::string svg_heatmap(const std::string& title, const std::string& x_label, const std::string& y_label,
                        const std::vector<double>& xs, const std::vector<double>& ys,
                        const std::vector<std::vector<double>>& values, double centre, int width = 720,
                        int height = 360);

// Points (x, y) in [0, 360)^2 degrees over a set drawn as shaded cells (in_set: n x n, row-major,
// index i * n + j for x cell i and y cell j); one colour per point group.
struct SvgPointGroup {
  std::string name, color;
  std::vector<std::pair<double, double>> points;
  bool hollow = false;
};
std::string svg_points_over_set(const std::string& title, const std::string& x_label, const std::string& y_label,
                                std::size_t n, const std::vector<char>& in_set, const std::string& set_name,
                                const std::vector<SvgPointGroup>& groups, int size = 520);

// Text with &, <, >, " escaped for HTML and SVG.
std::string xml_escape(const std::string& s);

// The colour of series i of a palette of ten.
std::string palette(std::size_t i);

}  // namespace abuopt::studies::detail
