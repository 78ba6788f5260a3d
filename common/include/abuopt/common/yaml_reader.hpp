#pragma once
// YamlReader: a strict, path-aware view of one YAML mapping.
//
// Every key read is remembered; finish() throws ConfigError for any key that was not read, so a
// misspelt key is an error instead of a silently ignored setting (as Drake's yaml loader does).
// Typed getters throw ConfigError naming the full key path, the value and the rule:
//   "simulation.rtol = abc: must be a number"
//
//   YamlReader root = YamlReader::load_file("configs/x.yaml");
//   double mu = root.get_double_or("mu", 0.02, Rule::non_negative());
//   YamlReader sim = root.child("simulation");     // optional section: empty reader if absent
//   ...; sim.finish(); root.finish();
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "abuopt/common/config_error.hpp"

namespace abuopt {

// A check on a number: returns an empty string when the value is fine, else the rule it broke.
struct Rule {
  std::function<std::string(double)> check;
  static Rule any();
  static Rule positive();                       // > 0
  static Rule non_negative();                   // >= 0
  static Rule in_range(double lo, double hi);   // lo <= v <= hi
  static Rule at_least(double lo);              // >= lo
  static Rule positive_at_most(double hi);      // 0 < v <= hi ("must be > 0" / "must be <= hi")
  static Rule non_negative_at_most(double hi);  // 0 <= v <= hi ("must be >= 0" / "must be <= hi")
};

// The size of a config document with every alias expanded, and its nesting depth: more is refused
// (a config is a few hundred values; nested aliases, "billion laughs", or a structure that contains
// itself would otherwise take unbounded time and memory). The same limits hold for a config given
// as a Python dict (python/src/convert.cpp).
inline constexpr double kMaxConfigNodes = 1e6;
inline constexpr std::size_t kMaxConfigDepth = 64;

class YamlReader {
 public:
  YamlReader() = default;
  YamlReader(YAML::Node node, std::string path);

  // Parses a file; a missing or malformed file is a ConfigError naming the file.
  static YamlReader load_file(const std::string& file);
  static YamlReader load_string(const std::string& text, const std::string& name = "<string>");

  const std::string& path() const { return path_; }
  bool present() const { return node_ && !node_.IsNull(); }
  bool has(const std::string& key) const;
  const YAML::Node& node() const { return node_; }

  // Full path of a key below this node ("simulation.rtol", "segments[2]").
  std::string key_path(const std::string& key) const;

  double get_double(const std::string& key, const Rule& rule = Rule::any());
  double get_double_or(const std::string& key, double fallback, const Rule& rule = Rule::any());
  long get_int(const std::string& key, const Rule& rule = Rule::any());
  long get_int_or(const std::string& key, long fallback, const Rule& rule = Rule::any());
  bool get_bool_or(const std::string& key, bool fallback);
  std::string get_string(const std::string& key);
  std::string get_string_or(const std::string& key, const std::string& fallback);
  // A string that must be one of `choices`; the message lists them.
  std::string get_choice_or(const std::string& key, const std::string& fallback,
                            const std::vector<std::string>& choices);
  std::vector<double> get_double_list(const std::string& key, const Rule& rule = Rule::any());
  // A list of strings (a single string counts as a list of one); absent: `fallback`.
  std::vector<std::string> get_string_list_or(const std::string& key, const std::vector<std::string>& fallback = {});

  // Sub-mapping; an absent key gives an empty reader (present() == false).
  YamlReader child(const std::string& key);
  // Elements of a sequence, each as its own reader with path "key[i]".
  std::vector<YamlReader> children(const std::string& key);
  // Throws if the node at `key` exists but is not a sequence/mapping.
  bool is_sequence(const std::string& key) const;

  // Counts `key` as read without reading it (a caller that reads it another way).
  void mark_read(const std::string& key) { read_.insert(key); }

  // Throws ConfigError for the first key of this mapping that was never read.
  void finish() const;

  // Reads a scalar node as a number, with the path for messages.
  static double scalar_as_double(const YAML::Node& n, const std::string& path, const Rule& rule);

 private:
  YAML::Node at(const std::string& key);
  YAML::Node node_;
  std::string path_;
  std::set<std::string> read_;
};

// Deep merge: a copy of `base` with `overlay` applied (maps merge recursively, anything else
// replaces). Neither argument is modified.
YAML::Node merge_yaml(const YAML::Node& base, const YAML::Node& overlay);

// A printable form of a YAML node for error messages (scalars as written, others as flow YAML).
std::string yaml_value_text(const YAML::Node& n);

}  // namespace abuopt
