// libFuzzer target: every config reader on arbitrary text. A reader may only accept the text or
// throw ConfigError (any other exception or a crash is a finding), and what it accepts must
// survive write -> read unchanged (the field lists' round trip), else the target aborts.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/config_fields.hpp"
#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/optimizer/optimizer_options.hpp"
#include "abuopt/problems/startup_profile_problem.hpp"
#include "abuopt/studies/reproduction_table.hpp"

namespace {

using namespace abuopt;

[[noreturn]] void finding(const std::string& what, const std::string& a, const std::string& b) {
  std::fprintf(stderr, "fuzz_config: %s\n--- first\n%s\n--- second\n%s\n", what.c_str(), a.c_str(), b.c_str());
  std::abort();
}

std::string indent(const std::string& text) {
  std::string out;
  bool start = true;
  for (char c : text) {
    if (start) out += "  ";
    out += c;
    start = c == '\n';
  }
  return out;
}

template <class F>
void rejected_or(F&& f) {
  try {
    f();
  } catch (const ConfigError&) {
  }
}

// Reading what was written must give the same fields, and must not fail.
template <class Read>
auto reread(const std::string& written, Read&& read) {
  try {
    YamlReader r = YamlReader::load_string(written, "written");
    auto v = read(r);
    r.finish();
    return v;
  } catch (const ConfigError& e) {
    finding(std::string("written config does not read back: ") + e.what(), written, "");
  }
}

void check(const std::string& text) {
  rejected_or([&] {
    YamlReader root = YamlReader::load_string(text, "fuzz");
    const SimulationSetup s = read_simulation_setup(root);
    const std::string y = to_yaml(s);
    const SimulationSetup back = reread(y, [](YamlReader& r) { return read_simulation_setup(r); });
    if (identity_fields(back) != identity_fields(s)) finding("setup round trip", identity_fields(s), identity_fields(back));
    const MonteCarloConfig mc = read_monte_carlo_config(root, s);
    const std::string my = y + "montecarlo:\n" + indent(write_fields(mc));
    const MonteCarloConfig mback = reread(my, [](YamlReader& r) {
      SimulationSetup setup = read_simulation_setup(r);
      return read_monte_carlo_config(r, setup);
    });
    if (identity_fields(mback) != identity_fields(mc) || mback.threads != mc.threads)
      finding("montecarlo round trip", write_fields(mc), write_fields(mback));
  });
  rejected_or([&] {
    YamlReader root = YamlReader::load_string(text, "fuzz");
    const problems::StartupProfileSettings s = problems::read_startup_profile_settings(root);
    const std::string y = write_fields(s);
    const problems::StartupProfileSettings back =
        reread(y, [](YamlReader& r) { return problems::read_startup_profile_settings(r); });
    if (write_fields(back) != y) finding("startup profile settings round trip", y, write_fields(back));
  });
  rejected_or([&] {
    YamlReader root = YamlReader::load_string(text, "fuzz");
    YamlReader opt = root.child("optimizer");
    YamlReader sao = root.child("sao");
    (void)opt::read_optimizer_options(opt, &sao);
  });
  rejected_or([&] { (void)read_reproduction_table_string(text, "fuzz"); });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 64 * 1024) return 0;
  check(std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}
