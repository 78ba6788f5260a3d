#pragma once
// The one look of every abuopt figure: fonts, sizes, colours, line widths, terminals, the typeset
// axis labels and the angle axis. Every plot (the Gnuplot helpers, reproduce, eqset, optimize,
// compare) gets its terminal lines and preamble from here, so a change of style is made once.
//
// Each figure is written twice by its script: a PNG (pngcairo; a screen look) and a PDF (pdfcairo;
// vector, for a paper), the second by `replot` on the same data:
//
//   figure_script("coverage", body, 900, 650)  ->  set terminal pngcairo ...; set output 'coverage.png'
//                                                  <preamble> <body>
//                                                  set terminal pdfcairo ...; set output 'coverage.pdf'
//                                                  replot; unset output
//
// Paths in scripts are relative to the script's own folder (run `gnuplot NAME.gp` there).
//
// Text is "enhanced" (typeset): `_` makes a subscript, `^` a superscript, `{}` groups, so labels
// read beta_1 as a Greek beta with a subscript 1. Text that comes from a config or a user (case
// labels, solver and problem names, file names) must be shown literally: wrap it with literal()
// (a quoted string with gnuplot's `noenhanced` flag, for titles and key entries) or escape() (for
// a piece inside a typeset string).
#include <string>

namespace abuopt::plot_style {

// Font of every text (DejaVu Sans: has Greek; installed with gnuplot's cairo terminals).
inline constexpr const char* kFont = "DejaVu Sans";
inline constexpr int kFontSize = 11;       // PNG, points
inline constexpr int kPdfFontSize = 9;     // PDF, points (a figure ~6 in wide on the page)
inline constexpr double kPdfPixelsPerInch = 150;  // PDF size = PNG size / this

// Categorical colours (Tableau 10, colour-blind safer than gnuplot's defaults), in order of use.
std::string colour(int k);  // k >= 0, cycles
inline constexpr const char* kBlue = "#1f77b4";
inline constexpr const char* kOrange = "#ff7f0e";
inline constexpr const char* kGreen = "#2ca02c";
inline constexpr const char* kRed = "#d62728";
inline constexpr const char* kGrey = "#7f7f7f";
// Equilibrium-set membership: in the set / outside it.
inline constexpr const char* kInSet = "#9ecae1";
inline constexpr const char* kOutOfSet = "#d4d4d4";

// Typeset axis labels (enhanced text).
inline constexpr const char* kBeta1 = "β_1 [rad]";
inline constexpr const char* kBeta2 = "β_2 [rad]";
inline constexpr const char* kIr = "|I_r| [10^{-7} kg m]";
inline constexpr const char* kIrx = "I_{r,x} [10^{-7} kg m]";
inline constexpr const char* kMu = "friction coefficient μ";
inline constexpr const char* kFreqHz = "f [Hz]";
inline constexpr const char* kTimeS = "t [s]";
inline constexpr const char* kPctMi = "%MI [%]";

// "set terminal pngcairo enhanced ..." / "set terminal pdfcairo ..." lines (with the font, size,
// line width). `png_terminal`: "pngcairo" or, on a gnuplot without cairo, "png".
std::string png_terminal_line(const std::string& png_terminal, int width_px, int height_px);
std::string pdf_terminal_line(int width_px, int height_px);
// The settings every figure starts with: encoding, line types 1..10 in colour(k) and 11..20 the same
// dashed, grid, key, tics.
std::string preamble();
// The whole script text of one figure: PNG then PDF of `body`, outputs `stem`.png and `stem`.pdf
// (relative to the script's folder). `png_terminal` as above.
std::string figure_script(const std::string& stem, const std::string& body, int width_px, int height_px,
                          const std::string& png_terminal = "pngcairo");

// An axis over one turn: range [0, 2 pi], tics at 0, pi/2, pi, 3pi/2, 2pi. axis: "x" or "y".
// with_range false: the tics only (an image of grid cells keeps its own range, the cells' edges).
std::string angle_axis(const std::string& axis, bool with_range = true);

// Literal text in a typeset string: the enhanced-text specials _ ^ @ & ~ { } escaped.
std::string escape(const std::string& text);
// A quoted string shown literally: "'a_b' noenhanced" (for set title/xlabel and plot titles).
std::string literal(const std::string& text);
// A quoted typeset string: "'β_1 [rad]'".
std::string typeset(const std::string& text);

}  // namespace abuopt::plot_style
