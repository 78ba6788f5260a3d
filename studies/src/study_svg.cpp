// Inline SVG figures of the study report (study_svg.hpp).
#include "study_svg.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace abuopt::studies::detail {

namespace {

// Ticks at 1, 2 or 5 x 10^k covering [lo, hi].
std::vector<double> nice_ticks(double lo, double hi, int target = 6) {
  std::vector<double> t;
  if (!(hi > lo)) return {lo};
  const double raw = (hi - lo) / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * step; v += step) t.push_back(std::fabs(v) < 1e-12 * step ? 0.0 : v);
  return t;
}

std::string num(double v, int precision = 4) {
  std::ostringstream os;
  os << std::setprecision(precision) << v;
  return os.str();
}

std::string px(double v) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(1) << v;
  return os.str();
}

}  // namespace

std::string xml_escape(const std::string& s) {
  std::string o;
  for (char ch : s) {
    switch (ch) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += ch;
    }
  }
  return o;
}

std::string palette(std::size_t i) {
  static const char* const p[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                  "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
  return p[i % 10];
}

std::string svg_line_chart(const std::string& title, const std::string& x_label, const std::string& y_label,
                           const std::vector<SvgSeries>& series, int width, int height) {
  const double inf = std::numeric_limits<double>::infinity();
  double x0 = inf, x1 = -inf, y0 = inf, y1 = -inf;
  std::vector<const SvgSeries*> shown;
  for (const auto& s : series) {
    bool any = false;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        x0 = std::min(x0, s.x[i]);
        x1 = std::max(x1, s.x[i]);
        y0 = std::min(y0, s.y[i]);
        y1 = std::max(y1, s.y[i]);
        any = true;
      }
    if (any) shown.push_back(&s);
  }
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" viewBox=\"0 0 " << width << " " << height << "\" role=\"img\" aria-label=\"" << xml_escape(title)
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << width / 2 << "\" y=\"18\" text-anchor=\"middle\" font-size=\"14\">" << xml_escape(title)
    << "</text>\n";
  if (shown.empty()) {
    o << "<text x=\"" << width / 2 << "\" y=\"" << height / 2 << "\" text-anchor=\"middle\">no data</text>\n</svg>\n";
    return o.str();
  }
  if (!(x1 > x0)) x1 = x0 + 1;
  bool dots = false;  // dots at the ends of the x range would be cut by the frame: pad it
  for (const SvgSeries* s : shown) dots = dots || s->markers || s->width <= 0;
  if (dots) {
    const double pad = 0.03 * (x1 - x0);
    x0 -= pad;
    x1 += pad;
  }
  if (!(y1 > y0)) {
    const double pad = std::max(std::fabs(y0) * 0.05, 1e-9);
    y0 -= pad;
    y1 += pad;
  } else {
    const double pad = 0.05 * (y1 - y0);
    y0 -= pad;
    y1 += pad;
  }
  const double L = 70, R = width - 20.0, T = 30, B = height - 70.0;
  const auto X = [&](double v) { return L + (v - x0) / (x1 - x0) * (R - L); };
  const auto Y = [&](double v) { return B - (v - y0) / (y1 - y0) * (B - T); };
  o << "<rect x=\"" << L << "\" y=\"" << T << "\" width=\"" << R - L << "\" height=\"" << B - T
    << "\" fill=\"none\" stroke=\"#444\"/>\n";
  for (double t : nice_ticks(x0, x1)) {
    o << "<line x1=\"" << px(X(t)) << "\" y1=\"" << B << "\" x2=\"" << px(X(t)) << "\" y2=\"" << T
      << "\" stroke=\"#ddd\"/><text x=\"" << px(X(t)) << "\" y=\"" << B + 15 << "\" text-anchor=\"middle\">" << num(t)
      << "</text>\n";
  }
  for (double t : nice_ticks(y0, y1)) {
    o << "<line x1=\"" << L << "\" y1=\"" << px(Y(t)) << "\" x2=\"" << R << "\" y2=\"" << px(Y(t))
      << "\" stroke=\"#ddd\"/><text x=\"" << L - 5 << "\" y=\"" << px(Y(t) + 4) << "\" text-anchor=\"end\">" << num(t)
      << "</text>\n";
  }
  o << "<text x=\"" << (L + R) / 2 << "\" y=\"" << B + 32 << "\" text-anchor=\"middle\">" << xml_escape(x_label)
    << "</text>\n<text transform=\"translate(16," << (T + B) / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
    << xml_escape(y_label) << "</text>\n";
  for (const SvgSeries* s : shown) {
    std::ostringstream d;
    bool pen_up = true;
    std::size_t points = 0;
    for (std::size_t i = 0; i < s->x.size() && i < s->y.size(); ++i) {
      if (!(std::isfinite(s->x[i]) && std::isfinite(s->y[i]))) {
        pen_up = true;
        continue;
      }
      d << (pen_up ? "M" : "L") << px(X(s->x[i])) << " " << px(Y(s->y[i])) << " ";
      pen_up = false;
      ++points;
    }
    if (s->width > 0)
      o << "<path d=\"" << d.str() << "\" fill=\"none\" stroke=\"" << s->color << "\" stroke-width=\"" << s->width << "\""
        << (s->dashed ? " stroke-dasharray=\"6 4\"" : "") << "/>\n";
    if (points == 1 || s->markers)  // a single point or markers: a dot at every point
      for (std::size_t i = 0; i < s->x.size(); ++i)
        if (std::isfinite(s->x[i]) && std::isfinite(s->y[i]))
          o << "<circle cx=\"" << px(X(s->x[i])) << "\" cy=\"" << px(Y(s->y[i])) << "\" r=\""
            << (s->markers ? 4.5 : 3.0) << "\" fill=\"" << (s->dashed && s->markers ? "white" : s->color)
            << "\" stroke=\"" << s->color << "\" stroke-width=\"1.5\"/>\n";
  }
  // legend below the axis label, in columns
  const double lx0 = L, ly = B + 50;
  double lx = lx0, row = 0;
  for (const SvgSeries* s : shown) {
    const double w = 40 + 7.0 * static_cast<double>(s->name.size());
    if (lx + w > R && lx > lx0) {
      lx = lx0;
      row += 16;
    }
    if (s->width > 0)
      o << "<line x1=\"" << px(lx) << "\" y1=\"" << px(ly + row - 4) << "\" x2=\"" << px(lx + 24) << "\" y2=\""
        << px(ly + row - 4) << "\" stroke=\"" << s->color << "\" stroke-width=\"" << s->width << "\""
        << (s->dashed ? " stroke-dasharray=\"6 4\"" : "") << "/>";
    if (s->markers || s->width <= 0)
      o << "<circle cx=\"" << px(lx + 12) << "\" cy=\"" << px(ly + row - 4) << "\" r=\"4.5\" fill=\""
        << (s->dashed && s->markers ? "white" : s->color) << "\" stroke=\"" << s->color << "\" stroke-width=\"1.5\"/>";
    o << "<text x=\"" << px(lx + 28) << "\" y=\"" << px(ly + row)
      << "\">" << xml_escape(s->name) << "</text>\n";
    lx += w;
  }
  o << "</svg>\n";
  return o.str();
}

std::string svg_heatmap(const std::string& title, const std::string& x_label, const std::string& y_label,
                        const std::vector<double>& xs, const std::vector<double>& ys,
                        const std::vector<std::vector<double>>& values, double centre, int width, int height) {
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" viewBox=\"0 0 " << width << " " << height << "\" role=\"img\" aria-label=\"" << xml_escape(title)
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << width / 2 << "\" y=\"18\" text-anchor=\"middle\" font-size=\"14\">" << xml_escape(title)
    << "</text>\n";
  double span = 1e-12;
  for (const auto& row : values)
    for (double v : row)
      if (std::isfinite(v)) span = std::max(span, std::fabs(v - centre));
  const double L = 90, R = width - 20.0, T = 30, B = height - 50.0;
  const double cw = (R - L) / std::max<std::size_t>(1, xs.size()), ch = (B - T) / std::max<std::size_t>(1, ys.size());
  for (std::size_t r = 0; r < ys.size() && r < values.size(); ++r)
    for (std::size_t c = 0; c < xs.size() && c < values[r].size(); ++c) {
      const double v = values[r][c];
      std::string fill = "#cccccc";
      if (std::isfinite(v)) {
        const double a = std::min(1.0, std::fabs(v - centre) / span);
        const int light = static_cast<int>(std::lround(255 - 150 * a));
        std::ostringstream f;
        f << "rgb(" << (v > centre ? 255 : light) << "," << light << "," << (v > centre ? light : 255) << ")";
        fill = f.str();
      }
      const double x = L + c * cw, y = B - (r + 1) * ch;  // first row at the bottom
      o << "<rect x=\"" << px(x) << "\" y=\"" << px(y) << "\" width=\"" << px(cw) << "\" height=\"" << px(ch)
        << "\" fill=\"" << fill << "\" stroke=\"white\"/><text x=\"" << px(x + cw / 2) << "\" y=\"" << px(y + ch / 2 + 4)
        << "\" text-anchor=\"middle\">" << (std::isfinite(v) ? num(v, 3) : "n/a") << "</text>\n";
    }
  for (std::size_t c = 0; c < xs.size(); ++c)
    o << "<text x=\"" << px(L + (c + 0.5) * cw) << "\" y=\"" << B + 16 << "\" text-anchor=\"middle\">" << num(xs[c])
      << "</text>\n";
  for (std::size_t r = 0; r < ys.size(); ++r)
    o << "<text x=\"" << L - 6 << "\" y=\"" << px(B - (r + 0.5) * ch + 4) << "\" text-anchor=\"end\">" << num(ys[r])
      << "</text>\n";
  o << "<text x=\"" << (L + R) / 2 << "\" y=\"" << B + 36 << "\" text-anchor=\"middle\">" << xml_escape(x_label)
    << "</text>\n<text transform=\"translate(16," << (T + B) / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
    << xml_escape(y_label) << "</text>\n</svg>\n";
  return o.str();
}

std::string svg_points_over_set(const std::string& title, const std::string& x_label, const std::string& y_label,
                                std::size_t n, const std::vector<char>& in_set, const std::string& set_name,
                                const std::vector<SvgPointGroup>& groups, int size) {
  const int width = size + 360, height = size;
  const double L = 70, T = 30, B = height - 50.0, R = L + (B - T);
  const auto X = [&](double deg) { return L + deg / 360.0 * (R - L); };
  const auto Y = [&](double deg) { return B - deg / 360.0 * (B - T); };
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" viewBox=\"0 0 " << width << " " << height << "\" role=\"img\" aria-label=\"" << xml_escape(title)
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << (L + R) / 2 << "\" y=\"18\" text-anchor=\"middle\" font-size=\"14\">" << xml_escape(title)
    << "</text>\n";
  const double cell = (R - L) / static_cast<double>(std::max<std::size_t>(1, n));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      if (i * n + j < in_set.size() && in_set[i * n + j])
        o << "<rect x=\"" << px(L + i * cell) << "\" y=\"" << px(B - (j + 1) * cell) << "\" width=\"" << px(cell + 0.3)
          << "\" height=\"" << px(cell + 0.3) << "\" fill=\"#cfe3cf\"/>";
  o << "\n<rect x=\"" << L << "\" y=\"" << T << "\" width=\"" << R - L << "\" height=\"" << B - T
    << "\" fill=\"none\" stroke=\"#444\"/>\n";
  for (double t = 0; t <= 360; t += 90)
    o << "<text x=\"" << px(X(t)) << "\" y=\"" << B + 15 << "\" text-anchor=\"middle\">" << num(t)
      << "</text><text x=\"" << L - 5 << "\" y=\"" << px(Y(t) + 4) << "\" text-anchor=\"end\">" << num(t) << "</text>\n";
  o << "<text x=\"" << (L + R) / 2 << "\" y=\"" << B + 34 << "\" text-anchor=\"middle\">" << xml_escape(x_label)
    << "</text>\n<text transform=\"translate(16," << (T + B) / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
    << xml_escape(y_label) << "</text>\n";
  for (const auto& g : groups)
    for (const auto& [x, y] : g.points)
      o << "<circle cx=\"" << px(X(x)) << "\" cy=\"" << px(Y(y)) << "\" r=\"3\" "
        << (g.hollow ? "fill=\"none\" stroke=\"" + g.color + "\"" : "fill=\"" + g.color + "\" fill-opacity=\"0.7\"")
        << "/>";
  // legend on the right
  double ly = T + 10;
  o << "\n<rect x=\"" << px(R + 15) << "\" y=\"" << px(ly - 9) << "\" width=\"12\" height=\"12\" fill=\"#cfe3cf\"/>"
    << "<text x=\"" << px(R + 32) << "\" y=\"" << px(ly + 1) << "\">" << xml_escape(set_name) << "</text>\n";
  for (const auto& g : groups) {
    ly += 20;
    o << "<circle cx=\"" << px(R + 21) << "\" cy=\"" << px(ly - 3) << "\" r=\"4\" "
      << (g.hollow ? "fill=\"none\" stroke=\"" + g.color + "\"" : "fill=\"" + g.color + "\"") << "/><text x=\""
      << px(R + 32) << "\" y=\"" << px(ly + 1) << "\">" << xml_escape(g.name) << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace abuopt::studies::detail
