#include "abuopt/common/provenance.hpp"

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "abuopt/common/config_error.hpp"

namespace abuopt {

std::string content_hash(std::string_view bytes) {
  std::uint64_t h = 14695981039346656037ULL;  // FNV-1a 64 offset basis
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ULL;  // FNV 64 prime
  }
  char out[32];
  std::snprintf(out, sizeof out, "fnv1a64:%016llx", static_cast<unsigned long long>(h));
  return out;
}

std::string config_hash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError("config file '" + path + "' cannot be read (for its hash)");
  std::ostringstream os;
  os << in.rdbuf();
  return content_hash(os.str());
}

Provenance provenance_of(const std::string& config_path) {
  return {abuopt_version(), abuopt_git_commit(), config_hash(config_path)};
}

}  // namespace abuopt
