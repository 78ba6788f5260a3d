#pragma once
// Test helper: a FieldArchive that changes exactly one field of a described struct, the
// `target`-th leaf in visiting order (numbers x 1.01 or 0.001 at zero, whole numbers + 1, flags
// flipped, enums to the next name, text + "x", number lists by their last element, lists of
// sections one element longer, absent optionals set).
// It counts the leaves and says whether the changed one is part of the identity (its own flag and
// every enclosing section's), so a test can prove that EVERY described key reaches the identity
// text: a key added to a field list is covered without touching the test.
#include <string>
#include <vector>

#include "abuopt/common/config_fields.hpp"

namespace abuopt::test_support {

class PerturbArchive final : public FieldArchive {
 public:
  explicit PerturbArchive(std::size_t target) : target_(target) {}
  Mode mode() const override { return Mode::Write; }  // no reading-only or validation-only logic
  std::string path(const std::string& key) const override { return prefix_ + key; }
  std::string here() const override { return prefix_; }
  bool has(const std::string&) const override { return true; }

  std::size_t leaves() const { return count_; }
  bool changed() const { return changed_; }
  bool changed_identity() const { return changed_identity_; }
  const std::string& changed_path() const { return changed_path_; }

  void number(const char* key, double& v, const Rule&, const FieldOptions& o) override {
    if (hit(key, o)) v = v == 0 ? 1e-3 : v * 1.01;
  }
  void integer(const char* key, long& v, const Rule&, const FieldOptions& o) override {
    if (hit(key, o)) v += 1;
  }
  void flag(const char* key, bool& v, const FieldOptions& o) override {
    if (hit(key, o)) v = !v;
  }
  void text(const char* key, std::string& v, const FieldOptions& o) override {
    if (hit(key, o)) v += "x";
  }
  void choice(const char* key, std::size_t& index, const std::vector<std::string>& names,
              const FieldOptions& o) override {
    if (hit(key, o)) index = (index + 1) % names.size();
  }
  void number_list(const char* key, std::vector<double>& v, const Rule&, const FieldOptions& o) override {
    if (hit(key, o)) change_list(v);
  }
  void optional_number(const char* key, std::optional<double>& v, const Rule&, const FieldOptions& o) override {
    if (hit(key, o)) v = v ? *v * 1.01 : 1.0;
  }
  void optional_number_list(const char* key, std::optional<std::vector<double>>& v, const Rule&,
                            const FieldOptions& o) override {
    if (!hit(key, o)) return;
    if (v)
      change_list(*v);
    else
      v = std::vector<double>{0.01, 0.02};
  }
  void optional_integer(const char* key, std::optional<long>& v, const Rule&, const FieldOptions& o) override {
    if (hit(key, o)) v = v ? *v + 1 : 1;
  }
  void section(const char* key, const std::function<void()>& body, const FieldOptions& o) override {
    if (!o.enabled) return;
    const std::string saved = prefix_;
    const bool saved_identity = identity_;
    prefix_ += std::string(key) + ".";
    identity_ = identity_ && o.identity;
    body();
    prefix_ = saved;
    identity_ = saved_identity;
  }
  void list(const char* key, std::size_t size, const std::function<void(std::size_t)>& resize,
            const std::function<void(std::size_t)>& item, const FieldOptions& o) override {
    if (!o.enabled) return;
    if (hit(key, o)) {
      resize(size + 1);
      return;
    }
    const std::string saved = prefix_;
    const bool saved_identity = identity_;
    identity_ = identity_ && o.identity;
    for (std::size_t i = 0; i < size; ++i) {
      prefix_ = saved + key + "[" + std::to_string(i) + "].";
      item(i);
    }
    prefix_ = saved;
    identity_ = saved_identity;
  }
  void number_or_section(const char* key, bool& is_section, double& v, const Rule& rule,
                         const std::function<void()>& body, const FieldOptions& o) override {
    if (is_section)
      section(key, body, o);
    else
      number(key, v, rule, o);
  }

 private:
  // The last element changed (a pair [lo, hi] stays a pair); an empty list gets one element.
  static void change_list(std::vector<double>& v) {
    if (v.empty())
      v.push_back(0.03);
    else
      v.back() = v.back() == 0 ? 1e-3 : v.back() * 1.01;
  }
  bool hit(const char* key, const FieldOptions& o) {
    if (!o.enabled) return false;
    if (count_++ != target_) return false;
    changed_ = true;
    changed_identity_ = identity_ && o.identity;
    changed_path_ = prefix_ + key;
    return true;
  }
  std::size_t target_;
  std::size_t count_ = 0;
  bool changed_ = false;
  bool changed_identity_ = false;
  bool identity_ = true;
  std::string prefix_;
  std::string changed_path_;
};

}  // namespace abuopt::test_support
