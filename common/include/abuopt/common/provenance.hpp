#pragma once
// Provenance of a result: which abuopt computed it, from which source, with which config.
//
//   abuopt_version()      the project version of CMakeLists.txt ("0.1.0")
//   abuopt_git_commit()   `git describe --always --dirty --tags` of the source tree when abuopt was
//                         built ("1ab36e3", "1ab36e3-dirty"), "unknown" when it was not built from
//                         a git checkout; refreshed at every build (cmake/build_info.cmake)
//   config_hash(path)     "fnv1a64:<16 hex digits>" of the config file's bytes: the same file gives
//                         the same hash on every machine; any changed byte changes it
//
// Every result.json and summary.json carries them in a `provenance` object, and the evaluation
// archive in its `metadata` table (docs/archive.md).
#include <string>
#include <string_view>

namespace abuopt {

std::string abuopt_version();
std::string abuopt_git_commit();
// "fnv1a64:" + 16 lowercase hex digits of FNV-1a 64 over `bytes`.
std::string content_hash(std::string_view bytes);
// content_hash of the file's bytes; throws ConfigError naming the file when it cannot be read.
std::string config_hash(const std::string& path);

// The three together, for a result computed from the config file at `config_path` (ConfigError
// when it cannot be read). JSON writers store them as
//   "provenance": {"abuopt_version": ..., "git_commit": ..., "config_hash": ...}
struct Provenance {
  std::string abuopt_version;
  std::string git_commit;
  std::string config_hash;
};
Provenance provenance_of(const std::string& config_path);

}  // namespace abuopt
