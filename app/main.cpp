// abuopt: design optimisation of startup profiles for Automatic Balancing Units.
#include <exception>
#include <iostream>

#include "abuopt/common/config_error.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {
namespace {
int g_exit_code = 0;
}
void set_exit_code(int code) { g_exit_code = code; }
int exit_code() { return g_exit_code; }
}  // namespace abuopt::app

int main(int argc, char** argv) {
  CLI::App app{
      "abuopt: simulate an Automatic Balancing Unit (ABU) during startup, evaluate startup profiles\n"
      "by Monte Carlo over initial ball positions, and optimise them.\n"
      "Every study is a YAML config (see configs/ and docs/config.md)."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "abuopt 0.1.0");
  abuopt::app::register_simulate(app);
  abuopt::app::register_montecarlo(app);
  abuopt::app::register_eqset(app);
  abuopt::app::register_reproduce(app);
  abuopt::app::register_compare(app);
  abuopt::app::register_optimize(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  } catch (const abuopt::ConfigError& e) {
    std::cerr << "abuopt: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "abuopt: internal error: " << e.what() << "\n";
    return 1;
  }
  return abuopt::app::exit_code();
}
