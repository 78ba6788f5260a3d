#pragma once
// The top-level sections of an abuopt config file, and the one way to finish reading its top level.
//
// One config file often serves several commands: configs/montecarlo_final_profile.yaml carries
// abu, profile, motor, simulation and montecarlo, and `abuopt simulate`, `abuopt eqset` and
// `abuopt montecarlo` all read it. A reader that takes some of the sections must accept the others
// unread, and still refuse a misspelt section ("montecalro", with "did you mean"):
//
//   YamlReader root = YamlReader::load_file(path);
//   const SimulationSetup setup = read_simulation_setup(root);   // abu, profile, motor, simulation
//   finish_config(root);    // montecarlo, eqset, sweep, ... accepted unread; anything else refused
//
// Sections a reader did read are checked by that reader as usual; a section it did not read is
// checked by the command that reads it. A new top-level section is added to config_sections().
#include <string>
#include <vector>

#include "abuopt/common/yaml_reader.hpp"

namespace abuopt {

// Every top-level section of a model config (the ones documented in docs/config.md), in a fixed order.
const std::vector<std::string>& config_sections();

// root.finish() with every section of config_sections() counted as read: an unknown top-level key
// is an error (with "did you mean"), a known section is not.
void finish_config(const YamlReader& root);

}  // namespace abuopt
