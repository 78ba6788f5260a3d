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

// Text with &, <, >, " escaped for HTML and SVG.
std::string xml_escape(const std::string& s);

// The colour of series i of a palette of ten.
std::string palette(std::size_t i);

}  // namespace abuopt::studies::detail
