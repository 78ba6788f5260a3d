#include "abuopt/common/config_error.hpp"

namespace abuopt {

ConfigError::ConfigError(const std::string& path, const std::string& value, const std::string& rule)
    : std::runtime_error(path + " = " + value + ": " + rule) {}

}  // namespace abuopt
