#include "abuopt/common/plot_style.hpp"

#include <array>
#include <cstdio>
#include <sstream>

#include "abuopt/common/gnuplot.hpp"

namespace abuopt::plot_style {

std::string colour(int k) {
  static const std::array<const char*, 10> c = {kBlue,     kOrange,   kGreen,    kRed,      "#9467bd",
                                                 "#8c564b", "#e377c2", kGrey,     "#bcbd22", "#17becf"};
  const int n = static_cast<int>(c.size());
  return c[static_cast<std::size_t>(((k % n) + n) % n)];
}

std::string png_terminal_line(const std::string& png_terminal, int width_px, int height_px) {
  std::ostringstream s;
  s << "set terminal " << png_terminal << " enhanced font '" << kFont << "," << kFontSize << "' size " << width_px
    << "," << height_px;
  if (png_terminal == "pngcairo") s << " linewidth 1.25";
  s << "\n";
  return s.str();
}

std::string pdf_terminal_line(int width_px, int height_px) {
  char size[64];
  std::snprintf(size, sizeof size, "%.2fin,%.2fin", width_px / kPdfPixelsPerInch, height_px / kPdfPixelsPerInch);
  std::ostringstream s;
  s << "set terminal pdfcairo enhanced font '" << kFont << "," << kPdfFontSize << "' size " << size
    << " linewidth 1.5\n";
  return s.str();
}

std::string preamble() {
  std::ostringstream s;
  s << "set encoding utf8\n";
  // ten colours, then the same ten dashed: a comparison of 11 - 20 methods still tells them apart
  for (int k = 0; k < 20; ++k)
    s << "set linetype " << k + 1 << " lc rgb '" << colour(k) << "' lw 2 dt " << (k < 10 ? 1 : 2) << " pt "
      << (k % 10 == 0 ? 7 : k % 10 == 1 ? 5 : k % 10 == 2 ? 9 : k % 10 == 3 ? 13 : 7 + k % 10) << " ps 0.8\n";
  s << "set border lw 1 lc rgb '#404040'\n"
    << "set tics out nomirror\n"
    << "set grid lc rgb '#d9d9d9' lw 1 dt solid\n"
    << "set key noopaque\n";
  return s.str();
}

std::string figure_script(const std::string& stem, const std::string& body, int width_px, int height_px,
                          const std::string& png_terminal) {
  std::ostringstream s;
  s << "# written by abuopt; run in this folder: gnuplot " << stem << ".gp (makes " << stem << ".png and " << stem
    << ".pdf)\n"
    << png_terminal_line(png_terminal, width_px, height_px) << "set output " << Gnuplot::quote(stem + ".png") << "\n"
    << preamble() << body << pdf_terminal_line(width_px, height_px) << "set output "
    << Gnuplot::quote(stem + ".pdf") << "\nreplot\nunset output\n";
  return s.str();
}

std::string angle_axis(const std::string& axis, bool with_range) {
  return (with_range ? "set " + axis + "range [0:2*pi]\n" : std::string()) + "set " + axis +
         "tics ('0' 0, 'π/2' pi/2, 'π' pi, '3π/2' 3*pi/2, '2π' 2*pi)\n";
}

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '_' || c == '^' || c == '@' || c == '&' || c == '~' || c == '{' || c == '}') out += '\\';
    out += c;
  }
  return out;
}

std::string literal(const std::string& text) { return Gnuplot::quote(text) + " noenhanced"; }

std::string typeset(const std::string& text) { return Gnuplot::quote(text); }

}  // namespace abuopt::plot_style
