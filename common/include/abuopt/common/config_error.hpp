#pragma once
// The one exception type for user errors (config files, command-line values). Its message names
// the key path, the offending value and the rule, e.g.
//   "profile.segments[1].duration_s = -2: must be > 0"
// Internal invariants use assert; numerical trouble inside one simulation is an outcome status.
#include <stdexcept>
#include <string>

namespace abuopt {

class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(const std::string& message) : std::runtime_error(message) {}
  // "<path> = <value>: <rule>"
  ConfigError(const std::string& path, const std::string& value, const std::string& rule);
};

}  // namespace abuopt
