#include "abuopt/common/text.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace abuopt {

namespace {
const char* non_finite(double v) { return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf"); }
}  // namespace

std::string format_number(double v) {
  if (!std::isfinite(v)) return non_finite(v);
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

std::string format_significant(double v, int digits) {
  if (!std::isfinite(v)) return non_finite(v);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

std::string format_fixed(double v, int digits) {
  if (!std::isfinite(v)) return "n/a";
  char buf[512];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}

std::string csv_number(double v) { return format_number(v); }
std::string csv_number(double v, int significant_digits) { return format_significant(v, significant_digits); }
std::string csv_optional(const std::optional<double>& v, int significant_digits) {
  return v ? format_significant(*v, significant_digits) : std::string();
}

std::string markdown_cell(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '|') o += "\\|";
    else if (c == '\n' || c == '\r') o += ' ';
    else o += c;
  }
  return o;
}

std::string file_safe(const std::string& s) {
  std::string out = s;
  for (char& c : out)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  return out;
}

}  // namespace abuopt
