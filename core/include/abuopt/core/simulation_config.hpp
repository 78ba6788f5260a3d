#pragma once
// The config sections of one simulation: `abu`, `profile`, `motor`, `simulation`. Each struct's
// fields are described once (describe_fields, see common/config_fields.hpp); reading, writing
// (to_yaml), validation and the identity text all come from that description. Every key is
// documented in docs/config.md. The caller owns the root reader: it may read its own sections
// (e.g. `montecarlo`) and must call root.finish() so unknown keys are reported.
#include <string>

#include "abuopt/common/config_fields.hpp"
#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/simulator.hpp"

namespace abuopt {

extern const EnumNames<MotorKind> kMotorKindNames;             // ideal, pi
extern const EnumNames<FrictionMethod> kFrictionMethodNames;   // event_driven, switch_model
extern const EnumNames<IntegratorBackend> kIntegratorNames;
extern const EnumNames<StuckIntegrator> kStuckIntegratorNames;  // rk, exact
extern const EnumNames<BallContact> kBallContactNames;        // none, hard    // native, arkode_erk

// The field lists. `abu` also accepts the shorthand ball_count/ball_mass_kg/ball_diameter_m for
// identical balls (read only; written as a balls list). Reading a profile requires its segments.
void describe_fields(FieldArchive& a, Ball& b);
void describe_fields(FieldArchive& a, AbuParameters& p);
void describe_fields(FieldArchive& a, InclinedSineSegment& s);
void describe_fields(FieldArchive& a, StartupProfile& p);
void describe_fields(FieldArchive& a, FeedForward& f);
void describe_fields(FieldArchive& a, MotorModel& m);
void describe_fields(FieldArchive& a, SimulationOptions& o);
// The four sections abu, profile, motor, simulation.
void describe_fields(FieldArchive& a, SimulationSetup& s);

SimulationSetup read_simulation_setup(YamlReader& root);
AbuParameters read_abu_parameters(YamlReader abu);
StartupProfile read_profile(YamlReader profile);
MotorModel read_motor(YamlReader motor);
SimulationOptions read_simulation_options(YamlReader sim);

// Throws ConfigError ("simulation.rtol = 0.5: must be in [1e-14, 0.1]") for a value that breaks
// its rule: the reader's rules, for options built in code (the Simulator constructor uses it).
void validate(const SimulationOptions& o, const std::string& path = "simulation");
void validate(const MotorModel& m, const std::string& path = "motor");

// Writes a setup back as YAML, every key of the four sections, numbers shortest round-trip (e.g.
// the best profile of an optimisation as a ready-to-run config). read(to_yaml(s)) == s.
std::string to_yaml(const SimulationSetup& setup);

}  // namespace abuopt
