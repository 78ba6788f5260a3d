// Out-of-tree use of the installed abuopt library: one startup of the 2003 report's final profile
// (0 -> 25 Hz in 1 s, 25 -> 29.5 Hz in 10 s, 29.5 -> 100 Hz in 8 s, mu = 0.02) from given initial
// ball angles, the config read by the library's own reader, and its residual imbalance printed.
//   abuopt_consumer CONFIG [BETA1 BETA2]
#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/config_sections.hpp"
#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "abuopt/core/simulator.hpp"

int main(int argc, char** argv) {
  if (argc != 2 && argc != 4) {
    std::cerr << "usage: abuopt_consumer CONFIG [BETA1 BETA2]\n";
    return 2;
  }
  try {
    abuopt::YamlReader root = abuopt::YamlReader::load_file(argv[1]);
    const abuopt::SimulationSetup setup = abuopt::read_simulation_setup(root);
    abuopt::finish_config(root);  // the other sections (montecarlo, ...) are not used here
    std::vector<double> beta0 = {0.5, 2.0};
    if (argc == 4) beta0 = {std::atof(argv[2]), std::atof(argv[3])};
    const abuopt::Simulator sim(setup);
    const abuopt::RunOutcome o = sim.run(beta0, {});
    std::cout << "status " << abuopt::to_string(o.status) << "\n"
              << "residual imbalance |I_r| = " << o.residual_imbalance_kgm * 1e7 << "e-7 kg m, I_r,x = "
              << o.residual_imbalance_x_kgm * 1e7 << "e-7 kg m (without balls " << setup.abu.imbalance_kgm() * 1e7
              << "e-7 kg m)\n";
    return o.ok() ? 0 : 3;
  } catch (const abuopt::ConfigError& e) {
    std::cerr << "abuopt_consumer: " << e.what() << "\n";
    return 2;
  }
}
