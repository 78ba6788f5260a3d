#pragma once
// Text helpers shared by the reproduction's sources (private to studies/).
#include <optional>
#include <string>

#include "abuopt/common/text.hpp"

#include "abuopt/studies/reproduction_table.hpp"
#include "abuopt/studies/verdicts.hpp"

namespace abuopt::studies_detail {

inline constexpr double kZ95 = 1.959963984540054;

// Fixed decimals for tables a person reads ("n/a" when not finite).
inline std::string num(double v, int digits) { return format_fixed(v, digits); }

// Shortest readable form of a parameter value (1, 0.025, 19).
inline std::string short_num(double v) { return format_significant(v, 6); }

inline std::string opt_num(const std::optional<double>& v, int digits) { return v ? num(*v, digits) : "-"; }

inline std::string mi_text(const CaseSummary& s) {
  return num(s.pct_mi_x, 2) + " [" + num(s.ci_x[0], 1) + ", " + num(s.ci_x[1], 1) + "]";
}
inline std::string mean_text(const CaseSummary& s) { return num(s.mean_x, 2) + " +- " + num(kZ95 * s.sem_x, 2); }

// CSV numbers of the reproduction's files: shortest text that reads back to the same double
// (common/text.hpp); an absent value is an empty field.
inline std::string csv_num(double v) { return csv_number(v); }
inline std::string csv_opt(const std::optional<double>& v) { return v ? csv_number(*v) : std::string(); }

inline std::string table_heading(const ReproductionTable& t) {
  const std::string name = (t.id == "final" || t.id == "mu") ? t.title : "Table " + t.id + ": " + t.title;
  return name;
}

}  // namespace abuopt::studies_detail
