#pragma once
// Internal: bytes on the wire between ranks. Numbers travel as their bytes (all ranks run the same
// binary on the same kind of machine: a cluster of one architecture), so values arrive bit for bit.
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "abuopt/core/monte_carlo.hpp"

namespace abuopt::parallel::detail {

class Writer {
 public:
  template <class T, std::enable_if_t<std::is_arithmetic_v<T>, int> = 0>
  void put(T v) {
    append(&v, sizeof v);
  }
  void put(const std::string& s) {
    put<std::uint64_t>(s.size());
    append(s.data(), s.size());
  }
  void put(const std::vector<double>& v) {
    put<std::uint64_t>(v.size());
    for (double d : v) put(d);
  }
  std::vector<char>& bytes() { return bytes_; }

 private:
  void append(const void* data, std::size_t n) {
    if (n == 0) return;
    const std::size_t at = bytes_.size();
    bytes_.resize(at + n);
    std::memcpy(bytes_.data() + at, data, n);
  }
  std::vector<char> bytes_;
};

class Reader {
 public:
  Reader(const char* data, std::size_t size) : p_(data), end_(data + size) {}
  template <class T, std::enable_if_t<std::is_arithmetic_v<T>, int> = 0>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, p_, sizeof v);
    p_ += sizeof v;
    return v;
  }
  std::string get_string() {
    const auto n = get<std::uint64_t>();
    need(n);
    std::string s(p_, p_ + n);
    p_ += n;
    return s;
  }
  std::vector<double> get_doubles() {
    const auto n = get<std::uint64_t>();
    need(n * sizeof(double));
    std::vector<double> v(n);
    for (auto& d : v) d = get<double>();
    return v;
  }
  bool done() const { return p_ == end_; }

 private:
  void need(std::size_t n) const {
    if (static_cast<std::size_t>(end_ - p_) < n) throw std::runtime_error("a message between ranks is truncated");
  }
  const char* p_;
  const char* end_;
};

void put_outcome(Writer& w, const RunOutcome& o);
RunOutcome get_outcome(Reader& r);

// The inputs of one run (initial angles and uncertain parameters).
void put_inputs(Writer& w, const MonteCarloSample& s);
void get_inputs(Reader& r, std::vector<double>& beta0, RunOverrides& o);

// The setup as text another rank rebuilds it from (YAML, read(to_yaml(s)) == s), and the rebuild,
// checked: the rebuilt setup must write the same text (else a field does not travel, or the ranks
// run different builds).
std::string encode_setup(const SimulationSetup& s);
SimulationSetup decode_setup(const std::string& text);

}  // namespace abuopt::parallel::detail
