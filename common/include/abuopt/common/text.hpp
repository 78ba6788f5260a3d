#pragma once
// Text and CSV output shared by every layer, so that every file abuopt writes formats numbers and
// fields the same way:
//
//   format_number(v)           shortest text that reads back to the same double ("0.324", "1e-07")
//   format_significant(v, d)   printf "%.<d>g" ("8.466316723" for d = 10)
//   format_fixed(v, d)         printf "%.<d>f" (for tables a person reads)
//   csv_field(s)               one CSV field (RFC 4180, below)
//   csv_number(v), csv_number(v, d), csv_optional(v, d)
//   markdown_cell(s)           text for one cell of a Markdown table
//
// Non-finite numbers: "nan", "inf" and "-inf" in files (format_number, format_significant,
// csv_number; Python, NumPy and pandas read them back), "n/a" in tables for people (format_fixed).
// An absent optional value is an empty CSV field. CSV fields follow RFC 4180: a field that holds a
// comma, a double quote, CR or LF is enclosed in double quotes with its quotes doubled; newlines are
// kept inside the quotes (a CSV reader restores them), never dropped.
#include <optional>
#include <string>

namespace abuopt {

std::string format_number(double v);
std::string format_significant(double v, int digits);
std::string format_fixed(double v, int digits);

std::string csv_field(const std::string& s);
std::string csv_number(double v);
std::string csv_number(double v, int significant_digits);
// Empty when absent.
std::string csv_optional(const std::optional<double>& v, int significant_digits);

// '|' escaped, CR/LF as spaces: a Markdown table cell stays one cell.
std::string markdown_cell(const std::string& s);

// A label as a piece of a file name: every character but letters, digits, '-' and '_' becomes '_'.
std::string file_safe(const std::string& s);

}  // namespace abuopt
