#pragma once
// Text helpers shared by the reproduction's sources (private to studies/).
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>

#include "abuopt/studies/reproduction_table.hpp"
#include "abuopt/studies/verdicts.hpp"

namespace abuopt::studies_detail {

inline constexpr double kZ95 = 1.959963984540054;

inline std::string num(double v, int digits) {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// Shortest readable form of a parameter value (1, 0.025, 19).
inline std::string short_num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

inline std::string opt_num(const std::optional<double>& v, int digits) { return v ? num(*v, digits) : "-"; }

inline std::string mi_text(const CaseSummary& s) {
  return num(s.pct_mi_x, 2) + " [" + num(s.ci_x[0], 1) + ", " + num(s.ci_x[1], 1) + "]";
}
inline std::string mean_text(const CaseSummary& s) { return num(s.mean_x, 2) + " +- " + num(kZ95 * s.sem_x, 2); }

inline std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

inline std::string csv_num(double v) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}
inline std::string csv_opt(const std::optional<double>& v) { return v ? csv_num(*v) : ""; }

inline std::string table_heading(const ReproductionTable& t) {
  const std::string name = (t.id == "final" || t.id == "mu") ? t.title : "Table " + t.id + ": " + t.title;
  return name;
}

}  // namespace abuopt::studies_detail
