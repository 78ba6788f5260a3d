#include "codec.hpp"

#include <sstream>

#include "abuopt/common/config_fields.hpp"
#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/simulation_config.hpp"

namespace abuopt::parallel::detail {

// Every field of RunOutcome travels; a field added to it must be added here (and this size).
static_assert(sizeof(RunOutcome) == 160 || sizeof(void*) != 8,
              "RunOutcome changed: encode the new field in put_outcome/get_outcome and update this size");

void put_outcome(Writer& w, const RunOutcome& o) {
  w.put<std::int32_t>(static_cast<std::int32_t>(o.status));
  w.put(o.message);
  w.put(o.beta_final);
  w.put(o.residual_imbalance_kgm);
  w.put(o.residual_imbalance_x_kgm);
  w.put<std::uint8_t>(o.settled ? 1 : 0);
  w.put(o.settling_time_s);
  w.put(o.max_amplitude_mm);
  w.put(o.end_time_s);
  w.put<std::int64_t>(o.events);
  w.put<std::int64_t>(o.impacts);
  w.put(o.min_contact_clearance_rad);
  w.put<std::int64_t>(o.rhs_evaluations);
  w.put<std::int64_t>(o.steps);
  w.put(o.wall_time_s);
}

RunOutcome get_outcome(Reader& r) {
  RunOutcome o;
  o.status = static_cast<RunStatus>(r.get<std::int32_t>());
  o.message = r.get_string();
  o.beta_final = r.get_doubles();
  o.residual_imbalance_kgm = r.get<double>();
  o.residual_imbalance_x_kgm = r.get<double>();
  o.settled = r.get<std::uint8_t>() != 0;
  o.settling_time_s = r.get<double>();
  o.max_amplitude_mm = r.get<double>();
  o.end_time_s = r.get<double>();
  o.events = static_cast<long>(r.get<std::int64_t>());
  o.impacts = static_cast<long>(r.get<std::int64_t>());
  o.min_contact_clearance_rad = r.get<double>();
  o.rhs_evaluations = static_cast<long>(r.get<std::int64_t>());
  o.steps = static_cast<long>(r.get<std::int64_t>());
  o.wall_time_s = r.get<double>();
  return o;
}

namespace {
std::string indent(const std::string& text) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line)) out += "  " + line + "\n";
  return out;
}

std::uint64_t fnv(std::uint64_t h, const void* data, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ULL;
  }
  return h;
}
template <class T>
std::uint64_t fnv(std::uint64_t h, const T& v) {
  return fnv(h, &v, sizeof v);
}
}  // namespace

std::string encode_study(const MonteCarloStudy& s) {
  MonteCarloConfig c;
  c.study = s;
  c.threads = 0;
  // the design's own seed is not a key (it is read from `seed`): it travels on a line of its own
  return to_yaml(s.setup) + "montecarlo:\n" + indent(write_fields(c)) + "# design_seed " +
         std::to_string(s.design.seed) + "\n";
}

MonteCarloStudy decode_study(const std::string& text) {
  const auto at = text.rfind("# design_seed ");
  if (at == std::string::npos) throw std::runtime_error("a study sent between ranks has no design seed");
  YamlReader root = YamlReader::load_string(text, "<study from rank 0>");
  SimulationSetup setup = read_simulation_setup(root);
  MonteCarloConfig c = read_monte_carlo_config(root, std::move(setup));
  root.finish();
  c.study.design.seed = std::stoull(text.substr(at + 14));
  return c.study;
}

std::uint64_t fingerprint(const MonteCarloStudy& s, const PreparedStudy& p) {
  std::uint64_t h = 1469598103934665603ULL;
  const std::string text = encode_study(s);
  h = fnv(h, text.data(), text.size());
  for (const MonteCarloSample& smp : p.samples) {
    h = fnv(h, smp.index);
    h = fnv(h, smp.reused_from);
    for (double b : smp.beta0) h = fnv(h, b);
    h = fnv(h, smp.overrides.friction_mu.value_or(-1.0));
    h = fnv(h, smp.overrides.imbalance_mass_kg.value_or(-1.0));
    h = fnv(h, smp.overrides.imbalance_angle_rad);
    h = fnv(h, smp.friction_mu);
    h = fnv(h, smp.imbalance_kgm);
  }
  return h;
}

}  // namespace abuopt::parallel::detail
