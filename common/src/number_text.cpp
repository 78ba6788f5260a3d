#include "abuopt/common/number_text.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "abuopt/common/config_error.hpp"

namespace abuopt {

namespace {
bool blank(const char* p) {
  while (*p != '\0' && std::isspace(static_cast<unsigned char>(*p))) ++p;
  return *p == '\0';
}
}  // namespace

double parse_finite_number(const std::string& item, const std::string& key, const std::string& whole,
                           const std::string& rule) {
  const char* begin = item.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  const bool overflow = errno == ERANGE && std::isinf(v);
  if (item.find('\0') != std::string::npos || end == begin || !blank(end))
    throw ConfigError(key, whole, "'" + item + "' is not a number; " + rule);
  if (overflow || !std::isfinite(v))
    throw ConfigError(key, whole, "'" + item + "' is not a finite number; " + rule);
  return v;
}

std::vector<double> parse_number_list(const std::string& text, char sep, const std::string& key,
                                      const std::string& rule) {
  std::vector<double> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t at = text.find(sep, start);
    const std::string item = text.substr(start, at == std::string::npos ? std::string::npos : at - start);
    if (blank(item.c_str())) throw ConfigError(key, text, "has an empty item; " + rule);
    out.push_back(parse_finite_number(item, key, text, rule));
    if (at == std::string::npos) break;
    start = at + 1;
  }
  return out;
}

long long parse_integer(const std::string& text, const std::string& key, long long lo, long long hi) {
  const std::string range = "must be a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(begin, &end, 10);
  if (text.find('\0') != std::string::npos || end == begin || !blank(end)) throw ConfigError(key, text, range);
  if (errno == ERANGE || v < lo || v > hi) throw ConfigError(key, text, range);
  return v;
}

}  // namespace abuopt
