#include "abuopt/common/config_fields.hpp"

#include <charconv>
#include <cmath>

#include <yaml-cpp/yaml.h>

namespace abuopt {

std::string format_shortest(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

namespace {

std::string join_choices(const std::vector<std::string>& names) {
  std::string list;
  for (std::size_t i = 0; i < names.size(); ++i) list += (i ? ", " : "") + names[i];
  return list;
}

std::string with_note(const std::string& rule, const std::string& note) {
  return note.empty() ? rule : rule + " " + note;
}

std::string list_text(const std::vector<double>& v) {
  std::string t = "[";
  for (std::size_t i = 0; i < v.size(); ++i) t += (i ? ", " : "") + format_shortest(v[i]);
  return t + "]";
}

std::string child_path(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

}  // namespace

// ---- Reading ---------------------------------------------------------------------------------

bool YamlReadArchive::given(const char* key, const FieldOptions& o) {
  if (!o.in_yaml) return false;  // not a key: never marked as read, so giving it is an unknown key
  YamlReader& r = *stack_.back();
  const bool present = r.has(key);
  r.mark_read(key);
  if (!o.enabled) {
    if (present) throw ConfigError(path(key), yaml_value_text(r.node()[key]), o.note);
    return false;
  }
  if (!present && o.required) throw ConfigError(path(key), "<missing>", with_note("is required", o.note));
  return present;
}

void YamlReadArchive::number(const char* key, double& v, const Rule& rule, const FieldOptions& o) {
  if (given(key, o)) v = stack_.back()->get_double(key, rule);
}

void YamlReadArchive::integer(const char* key, long& v, const Rule& rule, const FieldOptions& o) {
  if (given(key, o)) v = stack_.back()->get_int(key, rule);
}

void YamlReadArchive::flag(const char* key, bool& v, const FieldOptions& o) {
  if (given(key, o)) v = stack_.back()->get_bool_or(key, v);
}

void YamlReadArchive::text(const char* key, std::string& v, const FieldOptions& o) {
  if (given(key, o)) v = stack_.back()->get_string(key);
}

void YamlReadArchive::choice(const char* key, std::size_t& index, const std::vector<std::string>& names,
                             const FieldOptions& o) {
  if (!given(key, o)) return;
  const std::string v = stack_.back()->get_choice_or(key, names.front(), names);
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == v) index = i;
}

void YamlReadArchive::number_list(const char* key, std::vector<double>& v, const Rule& rule, const FieldOptions& o) {
  if (given(key, o)) v = stack_.back()->get_double_list(key, rule);
}

void YamlReadArchive::optional_number(const char* key, std::optional<double>& v, const Rule& rule,
                                      const FieldOptions& o) {
  if (given(key, o)) v = stack_.back()->get_double(key, rule);
}

void YamlReadArchive::optional_number_list(const char* key, std::optional<std::vector<double>>& v, const Rule& rule,
                                           const FieldOptions& o) {
  if (given(key, o)) v = stack_.back()->get_double_list(key, rule);
}

void YamlReadArchive::optional_integer(const char* key, std::optional<long>& v, const Rule& rule, const FieldOptions& o) {
  if (given(key, o)) v = stack_.back()->get_int(key, rule);
}

void YamlReadArchive::section(const char* key, const std::function<void()>& body, const FieldOptions& o) {
  if (!given(key, o) && !(o.body_when_absent && o.enabled && o.in_yaml)) return;
  YamlReader child = stack_.back()->child(key);  // empty (present() false) when absent
  stack_.push_back(&child);
  body();
  stack_.pop_back();
  child.finish();
}

void YamlReadArchive::list(const char* key, std::size_t, const std::function<void(std::size_t)>& resize,
                           const std::function<void(std::size_t)>& item, const FieldOptions& o) {
  if (!given(key, o)) return;
  std::vector<YamlReader> kids = stack_.back()->children(key);
  resize(kids.size());
  for (std::size_t i = 0; i < kids.size(); ++i) {
    stack_.push_back(&kids[i]);
    item(i);
    stack_.pop_back();
    kids[i].finish();
  }
}

void YamlReadArchive::number_or_section(const char* key, bool& is_section, double& number, const Rule& rule,
                                        const std::function<void()>& body, const FieldOptions& o) {
  if (!given(key, o)) return;
  if (static_cast<const YAML::Node&>(stack_.back()->node())[key].IsMap()) {
    is_section = true;
    section(key, body, o);
  } else {
    is_section = false;
    number = stack_.back()->get_double(key, rule);
  }
}

// ---- Writing ---------------------------------------------------------------------------------

struct YamlWriteArchive::Impl {
  YAML::Emitter e;
  void key(const char* k) { e << YAML::Key << k << YAML::Value; }
  void numbers(const std::vector<double>& v) {
    e << YAML::Flow << YAML::BeginSeq;
    for (double x : v) e << format_shortest(x);
    e << YAML::EndSeq;
  }
};

YamlWriteArchive::YamlWriteArchive() : impl_(new Impl) { impl_->e << YAML::BeginMap; }
YamlWriteArchive::~YamlWriteArchive() { delete impl_; }

std::string YamlWriteArchive::str() {
  impl_->e << YAML::EndMap;
  std::string s = impl_->e.c_str();
  if (s == "{}") s.clear();
  return s.empty() ? s : s + "\n";
}

void YamlWriteArchive::number(const char* key, double& v, const Rule&, const FieldOptions& o) {
  if (!o.enabled || !o.in_yaml) return;
  impl_->key(key);
  impl_->e << format_shortest(v);
}

void YamlWriteArchive::integer(const char* key, long& v, const Rule&, const FieldOptions& o) {
  if (!o.enabled || !o.in_yaml) return;
  impl_->key(key);
  impl_->e << v;
}

void YamlWriteArchive::flag(const char* key, bool& v, const FieldOptions& o) {
  if (!o.enabled || !o.in_yaml) return;
  impl_->key(key);
  impl_->e << (v ? "true" : "false");
}

void YamlWriteArchive::text(const char* key, std::string& v, const FieldOptions& o) {
  if (!o.enabled || !o.in_yaml) return;
  impl_->key(key);
  impl_->e << v;
}

void YamlWriteArchive::choice(const char* key, std::size_t& index, const std::vector<std::string>& names,
                              const FieldOptions& o) {
  if (!o.enabled || !o.in_yaml) return;
  impl_->key(key);
  impl_->e << (index < names.size() ? names[index] : std::string("?"));
}

void YamlWriteArchive::number_list(const char* key, std::vector<double>& v, const Rule&, const FieldOptions& o) {
  if (!o.enabled || !o.in_yaml) return;
  impl_->key(key);
  impl_->numbers(v);
}

void YamlWriteArchive::optional_number(const char* key, std::optional<double>& v, const Rule& rule,
                                       const FieldOptions& o) {
  if (v) number(key, *v, rule, o);
}

void YamlWriteArchive::optional_number_list(const char* key, std::optional<std::vector<double>>& v,
                                            const Rule& rule, const FieldOptions& o) {
  if (v) number_list(key, *v, rule, o);
}

void YamlWriteArchive::optional_integer(const char* key, std::optional<long>& v, const Rule& rule, const FieldOptions& o) {
  if (v) integer(key, *v, rule, o);
}

void YamlWriteArchive::section(const char* key, const std::function<void()>& body, const FieldOptions& o) {
  if (!o.enabled || !o.in_yaml) return;
  impl_->key(key);
  impl_->e << YAML::BeginMap;
  body();
  impl_->e << YAML::EndMap;
}

void YamlWriteArchive::list(const char* key, std::size_t size, const std::function<void(std::size_t)>&,
                            const std::function<void(std::size_t)>& item, const FieldOptions& o) {
  if (!o.enabled || !o.in_yaml) return;
  impl_->key(key);
  if (size == 0) impl_->e << YAML::Flow;
  impl_->e << YAML::BeginSeq;
  for (std::size_t i = 0; i < size; ++i) {
    impl_->e << YAML::Flow << YAML::BeginMap;
    item(i);
    impl_->e << YAML::EndMap;
  }
  impl_->e << YAML::EndSeq;
}

void YamlWriteArchive::number_or_section(const char* key, bool& is_section, double& number, const Rule& rule,
                                         const std::function<void()>& body, const FieldOptions& o) {
  if (is_section)
    section(key, body, o);
  else
    this->number(key, number, rule, o);
}

// ---- Validation ------------------------------------------------------------------------------

std::string ValidateArchive::path(const std::string& key) const { return child_path(prefix_.back(), key); }

void ValidateArchive::number(const char* key, double& v, const Rule& rule, const FieldOptions& o) {
  if (!o.enabled || !rule.check) return;
  const std::string broken = rule.check(v);
  if (!broken.empty()) throw ConfigError(path(key), format_shortest(v), broken);
}

void ValidateArchive::integer(const char* key, long& v, const Rule& rule, const FieldOptions& o) {
  if (!o.enabled || !rule.check) return;
  const std::string broken = rule.check(static_cast<double>(v));
  if (!broken.empty()) throw ConfigError(path(key), std::to_string(v), broken);
}

void ValidateArchive::choice(const char* key, std::size_t& index, const std::vector<std::string>& names,
                             const FieldOptions& o) {
  if (o.enabled && index >= names.size())
    throw ConfigError(path(key), "<not a known value>", "must be one of: " + join_choices(names));
}

void ValidateArchive::number_list(const char* key, std::vector<double>& v, const Rule& rule, const FieldOptions& o) {
  if (!o.enabled || !rule.check) return;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string broken = rule.check(v[i]);
    if (!broken.empty())
      throw ConfigError(path(key) + "[" + std::to_string(i) + "]", format_shortest(v[i]), broken);
  }
}

void ValidateArchive::optional_number(const char* key, std::optional<double>& v, const Rule& rule,
                                      const FieldOptions& o) {
  if (v) number(key, *v, rule, o);
}

void ValidateArchive::optional_number_list(const char* key, std::optional<std::vector<double>>& v, const Rule& rule,
                                           const FieldOptions& o) {
  if (v) number_list(key, *v, rule, o);
}

void ValidateArchive::optional_integer(const char* key, std::optional<long>& v, const Rule& rule, const FieldOptions& o) {
  if (v) integer(key, *v, rule, o);
}

void ValidateArchive::section(const char* key, const std::function<void()>& body, const FieldOptions& o) {
  if (!o.enabled) return;
  prefix_.push_back(path(key));
  body();
  prefix_.pop_back();
}

void ValidateArchive::list(const char* key, std::size_t size, const std::function<void(std::size_t)>&,
                           const std::function<void(std::size_t)>& item, const FieldOptions& o) {
  if (!o.enabled) return;
  const std::string base = path(key);
  for (std::size_t i = 0; i < size; ++i) {
    prefix_.push_back(base + "[" + std::to_string(i) + "]");
    item(i);
    prefix_.pop_back();
  }
}

void ValidateArchive::number_or_section(const char* key, bool& is_section, double& number, const Rule& rule,
                                        const std::function<void()>& body, const FieldOptions& o) {
  if (is_section)
    section(key, body, o);
  else
    this->number(key, number, rule, o);
}

// ---- Identity --------------------------------------------------------------------------------

std::string IdentityArchive::path(const std::string& key) const { return child_path(prefix_.back(), key); }

void IdentityArchive::line(const char* key, const std::string& value) {
  text_.append(path(key)).append(": ").append(value).append("\n");
}

void IdentityArchive::number(const char* key, double& v, const Rule&, const FieldOptions& o) {
  if (o.enabled && o.identity) line(key, format_shortest(v));
}

void IdentityArchive::integer(const char* key, long& v, const Rule&, const FieldOptions& o) {
  if (o.enabled && o.identity) line(key, std::to_string(v));
}

void IdentityArchive::flag(const char* key, bool& v, const FieldOptions& o) {
  if (o.enabled && o.identity) line(key, v ? "true" : "false");
}

void IdentityArchive::text(const char* key, std::string& v, const FieldOptions& o) {
  if (o.enabled && o.identity) line(key, v);
}

void IdentityArchive::choice(const char* key, std::size_t& index, const std::vector<std::string>& names,
                             const FieldOptions& o) {
  if (o.enabled && o.identity) line(key, index < names.size() ? names[index] : std::string("?"));
}

void IdentityArchive::number_list(const char* key, std::vector<double>& v, const Rule&, const FieldOptions& o) {
  if (o.enabled && o.identity) line(key, list_text(v));
}

void IdentityArchive::optional_number(const char* key, std::optional<double>& v, const Rule&,
                                      const FieldOptions& o) {
  if (o.enabled && o.identity) line(key, v ? format_shortest(*v) : std::string("none"));
}

void IdentityArchive::optional_number_list(const char* key, std::optional<std::vector<double>>& v, const Rule&,
                                           const FieldOptions& o) {
  if (o.enabled && o.identity) line(key, v ? list_text(*v) : std::string("none"));
}

void IdentityArchive::optional_integer(const char* key, std::optional<long>& v, const Rule&, const FieldOptions& o) {
  if (o.enabled && o.identity) line(key, v ? std::to_string(*v) : std::string("none"));
}

void IdentityArchive::section(const char* key, const std::function<void()>& body, const FieldOptions& o) {
  if (!o.enabled || !o.identity) return;
  prefix_.push_back(path(key));
  body();
  prefix_.pop_back();
}

void IdentityArchive::list(const char* key, std::size_t size, const std::function<void(std::size_t)>&,
                           const std::function<void(std::size_t)>& item, const FieldOptions& o) {
  if (!o.enabled || !o.identity) return;
  line(key, std::to_string(size) + " items");
  const std::string base = path(key);
  for (std::size_t i = 0; i < size; ++i) {
    prefix_.push_back(base + "[" + std::to_string(i) + "]");
    item(i);
    prefix_.pop_back();
  }
}

void IdentityArchive::number_or_section(const char* key, bool& is_section, double& number, const Rule& rule,
                                        const std::function<void()>& body, const FieldOptions& o) {
  if (!o.enabled || !o.identity) return;
  if (is_section) {
    line(key, "section");
    section(key, body, o);
  } else {
    this->number(key, number, rule, o);
  }
}

}  // namespace abuopt
