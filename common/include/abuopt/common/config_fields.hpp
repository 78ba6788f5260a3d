#pragma once
// One description of a config struct's fields, from which reading, writing, validation and the
// identity text are all derived (in the spirit of Drake's `Serialize(Archive*)` visitor): a field
// is listed once, so a new key cannot be read but forgotten by the writer or the archive identity.
//
// A struct is described by a free function found by argument-dependent lookup:
//
//   void describe_fields(FieldArchive& a, MotorModel& m) {
//     a.field("kind", m.kind, kMotorKindNames);
//     a.field("xi", m.xi, Rule::positive());
//     a.field("friction_feedback", m.friction_feedback);
//   }
//
// and used through four archives:
//   read_fields(reader, value)        strict: an unknown key is a ConfigError naming it; every value
//                                     is checked ("motor.xi = -1: must be > 0"); an absent key
//                                     keeps the value already in the struct (its default)
//   write_fields(value)               YAML text, numbers shortest round-trip (std::to_chars), so
//                                     read(write(x)) == x bit for bit
//   validate_fields(value, "motor")   the same rules on a struct built in code
//   identity_fields(value, "motor")   canonical "motor.xi: 0.5" lines of every field that decides
//                                     a result (fields marked not_identity() are left out)
// Cross-field rules (a ball smaller than its track, lo <= hi) stay in hand-written validate()
// functions that call validate_fields first.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "abuopt/common/yaml_reader.hpp"

namespace abuopt {

// Shortest text that reads back to the same double ("0.1", "1e-06", "10700"); "nan", "inf".
std::string format_shortest(double v);

// How a field takes part in the four jobs.
struct FieldOptions {
  bool required = false;   // reading: an absent key is an error
  bool identity = true;    // part of the identity text
  bool enabled = true;     // false: not valid in this context (reading it is an error; never written)
  std::string note;        // appended to "is required" / the disabled message, e.g. "(a list of ...)"
  bool in_yaml = true;     // false: a derived value that is part of the identity but never a key
  bool body_when_absent = false;  // sections, reading: run the body even when the section is absent
                                  // (its defaults depend on other sections)


  static FieldOptions required_key(std::string note = "") { return {true, true, true, std::move(note), true, false}; }
  static FieldOptions not_identity() { return {false, false, true, "", true, false}; }
  static FieldOptions derived_defaults() { return {false, true, true, "", true, true}; }
  // Valid only when `condition` holds; otherwise reading the key throws "<note>".
  static FieldOptions only_if(bool condition, std::string note) {
    return {false, true, condition, std::move(note), true, false};
  }
  // A value the struct holds beside its keys (e.g. a seed copied from another key): validated and
  // part of the identity, never read or written.
  static FieldOptions identity_only() { return {false, true, true, "", false, false}; }
  FieldOptions without_identity() const {
    FieldOptions c = *this;
    c.identity = false;
    return c;
  }
};

// Names of an enum's values as written in YAML, in a fixed order.
template <class E>
using EnumNames = std::vector<std::pair<E, std::string>>;

class FieldArchive {
 public:
  enum class Mode { Read, Write, Validate, Identity };
  virtual ~FieldArchive() = default;
  virtual Mode mode() const = 0;
  bool reading() const { return mode() == Mode::Read; }
  // Full key path of `key` in the current section ("simulation.rtol").
  virtual std::string path(const std::string& key) const = 0;
  // Full path of the current section ("abu", "abu.balls[1]"; "" at the top).
  virtual std::string here() const = 0;
  // Reading: whether the key is given (not null). Other modes: true.
  virtual bool has(const std::string& key) const = 0;
  // Reading: the reader of the current section (for the rare key that needs a special form).
  virtual YamlReader* reader() { return nullptr; }

  // ---- The primitive field kinds (each archive implements them) -------------------------
  virtual void number(const char* key, double& v, const Rule& rule, const FieldOptions& o) = 0;
  virtual void integer(const char* key, long& v, const Rule& rule, const FieldOptions& o) = 0;
  virtual void flag(const char* key, bool& v, const FieldOptions& o) = 0;
  virtual void text(const char* key, std::string& v, const FieldOptions& o) = 0;
  // An enum as the index of its name in `names`.
  virtual void choice(const char* key, std::size_t& index, const std::vector<std::string>& names,
                      const FieldOptions& o) = 0;
  // A number or a list of numbers (reading accepts a single number as a list of one).
  virtual void number_list(const char* key, std::vector<double>& v, const Rule& rule, const FieldOptions& o) = 0;
  // Absent: nullopt (never written). `set` says whether the value is given.
  virtual void optional_number(const char* key, std::optional<double>& v, const Rule& rule,
                               const FieldOptions& o) = 0;
  virtual void optional_number_list(const char* key, std::optional<std::vector<double>>& v, const Rule& rule,
                                    const FieldOptions& o) = 0;
  virtual void optional_integer(const char* key, std::optional<long>& v, const Rule& rule, const FieldOptions& o) = 0;
  // A sub-mapping whose fields `body` describes (an absent section keeps its values).
  virtual void section(const char* key, const std::function<void()>& body, const FieldOptions& o = {}) = 0;
  // A list of mappings: `resize(n)` is called when reading; `item(i)` describes element i.
  virtual void list(const char* key, std::size_t size, const std::function<void(std::size_t)>& resize,
                    const std::function<void(std::size_t)>& item, const FieldOptions& o) = 0;
  // Either a plain number (is_section = false) or a mapping described by `body` (is_section = true).
  virtual void number_or_section(const char* key, bool& is_section, double& number, const Rule& rule,
                                 const std::function<void()>& body, const FieldOptions& o = {}) = 0;

  // ---- Typed conveniences ----------------------------------------------------------------
  void field(const char* key, double& v, const Rule& rule = Rule::any(), const FieldOptions& o = {}) {
    number(key, v, rule, o);
  }
  void field(const char* key, bool& v, const FieldOptions& o = {}) { flag(key, v, o); }
  void field(const char* key, std::string& v, const FieldOptions& o = {}) { text(key, v, o); }
  void field(const char* key, std::vector<double>& v, const Rule& rule = Rule::any(), const FieldOptions& o = {}) {
    number_list(key, v, rule, o);
  }
  void field(const char* key, std::optional<double>& v, const Rule& rule = Rule::any(), const FieldOptions& o = {}) {
    optional_number(key, v, rule, o);
  }
  void field(const char* key, std::optional<std::vector<double>>& v, const Rule& rule = Rule::any(),
             const FieldOptions& o = {}) {
    optional_number_list(key, v, rule, o);
  }
  void field(const char* key, std::optional<long>& v, const Rule& rule = Rule::any(), const FieldOptions& o = {}) {
    optional_integer(key, v, rule, o);
  }
  // Whole numbers of any integer type (read as a whole number; the rule bounds it).
  template <class Int, std::enable_if_t<std::is_integral_v<Int> && !std::is_same_v<Int, bool>, int> = 0>
  void field(const char* key, Int& v, const Rule& rule = Rule::any(), const FieldOptions& o = {}) {
    long l = static_cast<long>(v);
    integer(key, l, rule, o);
    v = static_cast<Int>(l);
  }
  template <class E, std::enable_if_t<std::is_enum_v<E>, int> = 0>
  void field(const char* key, E& v, const EnumNames<E>& names, const FieldOptions& o = {}) {
    std::vector<std::string> texts;
    std::size_t index = names.size();
    for (std::size_t i = 0; i < names.size(); ++i) {
      texts.push_back(names[i].second);
      if (names[i].first == v) index = i;
    }
    choice(key, index, texts, o);
    if (index < names.size()) v = names[index].first;
  }
  // A nested struct described by its own describe_fields.
  template <class T>
  void nested(const char* key, T& v, const FieldOptions& o = {}) {
    section(key, [&] { describe_fields(*this, v); }, o);
  }
  // A list of structs, each described by describe_fields.
  template <class T>
  void items(const char* key, std::vector<T>& v, const FieldOptions& o = {}) {
    list(key, v.size(), [&](std::size_t n) { v.resize(n); }, [&](std::size_t i) { describe_fields(*this, v[i]); },
         o);
  }
};

// The enum's name in `names` ("?" if absent).
template <class E>
std::string enum_name(const EnumNames<E>& names, E v) {
  for (const auto& [e, s] : names)
    if (e == v) return s;
  return "?";
}

// ---- The archives ------------------------------------------------------------------------------

// Reads fields from a YamlReader. With finish_sections, every section opened is finished (unknown
// keys are errors); the reader handed in is finished by finish() (read_fields does it).
class YamlReadArchive final : public FieldArchive {
 public:
  explicit YamlReadArchive(YamlReader& top) : stack_{&top} {}
  Mode mode() const override { return Mode::Read; }
  std::string path(const std::string& key) const override { return stack_.back()->key_path(key); }
  std::string here() const override { return stack_.back()->path(); }
  bool has(const std::string& key) const override { return stack_.back()->has(key); }
  YamlReader* reader() override { return stack_.back(); }

  void number(const char* key, double& v, const Rule& rule, const FieldOptions& o) override;
  void integer(const char* key, long& v, const Rule& rule, const FieldOptions& o) override;
  void flag(const char* key, bool& v, const FieldOptions& o) override;
  void text(const char* key, std::string& v, const FieldOptions& o) override;
  void choice(const char* key, std::size_t& index, const std::vector<std::string>& names,
              const FieldOptions& o) override;
  void number_list(const char* key, std::vector<double>& v, const Rule& rule, const FieldOptions& o) override;
  void optional_number(const char* key, std::optional<double>& v, const Rule& rule, const FieldOptions& o) override;
  void optional_number_list(const char* key, std::optional<std::vector<double>>& v, const Rule& rule,
                            const FieldOptions& o) override;
  void optional_integer(const char* key, std::optional<long>& v, const Rule& rule, const FieldOptions& o) override;
  void section(const char* key, const std::function<void()>& body, const FieldOptions& o) override;
  void list(const char* key, std::size_t size, const std::function<void(std::size_t)>& resize,
            const std::function<void(std::size_t)>& item, const FieldOptions& o) override;
  void number_or_section(const char* key, bool& is_section, double& number, const Rule& rule,
                         const std::function<void()>& body, const FieldOptions& o) override;

 private:
  // False when the key is absent (after the required/disabled checks); marks it read.
  bool given(const char* key, const FieldOptions& o);
  std::vector<YamlReader*> stack_;
};

// Writes YAML (block mappings; list items and number lists in flow style).
class YamlWriteArchive final : public FieldArchive {
 public:
  YamlWriteArchive();
  ~YamlWriteArchive() override;
  Mode mode() const override { return Mode::Write; }
  std::string path(const std::string& key) const override { return key; }
  std::string here() const override { return ""; }
  bool has(const std::string&) const override { return true; }
  // The document so far (a mapping), ending in a newline.
  std::string str();

  void number(const char* key, double& v, const Rule& rule, const FieldOptions& o) override;
  void integer(const char* key, long& v, const Rule& rule, const FieldOptions& o) override;
  void flag(const char* key, bool& v, const FieldOptions& o) override;
  void text(const char* key, std::string& v, const FieldOptions& o) override;
  void choice(const char* key, std::size_t& index, const std::vector<std::string>& names,
              const FieldOptions& o) override;
  void number_list(const char* key, std::vector<double>& v, const Rule& rule, const FieldOptions& o) override;
  void optional_number(const char* key, std::optional<double>& v, const Rule& rule, const FieldOptions& o) override;
  void optional_number_list(const char* key, std::optional<std::vector<double>>& v, const Rule& rule,
                            const FieldOptions& o) override;
  void optional_integer(const char* key, std::optional<long>& v, const Rule& rule, const FieldOptions& o) override;
  void section(const char* key, const std::function<void()>& body, const FieldOptions& o) override;
  void list(const char* key, std::size_t size, const std::function<void(std::size_t)>& resize,
            const std::function<void(std::size_t)>& item, const FieldOptions& o) override;
  void number_or_section(const char* key, bool& is_section, double& number, const Rule& rule,
                         const std::function<void()>& body, const FieldOptions& o) override;

 private:
  struct Impl;
  Impl* impl_;
};

// Checks every value against its rule; throws ConfigError "<path> = <value>: <rule>".
class ValidateArchive final : public FieldArchive {
 public:
  explicit ValidateArchive(std::string root) : prefix_{std::move(root)} {}
  Mode mode() const override { return Mode::Validate; }
  std::string path(const std::string& key) const override;
  std::string here() const override { return prefix_.back(); }
  bool has(const std::string&) const override { return true; }

  void number(const char* key, double& v, const Rule& rule, const FieldOptions& o) override;
  void integer(const char* key, long& v, const Rule& rule, const FieldOptions& o) override;
  void flag(const char*, bool&, const FieldOptions&) override {}
  void text(const char*, std::string&, const FieldOptions&) override {}
  void choice(const char* key, std::size_t& index, const std::vector<std::string>& names,
              const FieldOptions& o) override;
  void number_list(const char* key, std::vector<double>& v, const Rule& rule, const FieldOptions& o) override;
  void optional_number(const char* key, std::optional<double>& v, const Rule& rule, const FieldOptions& o) override;
  void optional_number_list(const char* key, std::optional<std::vector<double>>& v, const Rule& rule,
                            const FieldOptions& o) override;
  void optional_integer(const char* key, std::optional<long>& v, const Rule& rule, const FieldOptions& o) override;
  void section(const char* key, const std::function<void()>& body, const FieldOptions& o) override;
  void list(const char* key, std::size_t size, const std::function<void(std::size_t)>& resize,
            const std::function<void(std::size_t)>& item, const FieldOptions& o) override;
  void number_or_section(const char* key, bool& is_section, double& number, const Rule& rule,
                         const std::function<void()>& body, const FieldOptions& o) override;

 private:
  std::vector<std::string> prefix_;
};

// Canonical text of every identity field, one "<path>: <value>" line each.
class IdentityArchive final : public FieldArchive {
 public:
  explicit IdentityArchive(std::string root) : prefix_{std::move(root)} {}
  Mode mode() const override { return Mode::Identity; }
  std::string path(const std::string& key) const override;
  std::string here() const override { return prefix_.back(); }
  bool has(const std::string&) const override { return true; }
  const std::string& str() const { return text_; }

  void number(const char* key, double& v, const Rule& rule, const FieldOptions& o) override;
  void integer(const char* key, long& v, const Rule& rule, const FieldOptions& o) override;
  void flag(const char* key, bool& v, const FieldOptions& o) override;
  void text(const char* key, std::string& v, const FieldOptions& o) override;
  void choice(const char* key, std::size_t& index, const std::vector<std::string>& names,
              const FieldOptions& o) override;
  void number_list(const char* key, std::vector<double>& v, const Rule& rule, const FieldOptions& o) override;
  void optional_number(const char* key, std::optional<double>& v, const Rule& rule, const FieldOptions& o) override;
  void optional_number_list(const char* key, std::optional<std::vector<double>>& v, const Rule& rule,
                            const FieldOptions& o) override;
  void optional_integer(const char* key, std::optional<long>& v, const Rule& rule, const FieldOptions& o) override;
  void section(const char* key, const std::function<void()>& body, const FieldOptions& o) override;
  void list(const char* key, std::size_t size, const std::function<void(std::size_t)>& resize,
            const std::function<void(std::size_t)>& item, const FieldOptions& o) override;
  void number_or_section(const char* key, bool& is_section, double& number, const Rule& rule,
                         const std::function<void()>& body, const FieldOptions& o) override;

 private:
  void line(const char* key, const std::string& value);
  std::vector<std::string> prefix_;
  std::string text_;
};

// ---- Whole-struct helpers (describe_fields found by argument-dependent lookup) ----------------

// Reads the fields of `value` from `r` (keys absent in r keep their values) and calls r.finish().
template <class T>
void read_fields(YamlReader& r, T& value) {
  YamlReadArchive a(r);
  describe_fields(a, value);
  r.finish();
}

// The fields of `value` as a YAML mapping (text ending in a newline).
template <class T>
std::string write_fields(const T& value) {
  T copy = value;
  YamlWriteArchive a;
  describe_fields(a, copy);
  return a.str();
}

// Throws ConfigError naming "<path>.<key>" for the first field that breaks its rule.
template <class T>
void validate_fields(const T& value, const std::string& path) {
  T copy = value;
  ValidateArchive a(path);
  describe_fields(a, copy);
}

// "<path>.<key>: <value>" lines of every identity field of `value`.
template <class T>
std::string identity_fields(const T& value, const std::string& path = "") {
  T copy = value;
  IdentityArchive a(path);
  describe_fields(a, copy);
  return a.str();
}

}  // namespace abuopt
