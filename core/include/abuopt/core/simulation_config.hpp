#pragma once
// Reading a SimulationSetup from YAML: sections `abu`, `profile`, `motor`, `simulation`.
// Every key is documented in docs/config.md. The caller owns the root reader: it may read its
// own sections (e.g. `montecarlo`) and must call root.finish() so unknown keys are reported.
#include <string>

#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/simulator.hpp"

namespace abuopt {

SimulationSetup read_simulation_setup(YamlReader& root);
AbuParameters read_abu_parameters(YamlReader abu);
StartupProfile read_profile(YamlReader profile);
MotorModel read_motor(YamlReader motor);
SimulationOptions read_simulation_options(YamlReader sim);

// Writes a setup back as YAML (e.g. the best profile of an optimisation as a ready-to-run config).
std::string to_yaml(const SimulationSetup& setup);

}  // namespace abuopt
