// The config sections of core (abu, balls, profile, motor, simulation, montecarlo with its
// uncertain parameters): read -> write -> read gives the same struct for every section, for every
// shipped config and for every single-field change; the Simulator and the reader share one rule
// per key.
#include "abuopt/core/simulation_config.hpp"

#include <filesystem>
#include <functional>

#include <gtest/gtest.h>

#include "../common/perturb_archive.hpp"
#include "abuopt/core/monte_carlo.hpp"

namespace {

using namespace abuopt;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no error>";
}

SimulationSetup setup_from(const std::string& yaml) {
  YamlReader root = YamlReader::load_string(yaml);
  SimulationSetup s = read_simulation_setup(root);
  root.finish();
  return s;
}

// Identity text equality is field-by-field equality: every field is in it, numbers in their
// shortest round-trip form (one text per double).
std::string fields_of(const SimulationSetup& s) { return identity_fields(s); }

// A setup where every field differs from its default.
SimulationSetup unusual_setup() {
  SimulationSetup s;
  s.abu.table_mass_kg = 0.1 + 0.2;
  s.abu.damping_Ns_per_m = 1.0 / 3.0;
  s.abu.stiffness_N_per_m = 12345.678;
  s.abu.ball_track_radius_m = 0.0125;
  s.abu.imbalance_mass_kg = 6.1e-4;
  s.abu.eccentricity_m = 3.3e-3;
  s.abu.friction_mu = 0.031;
  s.abu.ball_damping_Nms = 1e-9;
  s.abu.balls = {Ball{1.3e-4, 2.9e-3}, Ball{1.5e-4, 3.1e-3}, Ball{1.0 / 7000.0, 3e-3}};
  s.profile = StartupProfile({{24.5, 0.9}, {29.0 + 1.0 / 3.0, 9.75}, {90, 7}}, 1.5);
  s.motor.kind = MotorKind::PI;
  s.motor.omega_m_rad_s = 2.5;
  s.motor.xi = 0.7;
  s.motor.bearing_torque_Nm = 4e-4;
  s.motor.inertia_kgm2 = 3.1e-5;
  s.motor.friction_feedback = false;
  s.motor.setpoint_mismatch = true;
  s.motor.quantize_setpoint_1hz = true;
  // enabled stays false: true is refused with kind: ideal, which the perturbation test sets
  // (tests/core/feedforward_test.cpp reads it true)
  s.motor.feedforward.interval_s = 0.02;
  s.options.method = FrictionMethod::SwitchModel;
  s.options.backend = IntegratorBackend::ArkodeErk;
  s.options.erk_table = "ARKODE_VERNER_8_5_6";
  s.options.rtol = 3e-7;
  s.options.atol = 2e-10;
  s.options.end_time_s = 40;
  s.options.switch_band = 2e-4;
  s.options.max_steps = 123456;
  s.options.max_events = 54321;
  s.options.chatter_events = 150;
  s.options.chatter_window_s = 2e-3;
  s.options.closed_form_tail = false;
  s.options.trajectory_interval_s = 0.01;
  return s;
}

TEST(SimulationConfig, SetupRoundTripsBitForBit) {
  const SimulationSetup s = unusual_setup();
  const std::string yaml = to_yaml(s);
  const SimulationSetup back = setup_from(yaml);
  EXPECT_EQ(fields_of(back), fields_of(s)) << yaml;
  EXPECT_EQ(to_yaml(back), yaml);
  EXPECT_EQ(back.abu.table_mass_kg, 0.1 + 0.2);
  EXPECT_EQ(back.abu.balls[2].mass_kg, 1.0 / 7000.0);
  EXPECT_EQ(back.profile.segments()[1].end_frequency_hz, 29.0 + 1.0 / 3.0);
  EXPECT_EQ(back.profile.start_frequency_hz(), 1.5);
  EXPECT_EQ(back.options.erk_table, "ARKODE_VERNER_8_5_6");
  EXPECT_EQ(back.options.max_events, 54321);
  EXPECT_NE(yaml.find("table_mass_kg: 0.30000000000000004\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("rtol: 3e-07\n"), std::string::npos) << yaml;
}

TEST(SimulationConfig, DefaultSetupRoundTrips) {
  const SimulationSetup s;
  EXPECT_EQ(fields_of(setup_from(to_yaml(s))), fields_of(s));
  // Sections read alone give the same values as through the whole setup.
  const SimulationSetup u = unusual_setup();
  YamlReader root = YamlReader::load_string(to_yaml(u));
  EXPECT_EQ(identity_fields(read_abu_parameters(root.child("abu"))), identity_fields(u.abu));
  EXPECT_EQ(identity_fields(read_motor(root.child("motor"))), identity_fields(u.motor));
  EXPECT_EQ(identity_fields(read_simulation_options(root.child("simulation"))), identity_fields(u.options));
  StartupProfile p = read_profile(root.child("profile"));
  EXPECT_EQ(identity_fields(p), identity_fields(u.profile));
}

TEST(SimulationConfig, EveryFieldChangeRoundTripsAndChangesTheText) {
  const SimulationSetup base = unusual_setup();
  const std::string base_fields = fields_of(base);
  std::size_t leaves = 0;
  for (std::size_t k = 0;; ++k) {
    SimulationSetup s = base;
    test_support::PerturbArchive a(k);
    describe_fields(a, s);
    leaves = a.leaves();
    if (!a.changed()) break;
    EXPECT_TRUE(a.changed_identity()) << a.changed_path();
    EXPECT_NE(fields_of(s), base_fields) << a.changed_path();
    const std::string yaml = to_yaml(s);
    EXPECT_EQ(fields_of(setup_from(yaml)), fields_of(s)) << a.changed_path() << "\n" << yaml;
  }
  // At least: 8 abu numbers + balls list + 3 x 2 ball fields, start frequency + segments list +
  // 3 x 2, 8 motor keys, 13 simulation keys (a key added later is covered without a change here).
  EXPECT_GE(leaves, 8u + 1 + 6 + 1 + 1 + 6 + 8 + 13);
}

TEST(SimulationConfig, ShippedConfigsRoundTrip) {
  namespace fs = std::filesystem;
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(ABUOPT_SOURCE_DIR) / "configs")) {
    if (e.path().extension() != ".yaml") continue;
    YamlReader root = YamlReader::load_file(e.path().string());
    if (root.has("table") || root.has("problems")) continue;  // a reproduction table or a comparison
    SimulationSetup s;
    try {
      s = read_simulation_setup(root);
    } catch (const ConfigError& err) {
      ADD_FAILURE() << e.path() << ": " << err.what();
      continue;
    }
    EXPECT_EQ(fields_of(setup_from(to_yaml(s))), fields_of(s)) << e.path();
    ++n;
  }
  EXPECT_GE(n, 5);
}

TEST(SimulationConfig, ReaderAndSimulatorShareOneRulePerKey) {
  // rtol was (0, 1) in the Simulator and [1e-14, 0.1] in the reader; now one rule.
  EXPECT_EQ(error_of([] { setup_from("simulation: {rtol: 0.5}"); }), "simulation.rtol = 0.5: must be in [1e-14, 0.1]");
  auto simulator_error = [](const std::function<void(SimulationSetup&)>& change) {
    SimulationSetup s;
    change(s);
    return error_of([&] { Simulator sim(s); });
  };
  EXPECT_EQ(simulator_error([](SimulationSetup& s) { s.options.rtol = 0.5; }),
            "simulation.rtol = 0.5: must be in [1e-14, 0.1]");
  EXPECT_EQ(simulator_error([](SimulationSetup& s) { s.options.max_steps = 0; }),
            "simulation.max_steps = 0: must be >= 1");
  EXPECT_EQ(simulator_error([](SimulationSetup& s) { s.options.end_time_s = -1; }),
            "simulation.end_time_s = -1: must be >= 0 (0: twice the profile duration)");
  EXPECT_EQ(simulator_error([](SimulationSetup& s) { s.motor.xi = 0; }), "motor.xi = 0: must be > 0");
  EXPECT_EQ(simulator_error([](SimulationSetup& s) { s.abu.friction_mu = 1.0; }),
            "abu.friction_mu = 1: must be in [0, 0.999]");
  EXPECT_EQ(simulator_error([](SimulationSetup& s) { s.abu.balls[1].diameter_m = 0.02; }),
            "abu.balls[1].diameter_m = 0.02: must be smaller than abu.ball_track_radius_m (0.0115)");
}

TEST(SimulationConfig, ReadingErrorsNameKeyValueAndRule) {
  EXPECT_EQ(error_of([] { setup_from("simulation: {rtoll: 1e-6}"); }),
            "simulation.rtoll = 1e-6: unknown key (misspelt, or not valid here); did you mean 'rtol'?");
  EXPECT_EQ(error_of([] { setup_from("simulation: {integrator: rk4}"); }),
            "simulation.integrator = rk4: must be one of: native, arkode_erk");
  EXPECT_EQ(error_of([] { setup_from("profile: {segments: [{end_frequency_hz: 10, duration_s: -2}]}"); }),
            "profile.segments[0].duration_s = -2: must be > 0");
  EXPECT_EQ(error_of([] { setup_from("profile: {start_frequency_hz: 1}"); }),
            "profile.segments = <missing>: is required (a list of {end_frequency_hz, duration_s})");
  EXPECT_EQ(error_of([] { setup_from("profile: {segments: []}"); }), "profile.segments = []: must have at least one segment");
  EXPECT_EQ(error_of([] { setup_from("abu: {ball_count: 3, balls: [{mass_kg: 1e-4}]}"); }),
            "abu.balls = <list>: give either a balls list or ball_count/ball_mass_kg/ball_diameter_m, not both");
  EXPECT_EQ(error_of([] { setup_from("abu: {balls: [{mass_kg: 1e-4, size: 3}]}"); }),
            "abu.balls[0].size = 3: unknown key (misspelt, or not valid here)");
  EXPECT_EQ(error_of([] { setup_from("motor: {kind: pi, xi: -1}"); }), "motor.xi = -1: must be > 0");
  // The shorthand for identical balls is read, and written as a list.
  const SimulationSetup s = setup_from("abu: {ball_count: 3, ball_mass_kg: 2e-4}");
  ASSERT_EQ(s.abu.balls.size(), 3u);
  EXPECT_EQ(s.abu.balls[2].mass_kg, 2e-4);
  EXPECT_EQ(fields_of(setup_from(to_yaml(s))), fields_of(s));
}

// ---- The montecarlo section (design, runs, seeds, uncertain parameters) ----------------------

MonteCarloConfig mc_from(const std::string& yaml) {
  YamlReader root = YamlReader::load_string(yaml);
  SimulationSetup setup = read_simulation_setup(root);
  MonteCarloConfig c = read_monte_carlo_config(root, setup);
  root.finish();
  return c;
}

std::string indent(const std::string& text) {
  std::string out = "  ";
  for (char ch : text) {
    out += ch;
    if (ch == '\n') out += "  ";
  }
  return out;
}

TEST(MonteCarloConfig, RoundTripsEverySamplingForm) {
  for (const std::string text : {
           "{}",
           "{design: random, runs: 100, seed: 12, threads: 3, shift: false, reuse_exchangeable: false}",
           "{design: sobol, runs: 64, friction: {fixed: 0.025}, imbalance: {angle: uniform}}",
           "{design: lhs, runs: 10, friction: {list: [0.02, 0.03]}, imbalance: {mass_relative_range: [-0.1, 0.2]}}",
           "{design: halton, runs: 8, friction: {range: [0.01, 0.04]}, imbalance: {angle_rad: 0.3}}",
           "{design: grid, grid: 5}",
       }) {
    const MonteCarloConfig c = mc_from("montecarlo: " + text + "\n");
    const std::string yaml = "montecarlo:\n" + indent(write_fields(c));
    const MonteCarloConfig back = mc_from(yaml);
    EXPECT_EQ(identity_fields(back), identity_fields(c)) << text << "\n" << yaml;
    EXPECT_EQ(back.threads, c.threads) << text;
    EXPECT_EQ(write_fields(back), write_fields(c)) << text;
  }
  EXPECT_EQ(mc_from("montecarlo: {design: grid, grid: 5}\n").study.runs, 25u);  // derived default
}

TEST(MonteCarloConfig, EveryKeyButThreadsIsInTheIdentity) {
  const MonteCarloConfig base =
      mc_from("montecarlo: {design: lhs, runs: 10, seed: 3, friction: {range: [0.01, 0.04]},"
              " imbalance: {mass_relative_range: [-0.1, 0.1], angle_rad: 0.2}}\n");
  const std::string id = identity_fields(base);
  for (std::size_t k = 0;; ++k) {
    MonteCarloConfig c = base;
    test_support::PerturbArchive a(k);
    describe_fields(a, c);
    if (!a.changed()) break;
    if (a.changed_path() == "threads")
      EXPECT_FALSE(a.changed_identity());
    else
      EXPECT_TRUE(a.changed_identity()) << a.changed_path();
    EXPECT_EQ(identity_fields(c) != id, a.changed_identity()) << a.changed_path();
  }
  EXPECT_EQ(error_of([] { mc_from("montecarlo: {friction: {fixed: 0.02, list: [0.1]}}\n"); }),
            "montecarlo.friction = {fixed: 0.02, list: [0.1]}: must have exactly one of: fixed, list, range");
  EXPECT_EQ(error_of([] { mc_from("montecarlo: {friction: {range: [0.01, 0.02, 0.03]}}\n"); }),
            "montecarlo.friction.range = [0.01, 0.02, 0.03]: must be a list [lo, hi]");
  EXPECT_EQ(error_of([] { mc_from("montecarlo: {imbalance: {angle: uniform, angle_rad: 1}}\n"); }),
            "montecarlo.imbalance.angle_rad = 1: is only valid with angle: fixed (angle: uniform draws it)");
  EXPECT_EQ(error_of([] { mc_from("montecarlo: {design: random, runs: 0}\n"); }), "montecarlo.runs = 0: must be >= 1");
}

}  // namespace
