#include "abuopt/core/simulation_config.hpp"

#include <sstream>

#include <yaml-cpp/yaml.h>

namespace abuopt {

AbuParameters read_abu_parameters(YamlReader r) {
  AbuParameters p;
  if (!r.present()) return p;
  p.table_mass_kg = r.get_double_or("table_mass_kg", p.table_mass_kg, Rule::positive());
  p.damping_Ns_per_m = r.get_double_or("damping_Ns_per_m", p.damping_Ns_per_m, Rule::non_negative());
  p.stiffness_N_per_m = r.get_double_or("stiffness_N_per_m", p.stiffness_N_per_m, Rule::positive());
  p.ball_track_radius_m = r.get_double_or("ball_track_radius_m", p.ball_track_radius_m, Rule::positive());
  p.imbalance_mass_kg = r.get_double_or("imbalance_mass_kg", p.imbalance_mass_kg, Rule::non_negative());
  p.eccentricity_m = r.get_double_or("eccentricity_m", p.eccentricity_m, Rule::non_negative());
  p.friction_mu = r.get_double_or("friction_mu", p.friction_mu, Rule::in_range(0.0, 0.999));
  p.ball_damping_Nms = r.get_double_or("ball_damping_Nms", p.ball_damping_Nms, Rule::non_negative());
  p.ball_contact = r.get_choice_or("ball_contact", "none", {"none", "hard"}) == "hard" ? BallContact::Hard : BallContact::None;
  p.ball_restitution = r.get_double_or("ball_restitution", p.ball_restitution, Rule::in_range(0.0, 1.0));
  const bool has_list = r.has("balls");
  const bool has_count = r.has("ball_count") || r.has("ball_mass_kg") || r.has("ball_diameter_m");
  if (has_list && has_count)
    throw ConfigError(r.key_path("balls"), "<list>", "give either a balls list or ball_count/ball_mass_kg/ball_diameter_m, not both");
  if (has_list) {
    p.balls.clear();
    for (auto& b : r.children("balls")) {
      Ball ball;
      ball.mass_kg = b.get_double_or("mass_kg", ball.mass_kg, Rule::positive());
      ball.diameter_m = b.get_double_or("diameter_m", ball.diameter_m, Rule::positive());
      b.finish();
      p.balls.push_back(ball);
    }
  } else {
    const long count = r.get_int_or("ball_count", 2, Rule::in_range(0, 64));
    Ball ball;
    ball.mass_kg = r.get_double_or("ball_mass_kg", ball.mass_kg, Rule::positive());
    ball.diameter_m = r.get_double_or("ball_diameter_m", ball.diameter_m, Rule::positive());
    p.balls.assign(static_cast<std::size_t>(count), ball);
  }
  r.finish();
  validate(p, r.path().c_str());
  return p;
}

StartupProfile read_profile(YamlReader r) {
  if (!r.present()) return StartupProfile::report_final();
  const double f0 = r.get_double_or("start_frequency_hz", 0.0, Rule::non_negative());
  std::vector<InclinedSineSegment> segs;
  if (!r.has("segments")) throw ConfigError(r.key_path("segments"), "<missing>", "is required (a list of {end_frequency_hz, duration_s})");
  for (auto& s : r.children("segments")) {
    InclinedSineSegment seg;
    seg.end_frequency_hz = s.get_double("end_frequency_hz", Rule::non_negative());
    seg.duration_s = s.get_double("duration_s", Rule::positive());
    s.finish();
    segs.push_back(seg);
  }
  if (segs.empty()) throw ConfigError(r.key_path("segments"), "[]", "must have at least one segment");
  r.finish();
  StartupProfile p(segs, f0);
  validate(p, r.path().c_str());
  return p;
}

MotorModel read_motor(YamlReader r) {
  MotorModel m;
  if (!r.present()) return m;
  const std::string kind = r.get_choice_or("kind", "ideal", {"ideal", "pi"});
  m.kind = kind == "ideal" ? MotorKind::Ideal : MotorKind::PI;
  m.omega_m_rad_s = r.get_double_or("omega_m_rad_s", m.omega_m_rad_s, Rule::positive());
  m.xi = r.get_double_or("xi", m.xi, Rule::positive());
  m.bearing_torque_Nm = r.get_double_or("bearing_torque_Nm", m.bearing_torque_Nm, Rule::non_negative());
  m.inertia_kgm2 = r.get_double_or("inertia_kgm2", m.inertia_kgm2, Rule::positive());
  m.friction_feedback = r.get_bool_or("friction_feedback", m.friction_feedback);
  m.setpoint_mismatch = r.get_bool_or("setpoint_mismatch", m.setpoint_mismatch);
  m.quantize_setpoint_1hz = r.get_bool_or("quantize_setpoint_1hz", m.quantize_setpoint_1hz);
  r.finish();
  return m;
}

SimulationOptions read_simulation_options(YamlReader r) {
  SimulationOptions o;
  if (!r.present()) return o;
  const std::string method = r.get_choice_or("method", "event_driven", {"event_driven", "switch_model"});
  o.method = method == "event_driven" ? FrictionMethod::EventDriven : FrictionMethod::SwitchModel;
  const std::string backend = r.get_choice_or("integrator", "native", {"native", "arkode_erk"});
  o.backend = backend == "native" ? IntegratorBackend::Native : IntegratorBackend::ArkodeErk;
  o.erk_table = r.get_string_or("erk_table", o.erk_table);
  o.rtol = r.get_double_or("rtol", o.rtol, Rule::in_range(1e-14, 0.1));
  o.atol = r.get_double_or("atol", o.atol, Rule::positive());
  o.end_time_s = r.get_double_or("end_time_s", o.end_time_s, Rule::non_negative());
  o.switch_band = r.get_double_or("switch_band", o.switch_band, Rule::positive());
  o.max_steps = r.get_int_or("max_steps", o.max_steps, Rule::at_least(1));
  o.max_events = r.get_int_or("max_events", o.max_events, Rule::at_least(1));
  o.chatter_events = r.get_int_or("chatter_events", o.chatter_events, Rule::at_least(1));
  o.chatter_window_s = r.get_double_or("chatter_window_s", o.chatter_window_s, Rule::positive());
  o.closed_form_tail = r.get_bool_or("closed_form_tail", o.closed_form_tail);
  o.trajectory_interval_s = r.get_double_or("trajectory_interval_s", o.trajectory_interval_s, Rule::non_negative());
  r.finish();
  return o;
}

SimulationSetup read_simulation_setup(YamlReader& root) {
  SimulationSetup s;
  s.abu = read_abu_parameters(root.child("abu"));
  s.profile = read_profile(root.child("profile"));
  s.motor = read_motor(root.child("motor"));
  s.options = read_simulation_options(root.child("simulation"));
  return s;
}

std::string to_yaml(const SimulationSetup& s) {
  YAML::Emitter e;
  e.SetDoublePrecision(17);
  e << YAML::BeginMap;
  e << YAML::Key << "abu" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "table_mass_kg" << YAML::Value << s.abu.table_mass_kg;
  e << YAML::Key << "damping_Ns_per_m" << YAML::Value << s.abu.damping_Ns_per_m;
  e << YAML::Key << "stiffness_N_per_m" << YAML::Value << s.abu.stiffness_N_per_m;
  e << YAML::Key << "ball_track_radius_m" << YAML::Value << s.abu.ball_track_radius_m;
  e << YAML::Key << "imbalance_mass_kg" << YAML::Value << s.abu.imbalance_mass_kg;
  e << YAML::Key << "eccentricity_m" << YAML::Value << s.abu.eccentricity_m;
  e << YAML::Key << "friction_mu" << YAML::Value << s.abu.friction_mu;
  e << YAML::Key << "ball_damping_Nms" << YAML::Value << s.abu.ball_damping_Nms;
  if (s.abu.ball_contact != BallContact::None) {  // written when on: older configs (and archive identities) stay as they were
    e << YAML::Key << "ball_contact" << YAML::Value << to_string(s.abu.ball_contact);
    e << YAML::Key << "ball_restitution" << YAML::Value << s.abu.ball_restitution;
  }
  e << YAML::Key << "balls" << YAML::Value << YAML::BeginSeq;
  for (const auto& b : s.abu.balls)
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "mass_kg" << YAML::Value << b.mass_kg << YAML::Key
      << "diameter_m" << YAML::Value << b.diameter_m << YAML::EndMap;
  e << YAML::EndSeq << YAML::EndMap;
  e << YAML::Key << "profile" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "start_frequency_hz" << YAML::Value << s.profile.start_frequency_hz();
  e << YAML::Key << "segments" << YAML::Value << YAML::BeginSeq;
  for (const auto& g : s.profile.segments())
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "end_frequency_hz" << YAML::Value << g.end_frequency_hz
      << YAML::Key << "duration_s" << YAML::Value << g.duration_s << YAML::EndMap;
  e << YAML::EndSeq << YAML::EndMap;
  e << YAML::Key << "motor" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "kind" << YAML::Value << to_string(s.motor.kind);
  if (s.motor.kind == MotorKind::PI) {
    e << YAML::Key << "omega_m_rad_s" << YAML::Value << s.motor.omega_m_rad_s;
    e << YAML::Key << "xi" << YAML::Value << s.motor.xi;
    e << YAML::Key << "bearing_torque_Nm" << YAML::Value << s.motor.bearing_torque_Nm;
    e << YAML::Key << "inertia_kgm2" << YAML::Value << s.motor.inertia_kgm2;
    e << YAML::Key << "friction_feedback" << YAML::Value << s.motor.friction_feedback;
  }
  e << YAML::Key << "setpoint_mismatch" << YAML::Value << s.motor.setpoint_mismatch;
  e << YAML::Key << "quantize_setpoint_1hz" << YAML::Value << s.motor.quantize_setpoint_1hz;
  e << YAML::EndMap;
  e << YAML::Key << "simulation" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "method" << YAML::Value << to_string(s.options.method);
  e << YAML::Key << "integrator" << YAML::Value << to_string(s.options.backend);
  e << YAML::Key << "erk_table" << YAML::Value << s.options.erk_table;
  e << YAML::Key << "rtol" << YAML::Value << s.options.rtol;
  e << YAML::Key << "atol" << YAML::Value << s.options.atol;
  e << YAML::Key << "end_time_s" << YAML::Value << s.options.end_time_s;
  e << YAML::Key << "closed_form_tail" << YAML::Value << s.options.closed_form_tail;
  e << YAML::EndMap << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

}  // namespace abuopt
