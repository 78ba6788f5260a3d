#include "codec.hpp"


#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/simulation_config.hpp"

namespace abuopt::parallel::detail {

// Every field of RunOutcome travels; a field added to it must be added here (and this size).
static_assert(sizeof(RunOutcome) == 160 || sizeof(void*) != 8,
              "RunOutcome changed: encode the new field in put_outcome/get_outcome and update this size");

// Likewise for RunOverrides.
static_assert(sizeof(RunOverrides) == 72 || sizeof(void*) != 8,
              "RunOverrides changed: encode the new field in put_inputs/get_inputs and update this size");

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

void put_inputs(Writer& w, const MonteCarloSample& s) {
  w.put(s.beta0);
  w.put<std::uint8_t>(s.overrides.friction_mu ? 1 : 0);
  w.put(s.overrides.friction_mu.value_or(0.0));
  w.put<std::uint8_t>(s.overrides.imbalance_mass_kg ? 1 : 0);
  w.put(s.overrides.imbalance_mass_kg.value_or(0.0));
  w.put<std::uint8_t>(s.overrides.stiffness_N_per_m ? 1 : 0);
  w.put(s.overrides.stiffness_N_per_m.value_or(0.0));
  w.put<std::uint8_t>(s.overrides.ball_restitution ? 1 : 0);
  w.put(s.overrides.ball_restitution.value_or(0.0));
  w.put(s.overrides.imbalance_angle_rad);
}

void get_inputs(Reader& r, std::vector<double>& beta0, RunOverrides& o) {
  beta0 = r.get_doubles();
  o = RunOverrides{};
  const bool has_mu = r.get<std::uint8_t>() != 0;
  const double mu = r.get<double>();
  if (has_mu) o.friction_mu = mu;
  const bool has_mass = r.get<std::uint8_t>() != 0;
  const double mass = r.get<double>();
  if (has_mass) o.imbalance_mass_kg = mass;
  const bool has_k = r.get<std::uint8_t>() != 0;
  const double k = r.get<double>();
  if (has_k) o.stiffness_N_per_m = k;
  const bool has_e = r.get<std::uint8_t>() != 0;
  const double e = r.get<double>();
  if (has_e) o.ball_restitution = e;
  o.imbalance_angle_rad = r.get<double>();
}

std::string encode_setup(const SimulationSetup& s) { return to_yaml(s); }

SimulationSetup decode_setup(const std::string& text) {
  YamlReader root = YamlReader::load_string(text, "<setup from rank 0>");
  SimulationSetup s = read_simulation_setup(root);
  root.finish();
  if (to_yaml(s) != text)
    throw std::runtime_error("this rank rebuilt a different setup from rank 0's description (a field that does "
                             "not travel, or ranks running different builds)");
  return s;
}

}  // namespace abuopt::parallel::detail
