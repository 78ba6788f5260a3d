#pragma once
// One file per subcommand under app/commands/; each registers itself on the top-level CLI11 app.
// A command's callback stores its exit status with set_exit_code(); ConfigError thrown from a
// command is caught in main.cpp and printed as one line, exit status 2.
#include <CLI/CLI.hpp>

namespace abuopt::app {

void set_exit_code(int code);
int exit_code();

void register_simulate(CLI::App& app);
void register_montecarlo(CLI::App& app);
void register_eqset(CLI::App& app);
void register_reproduce(CLI::App& app);
void register_compare(CLI::App& app);
void register_optimize(CLI::App& app);
void register_sweep(CLI::App& app);
void register_pareto(CLI::App& app);
void register_archive(CLI::App& app);
void register_study(CLI::App& app);
// Every subcommand above, in the order of `abuopt --help` (commands/register_all.cpp).
void register_all(CLI::App& app);
// Every option value given (empty, non-finite, out of range): ConfigError naming the option
// (commands/option_values.cpp). register_all runs it after parsing, before the command.
void check_option_values(const CLI::App& app);

}  // namespace abuopt::app
