#include "abuopt/core/simulation_config.hpp"

#include <algorithm>
#include <cmath>

namespace abuopt {

const EnumNames<MotorKind> kMotorKindNames = {{MotorKind::Ideal, "ideal"}, {MotorKind::PI, "pi"}};
const EnumNames<FrictionMethod> kFrictionMethodNames = {{FrictionMethod::EventDriven, "event_driven"},
                                                        {FrictionMethod::SwitchModel, "switch_model"}};
const EnumNames<BallContact> kBallContactNames = {{BallContact::None, "none"}, {BallContact::Hard, "hard"}};
const EnumNames<IntegratorBackend> kIntegratorNames = {{IntegratorBackend::Native, "native"},
                                                       {IntegratorBackend::ArkodeErk, "arkode_erk"}};
const EnumNames<StuckIntegrator> kStuckIntegratorNames = {{StuckIntegrator::RungeKutta, "rk"},
                                                          {StuckIntegrator::Exact, "exact"}};

namespace {

// Reads the shorthand for identical balls (ball_count, ball_mass_kg, ball_diameter_m) into p.balls.
void read_ball_shorthand(YamlReader& r, AbuParameters& p) {
  const bool has_list = r.has("balls");
  const bool has_count = r.has("ball_count") || r.has("ball_mass_kg") || r.has("ball_diameter_m");
  if (has_list && has_count)
    throw ConfigError(r.key_path("balls"), "<list>",
                      "give either a balls list or ball_count/ball_mass_kg/ball_diameter_m, not both");
  const long count = r.get_int_or("ball_count", 2, Rule::in_range(0, 64));
  Ball ball;
  ball.mass_kg = r.get_double_or("ball_mass_kg", ball.mass_kg, Rule::positive_at_most(AbuLimits::kMassKg));
  ball.diameter_m = r.get_double_or("ball_diameter_m", ball.diameter_m, Rule::positive_at_most(AbuLimits::kLengthM));
  if (has_count) p.balls.assign(static_cast<std::size_t>(count), ball);
}

// Every ball must fit on its track (a rule across fields).
void check_balls_fit(const AbuParameters& p, const std::string& path) {
  for (std::size_t i = 0; i < p.balls.size(); ++i) {
    if (p.balls[i].diameter_m >= p.ball_track_radius_m) {
      const std::string b = (path.empty() ? "" : path + ".") + "balls[" + std::to_string(i) + "]";
      throw ConfigError(b + ".diameter_m", format_shortest(p.balls[i].diameter_m),
                        "must be smaller than abu.ball_track_radius_m (" + format_shortest(p.ball_track_radius_m) +
                            ")");
    }
  }
  if (p.ball_contact == BallContact::Hard && p.balls.size() > 1) {
    // with contact the balls must also fit side by side: sum of the neighbour spacings < 2 pi
    double need = 0;
    for (std::size_t i = 0; i < p.balls.size(); ++i) {
      const double s = (p.balls[i].diameter_m + p.balls[(i + 1) % p.balls.size()].diameter_m) /
                       (4.0 * p.ball_track_radius_m);
      need += 2.0 * std::asin(std::min(1.0, s));
    }
    if (!(need < 2.0 * M_PI))
      throw ConfigError((path.empty() ? "" : path + ".") + "ball_contact", "hard",
                        "the " + std::to_string(p.balls.size()) +
                            " balls do not fit side by side on the track (they need " + format_shortest(need) +
                            " rad of the 2 pi)");
  }
}

// "must be >= 0 (0: twice the profile duration)"
Rule end_time_rule() {
  return {[](double v) {
    return (std::isfinite(v) && v >= 0) ? std::string() : std::string("must be >= 0 (0: twice the profile duration)");
  }};
}

}  // namespace

void describe_fields(FieldArchive& a, Ball& b) {
  a.field("mass_kg", b.mass_kg, Rule::positive_at_most(AbuLimits::kMassKg));
  a.field("diameter_m", b.diameter_m, Rule::positive_at_most(AbuLimits::kLengthM));
}

void describe_fields(FieldArchive& a, AbuParameters& p) {
  if (YamlReader* r = a.reader()) read_ball_shorthand(*r, p);
  a.field("table_mass_kg", p.table_mass_kg, Rule::positive_at_most(AbuLimits::kMassKg));
  a.field("damping_Ns_per_m", p.damping_Ns_per_m, Rule::non_negative_at_most(AbuLimits::kDampingNsPerM));
  a.field("stiffness_N_per_m", p.stiffness_N_per_m, Rule::positive_at_most(AbuLimits::kStiffnessNPerM));
  a.field("ball_track_radius_m", p.ball_track_radius_m, Rule::positive_at_most(AbuLimits::kLengthM));
  a.field("imbalance_mass_kg", p.imbalance_mass_kg, Rule::non_negative_at_most(AbuLimits::kMassKg));
  a.field("eccentricity_m", p.eccentricity_m, Rule::non_negative_at_most(AbuLimits::kLengthM));
  a.field("friction_mu", p.friction_mu, Rule::in_range(0.0, 0.999));
  a.field("ball_damping_Nms", p.ball_damping_Nms, Rule::non_negative_at_most(AbuLimits::kBallDampingNms));
  a.field("ball_contact", p.ball_contact, kBallContactNames);
  a.field("ball_restitution", p.ball_restitution, Rule::in_range(0.0, 1.0));
  a.items("balls", p.balls);
  if (a.mode() == FieldArchive::Mode::Read || a.mode() == FieldArchive::Mode::Validate) {
    if (p.balls.size() > 64)  // the same limit as ball_count: run time grows with the square of the count
      throw ConfigError((a.here().empty() ? "" : a.here() + ".") + "balls", std::to_string(p.balls.size()) + " balls",
                        "must hold at most 64 balls (as ball_count; the limit is in core/src/simulation_config.cpp)");
    check_balls_fit(p, a.here());
  }
}

void describe_fields(FieldArchive& a, InclinedSineSegment& s) {
  a.field("end_frequency_hz", s.end_frequency_hz, Rule::non_negative_at_most(kMaxFrequencyHz), FieldOptions::required_key());
  a.field("duration_s", s.duration_s, Rule::positive_at_most(kMaxSegmentDurationS), FieldOptions::required_key());
}

void describe_fields(FieldArchive& a, StartupProfile& p) {
  double f0 = p.start_frequency_hz();
  std::vector<InclinedSineSegment> segments = p.segments();
  a.field("start_frequency_hz", f0, Rule::non_negative_at_most(kMaxFrequencyHz));
  a.items("segments", segments, FieldOptions::required_key("(a list of {end_frequency_hz, duration_s})"));
  if (a.reading() && segments.empty()) throw ConfigError(a.path("segments"), "[]", "must have at least one segment");
  // A class, not a plain struct: rebuilt when the fields changed (by reading, or any other archive).
  bool changed = f0 != p.start_frequency_hz() || segments.size() != p.segments().size();
  for (std::size_t i = 0; i < segments.size() && !changed; ++i)
    changed = segments[i].end_frequency_hz != p.segments()[i].end_frequency_hz ||
              segments[i].duration_s != p.segments()[i].duration_s;
  if (a.reading() || changed) p = StartupProfile(std::move(segments), f0);
}

void describe_fields(FieldArchive& a, FeedForward& f) {
  a.field("enabled", f.enabled);
  a.field("interval_s", f.interval_s, Rule::positive_at_most(kMaxSegmentDurationS));
}

void describe_fields(FieldArchive& a, MotorModel& m) {
  a.field("kind", m.kind, kMotorKindNames);
  a.field("omega_m_rad_s", m.omega_m_rad_s, Rule::positive());
  a.field("xi", m.xi, Rule::positive());
  a.field("bearing_torque_Nm", m.bearing_torque_Nm, Rule::non_negative());
  a.field("inertia_kgm2", m.inertia_kgm2, Rule::positive());
  a.field("friction_feedback", m.friction_feedback);
  a.field("setpoint_mismatch", m.setpoint_mismatch);
  a.field("quantize_setpoint_1hz", m.quantize_setpoint_1hz);
  a.nested("feedforward", m.feedforward);
  if ((a.mode() == FieldArchive::Mode::Read || a.mode() == FieldArchive::Mode::Validate) && m.feedforward.enabled &&
      m.kind != MotorKind::PI)
    throw ConfigError((a.here().empty() ? "" : a.here() + ".") + "feedforward.enabled", "true",
                      "needs kind: pi (the ideal motor's speed is the profile already)");
}

void describe_fields(FieldArchive& a, SimulationOptions& o) {
  a.field("method", o.method, kFrictionMethodNames);
  a.field("integrator", o.backend, kIntegratorNames);
  a.field("erk_table", o.erk_table);
  // Below 1e-14 the tolerance is under the rounding of the state; above 0.1 it is no accuracy.
  a.field("rtol", o.rtol, Rule::in_range(1e-14, 0.1));
  a.field("atol", o.atol, Rule::positive());
  a.field("end_time_s", o.end_time_s, end_time_rule());
  a.field("switch_band", o.switch_band, Rule::positive());
  a.field("max_steps", o.max_steps, Rule::at_least(1));
  a.field("max_events", o.max_events, Rule::at_least(1));
  a.field("chatter_events", o.chatter_events, Rule::at_least(1));
  a.field("chatter_window_s", o.chatter_window_s, Rule::positive());
  a.field("closed_form_tail", o.closed_form_tail);
  a.field("stuck_integrator", o.stuck_integrator, kStuckIntegratorNames);
  a.field("trajectory_interval_s", o.trajectory_interval_s, Rule::non_negative());
}

void describe_fields(FieldArchive& a, SimulationSetup& s) {
  a.nested("abu", s.abu);
  a.nested("profile", s.profile);
  a.nested("motor", s.motor);
  a.nested("simulation", s.options);
}

AbuParameters read_abu_parameters(YamlReader r) {
  AbuParameters p;
  if (r.present()) read_fields(r, p);
  return p;
}

StartupProfile read_profile(YamlReader r) {
  if (!r.present()) return StartupProfile::report_final();
  StartupProfile p;
  read_fields(r, p);
  return p;
}

MotorModel read_motor(YamlReader r) {
  MotorModel m;
  read_fields(r, m);
  return m;
}

SimulationOptions read_simulation_options(YamlReader r) {
  SimulationOptions o;
  read_fields(r, o);
  return o;
}

SimulationSetup read_simulation_setup(YamlReader& root) {
  SimulationSetup s;
  YamlReadArchive a(root);
  describe_fields(a, s);
  return s;
}

void validate(const SimulationOptions& o, const std::string& path) { validate_fields(o, path); }
void validate(const MotorModel& m, const std::string& path) { validate_fields(m, path); }

std::string to_yaml(const SimulationSetup& s) { return write_fields(s); }

}  // namespace abuopt
