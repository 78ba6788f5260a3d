#include "abuopt/common/yaml_reader.hpp"

#include "abuopt/common/suggest.hpp"

#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <vector>
#include <sys/stat.h>
#include <cstdlib>
#include <sstream>

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>

namespace abuopt {

namespace {
constexpr const char* kNullRule = "has no value (null): give a value, or leave the key out for its default";
std::string fmt(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}
}  // namespace

Rule Rule::any() {
  return {[](double v) { return std::isfinite(v) ? std::string() : std::string("must be finite"); }};
}
Rule Rule::positive() {
  return {[](double v) { return (std::isfinite(v) && v > 0) ? std::string() : std::string("must be > 0"); }};
}
Rule Rule::non_negative() {
  return {[](double v) { return (std::isfinite(v) && v >= 0) ? std::string() : std::string("must be >= 0"); }};
}
Rule Rule::in_range(double lo, double hi) {
  return {[lo, hi](double v) {
    return (std::isfinite(v) && v >= lo && v <= hi)
               ? std::string()
               : "must be in [" + fmt(lo) + ", " + fmt(hi) + "]";
  }};
}
Rule Rule::positive_at_most(double hi) {
  return {[hi](double v) {
    if (!(std::isfinite(v) && v > 0)) return std::string("must be > 0");
    return v <= hi ? std::string() : "must be <= " + fmt(hi) + " (the largest value abuopt accepts here)";
  }};
}
Rule Rule::non_negative_at_most(double hi) {
  return {[hi](double v) {
    if (!(std::isfinite(v) && v >= 0)) return std::string("must be >= 0");
    return v <= hi ? std::string() : "must be <= " + fmt(hi) + " (the largest value abuopt accepts here)";
  }};
}
Rule Rule::at_least(double lo) {
  return {[lo](double v) { return (std::isfinite(v) && v >= lo) ? std::string() : "must be >= " + fmt(lo); }};
}

std::string yaml_value_text(const YAML::Node& n) {
  if (!n) return "<missing>";
  if (n.IsScalar()) return n.Scalar();
  if (n.IsNull()) return "null";
  YAML::Emitter e;
  e << YAML::Flow << n;
  return e.c_str();
}

namespace {
// As yaml_value_text, cut to about `max_chars` characters between elements ("{design: grid, grid: 32,
// ...}"): the value of an unknown section in a message, which would otherwise be the whole section.
std::string yaml_value_brief(const YAML::Node& n, std::size_t max_chars = 60) {
  if (!n || n.IsScalar() || n.IsNull()) return yaml_value_text(n);
  // Element by element, so that the cut falls between elements and the text stays readable.
  const bool map = n.IsMap();
  std::string out = map ? "{" : "[";
  std::size_t i = 0;
  for (auto it = n.begin(); it != n.end(); ++it, ++i) {
    std::string item;
    if (map) {
      const std::string k = it->first.IsScalar() ? it->first.Scalar() : yaml_value_text(it->first);
      item = k + ": " + (it->second.IsScalar() ? it->second.Scalar() : (it->second.IsMap() ? "{...}" : "[...]"));
    } else {
      item = it->IsScalar() ? it->Scalar() : (it->IsMap() ? "{...}" : "[...]");
    }
    if (i > 0 && out.size() + item.size() + 2 > max_chars) {
      out += ", ...";
      break;
    }
    out += (i ? ", " : "") + item;
  }
  return out + (map ? "}" : "]");
}
}  // namespace

YamlReader::YamlReader(YAML::Node node, std::string path) : node_(std::move(node)), path_(std::move(path)) {
  if (node_ && !node_.IsNull() && !node_.IsMap()) {
    throw ConfigError(path_.empty() ? "<top level>" : path_, yaml_value_text(node_), "must be a mapping of keys");
  }
}

namespace {

// Every mapping of the document must have each key once: yaml-cpp keeps both entries of a
// duplicate key and a lookup silently sees the first, so `friction_mu` twice (or two `abu:`
// sections) would keep one of them without a word.
void check_unique_keys(const YAML::Node& n, const std::string& path, const std::string& where) {
  if (n.IsMap()) {
    std::set<std::string> seen;
    for (auto it = n.begin(); it != n.end(); ++it) {
      const std::string k = it->first.IsScalar() ? it->first.Scalar() : yaml_value_text(it->first);
      const std::string kp = path.empty() ? k : path + "." + k;
      if (!seen.insert(k).second)
        throw ConfigError(where + kp, yaml_value_text(it->second),
                          "appears twice in the same mapping (line " + std::to_string(it->first.Mark().line + 1) +
                              "): give each key once");
      check_unique_keys(it->second, kp, where);
    }
  } else if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i) check_unique_keys(n[i], path + "[" + std::to_string(i) + "]", where);
  }
}

// The shape of a config, checked on the parser's events before any node is built (one pass, one
// mechanism for every alias, tag and nesting problem; yaml-cpp's nodes share an aliased node, so
// a walk over them, check_unique_keys or a reader, would expand aliases):
//  * an alias inside the node it names (`a: &x [*x]`) is a loop: refused (a walk over it never ends);
//  * the document with every alias expanded has at most kMaxConfigNodes nodes and nests at most
//    kMaxConfigDepth deep (nested aliases can expand exponentially, "billion laughs");
//  * no node has an explicit tag (`!foo`, `!!str`): a config is plain data, a tag would be ignored.
// Only the first document is checked; a second one is an error of its own (single_document).
class ConfigShape final : public YAML::EventHandler {
 public:
  explicit ConfigShape(std::string what) : what_(std::move(what)) {}
  void OnDocumentStart(const YAML::Mark&) override { ++documents_; }
  void OnDocumentEnd() override {}
  void OnAnchor(const YAML::Mark&, const std::string& name) override { anchor_name_ = name; }
  void OnNull(const YAML::Mark& m, YAML::anchor_t anchor) override { leaf(m, "", anchor, "~"); }
  void OnScalar(const YAML::Mark& m, const std::string& tag, YAML::anchor_t anchor, const std::string& v) override {
    leaf(m, tag, anchor, v);
  }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t anchor) override {
    if (!active()) return;
    const std::string name = names_.count(anchor) ? "*" + names_[anchor] : std::string("an alias");
    for (const Frame& f : stack_)
      if (f.anchor == anchor && anchor != YAML::NullAnchor)
        fail(m, name, "refers to the node it is part of (a loop): a config cannot contain itself");
    const auto it = anchors_.find(anchor);
    const Extent e = it == anchors_.end() ? Extent{1, 0} : it->second;
    add(m, name, e.nodes, e.height);
    end_value();
  }
  void OnSequenceStart(const YAML::Mark& m, const std::string& tag, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    open(m, tag, anchor, false);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& m, const std::string& tag, YAML::anchor_t anchor, YAML::EmitterStyle::value) override {
    open(m, tag, anchor, true);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Extent {
    double nodes;        // with every alias expanded
    std::size_t height;  // levels below the node
  };
  struct Frame {
    YAML::anchor_t anchor = YAML::NullAnchor;
    bool map = false;
    bool expect_key = true;
    std::string key;
    std::size_t index = 0;
    double nodes_at_start = 0;
    std::size_t height = 0;
  };

  bool active() const { return documents_ == 1; }

  std::string path() const {
    std::string p;
    for (const Frame& f : stack_) {
      if (f.map) {
        if (f.expect_key) break;  // at a key: the path of its mapping
        p += (p.empty() ? "" : ".") + f.key;
      } else {
        p += "[" + std::to_string(f.index) + "]";
      }
    }
    return p.empty() ? "<top level>" : p;
  }

  [[noreturn]] void fail(const YAML::Mark& m, const std::string& value, const std::string& rule) const {
    throw ConfigError(what_ + ", line " + std::to_string(m.line + 1) + ": " + path() + " = " + value + ": " + rule);
  }

  void check_tag(const YAML::Mark& m, const std::string& tag, const std::string& value) const {
    if (tag.empty() || tag == "?" || tag == "!") return;
    fail(m, value, "has the YAML tag '" + tag + "': tags are not used in a config (remove it)");
  }

  void add(const YAML::Mark& m, const std::string& value, double nodes, std::size_t height) {
    total_ += nodes;
    if (total_ > kMaxConfigNodes)
      fail(m, value,
           "with its aliases expanded the config has more than " + fmt(kMaxConfigNodes) +
               " values (the limit of a config): "
           "write the values out or use fewer nested aliases");
    if (stack_.size() + height > kMaxConfigDepth)
      fail(m, value, "nests more than " + std::to_string(kMaxConfigDepth) +
                         " levels deep (with its aliases expanded; the limit of a config)");
    if (!stack_.empty()) stack_.back().height = std::max(stack_.back().height, height + 1);
  }

  // After a node that is a mapping's key or value, or a sequence's element.
  void end_value() {
    if (stack_.empty()) return;
    Frame& f = stack_.back();
    if (f.map) f.expect_key = !f.expect_key;
    else ++f.index;
  }

  void remember(YAML::anchor_t anchor, Extent e) {
    if (anchor == YAML::NullAnchor) return;
    anchors_[anchor] = e;
    if (!anchor_name_.empty()) names_[anchor] = anchor_name_;
    anchor_name_.clear();
  }

  void leaf(const YAML::Mark& m, const std::string& tag, YAML::anchor_t anchor, const std::string& value) {
    if (!active()) return;
    if (!stack_.empty() && stack_.back().map && stack_.back().expect_key) stack_.back().key = value;
    check_tag(m, tag, value);
    add(m, value, 1, 0);
    remember(anchor, {1, 0});
    end_value();
  }

  void open(const YAML::Mark& m, const std::string& tag, YAML::anchor_t anchor, bool map) {
    if (!active()) return;
    if (!stack_.empty() && stack_.back().map && stack_.back().expect_key) stack_.back().key = "<key>";
    check_tag(m, tag, map ? "{...}" : "[...]");
    add(m, map ? "{...}" : "[...]", 1, 0);
    if (anchor != YAML::NullAnchor && !anchor_name_.empty()) {
      names_[anchor] = anchor_name_;
      anchor_name_.clear();
    }
    Frame f;
    f.anchor = anchor;
    f.map = map;
    f.nodes_at_start = total_ - 1;
    stack_.push_back(f);
  }

  void close() {
    if (!active() || stack_.empty()) return;
    const Frame f = stack_.back();
    stack_.pop_back();
    if (!stack_.empty()) stack_.back().height = std::max(stack_.back().height, f.height + 1);
    remember(f.anchor, {total_ - f.nodes_at_start, f.height});
    end_value();
  }

  std::string what_;
  int documents_ = 0;
  double total_ = 0;
  std::vector<Frame> stack_;
  std::map<YAML::anchor_t, Extent> anchors_;
  std::map<YAML::anchor_t, std::string> names_;
  std::string anchor_name_;
};

// YAML 1.2 counts a lone CR as a line break; yaml-cpp does not (a file saved with CR-only line
// endings would read as one line, or as empty). Lone CRs become LF; CRLF stays.
std::string normalise_line_breaks(const std::string& text) {
  if (text.find('\r') == std::string::npos) return text;
  std::string out = text;
  for (std::size_t i = 0; i < out.size(); ++i)
    if (out[i] == '\r' && (i + 1 == out.size() || out[i + 1] != '\n')) out[i] = '\n';
  return out;
}

// The first YAML document of `text`; a second one is an error. yaml-cpp's LoadAll is not used: on
// some malformed input (found by fuzz_config) its parser keeps reporting empty documents, and
// LoadAll collects them until memory runs out. Asking the parser for two documents at most cannot
// loop. The first pass also checks the document's shape (ConfigShape) before it is built.
YAML::Node single_document(const std::string& raw, const std::string& what) {
  const std::string text = normalise_line_breaks(raw);
  std::istringstream count_in(text);
  YAML::Parser parser(count_in);
  ConfigShape shape(what);
  if (parser.HandleNextDocument(shape) && parser.HandleNextDocument(shape))
    throw ConfigError(what + " holds more than one YAML document (a line '---' starts a new one): a config "
                             "is one document");
  return YAML::Load(text);
}

}  // namespace

YamlReader YamlReader::load_file(const std::string& file) {
  // a name with a NUL (possible from Python) would be cut there by every system call
  if (file.find('\0') != std::string::npos)
    throw ConfigError("config file name '" + file.substr(0, file.find('\0')) +
                      "<NUL>...' contains a NUL character: not a file name");
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw ConfigError("config file '" + file + "' is a directory, not a YAML file");
  // A FIFO, socket or device would block the read or never end: a config is a regular file.
  struct stat st {};
  if (::stat(file.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw ConfigError("config file '" + file + "' is not a regular file (a FIFO, device or socket): give a YAML file");
  YAML::Node n;
  try {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw ConfigError("config file '" + file + "' cannot be opened (missing or unreadable)");
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw ConfigError("config file '" + file + "' cannot be read");
    n = single_document(text.str(), "config file '" + file + "'");
  } catch (const YAML::ParserException& e) {
    throw ConfigError("config file '" + file + "' is not valid YAML: line " + std::to_string(e.mark.line + 1) +
                      ", column " + std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  if (!n || n.IsNull()) throw ConfigError("config file '" + file + "' is empty");
  check_unique_keys(n, "", "config file '" + file + "': ");
  return YamlReader(n, "");
}

YamlReader YamlReader::load_string(const std::string& text, const std::string& name) {
  YAML::Node n;
  try {
    n = single_document(text, "config '" + name + "'");
  } catch (const YAML::ParserException& e) {
    throw ConfigError("config '" + name + "' is not valid YAML: line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (n) check_unique_keys(n, "", "");
  return YamlReader(n, "");
}

std::string YamlReader::key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

bool YamlReader::has(const std::string& key) const {
  if (!present()) return false;
  const YAML::Node n = node_[key];
  return static_cast<bool>(n);  // a null value is given too: reading it is an error (at)
}

YAML::Node YamlReader::at(const std::string& key) {
  read_.insert(key);
  // An absent or null key gives an undefined node (operator! is true for it); a default-
  // constructed YAML::Node would be a *defined* null.
  if (!present()) return YAML::Node(YAML::NodeType::Undefined);
  const YAML::Node& cnode = node_;  // const access: the non-const operator[] would insert the key
  YAML::Node n = cnode[key];
  if (!n) return YAML::Node(YAML::NodeType::Undefined);
  // `key: ~`, `key: null` or `key:` with nothing: not a value, and not the default either (that
  // would take the default without a word)
  if (n.IsNull()) throw ConfigError(key_path(key), "~", kNullRule);
  return n;
}

double YamlReader::scalar_as_double(const YAML::Node& n, const std::string& path, const Rule& rule) {
  if (!n.IsScalar()) throw ConfigError(path, yaml_value_text(n), "must be a number");
  const std::string& s = n.Scalar();
  // strtod, not stod: stod rejects subnormal values (5e-324) as out of range, so a number that
  // was written could not be read back. An overflow (1e400) is still not a number.
  const char* begin = s.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  const bool overflow = errno == ERANGE && std::isinf(v);
  while (end && *end != '\0' && std::isspace(static_cast<unsigned char>(*end))) ++end;
  if (end == begin || end == nullptr || *end != '\0' || overflow || s.find('\0') != std::string::npos)
    throw ConfigError(path, s, "must be a number");
  const std::string broken = rule.check ? rule.check(v) : std::string();
  if (!broken.empty()) throw ConfigError(path, s, broken);
  return v;
}

double YamlReader::get_double(const std::string& key, const Rule& rule) {
  YAML::Node n = at(key);
  if (!n) throw ConfigError(key_path(key), "<missing>", "is required");
  return scalar_as_double(n, key_path(key), rule);
}

double YamlReader::get_double_or(const std::string& key, double fallback, const Rule& rule) {
  YAML::Node n = at(key);
  if (!n) return fallback;
  return scalar_as_double(n, key_path(key), rule);
}

long YamlReader::get_int(const std::string& key, const Rule& rule) {
  YAML::Node n = at(key);
  if (!n) throw ConfigError(key_path(key), "<missing>", "is required");
  double v = scalar_as_double(n, key_path(key), rule);
  if (v != std::floor(v) || std::fabs(v) > 9e15) throw ConfigError(key_path(key), n.Scalar(), "must be a whole number");
  return static_cast<long>(v);
}

long YamlReader::get_int_or(const std::string& key, long fallback, const Rule& rule) {
  if (!has(key)) {
    read_.insert(key);
    return fallback;
  }
  return get_int(key, rule);
}

bool YamlReader::get_bool_or(const std::string& key, bool fallback) {
  YAML::Node n = at(key);
  if (!n) return fallback;
  const std::string s = n.IsScalar() ? n.Scalar() : std::string();
  if (s == "true" || s == "yes" || s == "on") return true;
  if (s == "false" || s == "no" || s == "off") return false;
  throw ConfigError(key_path(key), yaml_value_text(n), "must be true or false");
}

std::string YamlReader::get_string(const std::string& key) {
  YAML::Node n = at(key);
  if (!n) throw ConfigError(key_path(key), "<missing>", "is required");
  if (!n.IsScalar()) throw ConfigError(key_path(key), yaml_value_text(n), "must be a string");
  return n.Scalar();
}

std::string YamlReader::get_string_or(const std::string& key, const std::string& fallback) {
  if (!has(key)) {
    read_.insert(key);
    return fallback;
  }
  return get_string(key);
}

std::string YamlReader::get_choice_or(const std::string& key, const std::string& fallback,
                                      const std::vector<std::string>& choices) {
  std::string v = get_string_or(key, fallback);
  for (const auto& c : choices)
    if (c == v) return v;
  std::string list;
  for (size_t i = 0; i < choices.size(); ++i) list += (i ? ", " : "") + choices[i];
  throw ConfigError(key_path(key), v, "must be one of: " + list);
}

std::vector<double> YamlReader::get_double_list(const std::string& key, const Rule& rule) {
  YAML::Node n = at(key);
  if (!n) throw ConfigError(key_path(key), "<missing>", "is required");
  std::vector<double> out;
  if (n.IsScalar()) {
    out.push_back(scalar_as_double(n, key_path(key), rule));
    return out;
  }
  if (!n.IsSequence()) throw ConfigError(key_path(key), yaml_value_text(n), "must be a number or a list of numbers");
  for (size_t i = 0; i < n.size(); ++i)
    out.push_back(scalar_as_double(n[i], key_path(key) + "[" + std::to_string(i) + "]", rule));
  return out;
}

std::vector<std::string> YamlReader::get_string_list_or(const std::string& key, const std::vector<std::string>& fallback) {
  YAML::Node n = at(key);
  if (!n) return fallback;
  std::vector<std::string> out;
  if (n.IsScalar()) {
    out.push_back(n.Scalar());
    return out;
  }
  if (!n.IsSequence()) throw ConfigError(key_path(key), yaml_value_text(n), "must be a string or a list of strings");
  for (size_t i = 0; i < n.size(); ++i) {
    if (!n[i].IsScalar())
      throw ConfigError(key_path(key) + "[" + std::to_string(i) + "]", yaml_value_text(n[i]), "must be a string");
    out.push_back(n[i].Scalar());
  }
  return out;
}

YAML::Node merge_yaml(const YAML::Node& base, const YAML::Node& overlay) {
  if (!overlay || overlay.IsNull()) return YAML::Clone(base);
  if (!base || !base.IsMap() || !overlay.IsMap()) return YAML::Clone(overlay);
  YAML::Node out = YAML::Clone(base);
  for (auto it = overlay.begin(); it != overlay.end(); ++it) {
    const std::string key = it->first.Scalar();
    const YAML::Node& cout_ = out;  // const lookup: does not insert
    const YAML::Node existing = cout_[key];
    if (existing && existing.IsMap() && it->second.IsMap())
      out[key] = merge_yaml(existing, it->second);
    else
      out[key] = YAML::Clone(it->second);
  }
  return out;
}

YamlReader YamlReader::child(const std::string& key) { return YamlReader(at(key), key_path(key)); }

bool YamlReader::is_sequence(const std::string& key) const { return has(key) && static_cast<const YAML::Node&>(node_)[key].IsSequence(); }

std::vector<YamlReader> YamlReader::children(const std::string& key) {
  YAML::Node n = at(key);
  std::vector<YamlReader> out;
  if (!n) return out;
  if (!n.IsSequence()) throw ConfigError(key_path(key), yaml_value_text(n), "must be a list");
  for (size_t i = 0; i < n.size(); ++i) {
    if (n[i].IsNull()) throw ConfigError(key_path(key) + "[" + std::to_string(i) + "]", "~", kNullRule);
    out.emplace_back(n[i], key_path(key) + "[" + std::to_string(i) + "]");
  }
  return out;
}

void YamlReader::finish() const {
  if (!present()) return;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    // A key that is not a scalar ({[a, b]: 1}) is never a known key; as<std::string>() would throw
    // YAML's own exception (an internal error instead of a config error).
    const std::string k = it->first.IsScalar() ? it->first.Scalar() : yaml_value_text(it->first);
    if (!read_.count(k)) {
      // Every key asked for here (present or not) is a known key: the nearest one is the hint.
      const std::vector<std::string> known(read_.begin(), read_.end());
      throw ConfigError(key_path(k), yaml_value_brief(it->second),
                        "unknown key (misspelt, or not valid here)" + did_you_mean(k, known));
    }
  }
}

}  // namespace abuopt
