#include "abuopt/common/config_error.hpp"

namespace abuopt {

namespace {
// Built with append(): GCC 12 warns falsely (-Wrestrict) on chained operator+ here.
std::string compose(const std::string& path, const std::string& value, const std::string& rule) {
  std::string m;
  m.reserve(path.size() + value.size() + rule.size() + 5);
  m.append(path).append(" = ").append(value).append(": ").append(rule);
  return m;
}
}  // namespace

ConfigError::ConfigError(const std::string& path, const std::string& value, const std::string& rule)
    : std::runtime_error(compose(path, value, rule)) {}

}  // namespace abuopt
