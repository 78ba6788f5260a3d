// abuopt: design optimisation of startup profiles for Automatic Balancing Units.
#include <algorithm>
#include <csignal>
#include <exception>
#include <filesystem>
#include <new>
#include <iostream>
#include <string>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/output_file.hpp"
#include "abuopt/common/provenance.hpp"
#include "abuopt/common/stop.hpp"
#include "abuopt/common/suggest.hpp"
#include "abuopt/parallel/parallel.hpp"
#include "abuopt/studies/terms.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {
namespace {
int g_exit_code = 0;
}
void set_exit_code(int code) { g_exit_code = code; }
int exit_code() { return g_exit_code; }

// After a parse error: "did you mean" for the first argument that is neither a subcommand (in
// first place) nor an option of the chosen subcommand ("" when nothing is close).
std::string hint_for(CLI::App& app, int argc, char** argv) {
  if (argc < 2) return "";
  const std::string first = argv[1];
  if (first.empty() || first[0] == '-') return "";
  const std::vector<CLI::App*> subs = app.get_subcommands([](CLI::App*) { return true; });
  std::vector<std::string> names;
  CLI::App* sub = nullptr;
  for (CLI::App* s : subs) {
    names.push_back(s->get_name());
    if (s->get_name() == first) sub = s;
  }
  if (!sub) {
    const auto m = closest_match(first, names);
    return m ? "abuopt: '" + first + "' is not a command; did you mean '" + *m + "'?" : "";
  }
  std::vector<std::string> flags = {"--help"};
  for (const CLI::Option* o : sub->get_options())
    for (const std::string& n : o->get_lnames()) flags.push_back("--" + n);
  for (int i = 2; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--") break;
    if (arg.rfind("--", 0) != 0) continue;
    arg = arg.substr(0, arg.find('='));
    if (std::find(flags.begin(), flags.end(), arg) != flags.end()) continue;
    const auto m = closest_match(arg, flags);
    return m ? "abuopt " + first + ": '" + arg + "' is not an option; did you mean '" + *m + "'?" : "";
  }
  return "";
}

}  // namespace abuopt::app

namespace {

int run_cli(int argc, char** argv) {
  CLI::App app{
      "abuopt: simulate an Automatic Balancing Unit (ABU) during startup, evaluate startup profiles\n"
      "by Monte Carlo over initial ball positions, and optimise them.\n"
      "Every study is a YAML config (see configs/ and docs/config.md).\n"
      "Exit status of every command: 0 ok; 2 bad input (config, option or value; the message names the\n"
      "key, value and rule); 3 the computation gave no usable result (every run failed, no feasible\n"
      "design, an evaluation error ended it, out of memory); 4 an output file could not be written (disk\n"
      "full, no permission: nothing half-written is left under its name); 130 interrupted (Ctrl-C, SIGINT),\n"
      "143 terminated (SIGTERM): what is complete is kept and the message says what.\n"
      "docs/security.md says what abuopt trusts, where it writes and how it runs gnuplot."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "abuopt " + abuopt::abuopt_version() + " (" + abuopt::abuopt_git_commit() + ")");
  abuopt::app::register_all(app);
  // After the subcommands: CLI11 copies a footer into every subcommand made later, and the terms
  // belong once in `abuopt --help` (the commands that print them point here).
  app.footer("\n" + abuopt::terms_text(""));

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
    if (const std::string hint = abuopt::app::hint_for(app, argc, argv); !hint.empty()) std::cerr << hint << "\n";
    return 2;
  } catch (const abuopt::Interrupted& e) {  // SIGINT / SIGTERM (abuopt/common/stop.hpp; under mpirun docs/cluster.md)
    std::cerr << "abuopt: " << e.what() << "\n";
    return abuopt::stop_exit_status();
  } catch (const abuopt::ConfigError& e) {
    std::cerr << "abuopt: error: " << e.what() << "\n";
    return 2;
  } catch (const abuopt::OutputError& e) {
    std::cerr << "abuopt: error: " << e.what() << "\n";
    return 4;
  } catch (const std::filesystem::filesystem_error& e) {
    std::cerr << "abuopt: error: " << e.what() << "\n";
    return 4;
  } catch (const std::bad_alloc&) {
    std::cerr << "abuopt: error: out of memory (the request needs more memory than is available; ask for fewer "
                 "runs, a coarser grid or a longer trajectory interval)\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "abuopt: error: the computation failed: " << e.what() << "\n";
    return 3;
  }
  return abuopt::app::exit_code();
}

}  // namespace

// Under mpirun, rank 0 runs the command and the other ranks serve its Monte Carlo studies
// (abuopt/parallel/parallel.hpp); without mpirun this is a plain program.
int main(int argc, char** argv) {
  // A file-size limit (ulimit -f) must fail a write like a full disk does (exit 4, nothing
  // half-written under the final name), not kill the process with SIGXFSZ.
  std::signal(SIGXFSZ, SIG_IGN);
  abuopt::parallel::Session mpi(argc, argv);
  if (!mpi.is_root()) return mpi.serve();
  // SIGINT and SIGTERM: a command that polls the stop request (StopScope) stops at its next safe
  // point, keeps what is complete and exits 130 / 143; any other ends at once (docs/security.md)
  abuopt::install_stop_handlers();
  return mpi.finish(run_cli(argc, argv));
}
