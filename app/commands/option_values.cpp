// The values of every option given to the chosen subcommand, checked in one place before the
// command runs (CLI11 converts them; some texts it converts are not values abuopt accepts):
//  * an empty value (--out '', --runs '') is not a value: CLI11 takes it as "not given" or as "";
//  * a number option (CLI11 type FLOAT, also a list of them) is a finite number: CLI11 reads
//    nan and inf, which would run and print NaN results (abuopt/common/number_text.hpp);
//  * an integer option (INT, UINT) is within its type's range: CLI11 clamps 99999999999999999999
//    to the largest value without a word.
// Each refusal is one ConfigError naming the option, the value and the rule (exit status 2).
#include <cerrno>
#include <cstdlib>
#include <string>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/number_text.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {

namespace {

void check_integer(const std::string& name, const std::string& text, bool is_unsigned) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  bool out_of_range = false;
  if (is_unsigned) {
    const char* p = begin;
    while (*p == ' ' || *p == '\t') ++p;
    (void)std::strtoull(begin, &end, 0);
    out_of_range = errno == ERANGE || *p == '-';
  } else {
    (void)std::strtoll(begin, &end, 0);
    out_of_range = errno == ERANGE;
  }
  if (out_of_range)
    throw ConfigError(name, text,
                      is_unsigned ? "must be a whole number in [0, 18446744073709551615]"
                                  : "must be a whole number in [-9223372036854775808, 9223372036854775807]");
}

void check_app(const CLI::App& app) {
  for (const CLI::Option* o : app.get_options()) {
    if (o->count() == 0 || o->get_type_size_max() == 0) continue;  // not given, or a flag
    const std::string name = o->get_name();
    const std::string type = o->get_type_name();
    for (const std::string& r : o->results()) {
      if (r.empty()) throw ConfigError(name, "''", "needs a value (an empty text is not one)");
      if (type == "FLOAT") (void)parse_finite_number(r, name, r, "must be a finite number");
      else if (type == "INT") check_integer(name, r, false);
      else if (type == "UINT") check_integer(name, r, true);
    }
  }
  for (const CLI::App* sub : app.get_subcommands()) check_app(*sub);
}

}  // namespace

void check_option_values(const CLI::App& app) { check_app(app); }

}  // namespace abuopt::app
