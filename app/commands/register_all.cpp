// The one list of subcommands: main.cpp and the fuzz target (fuzz/fuzz_cli.cpp) both register
// through it, so a new command is fuzzed as soon as it exists.
#include "commands/commands.hpp"

namespace abuopt::app {

void register_all(CLI::App& app) {
  register_simulate(app);
  register_montecarlo(app);
  register_eqset(app);
  register_reproduce(app);
  register_compare(app);
  register_optimize(app);
  register_sweep(app);
  register_pareto(app);
  register_archive(app);
  register_study(app);
  // after every option is converted, before the command's callback runs
  app.parse_complete_callback([&app] { check_option_values(app); });
}

}  // namespace abuopt::app
