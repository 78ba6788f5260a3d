// libFuzzer target: the command line. The input is split at newlines into arguments (at most 24)
// and parsed by the real `abuopt` CLI definition; the app's parse-complete callback, which CLI11
// runs after every option is converted and before any command's action, throws, so only parsing,
// conversion and validation of options run (never a study, never a file write). (Replacing each
// command's action with a no-op instead destroyed the shared arguments its lambda owned, and the
// options then wrote into freed memory: a finding of this target in the harness itself.)
// Parsing may only succeed or throw CLI11's ParseError or ConfigError; anything else is a finding.
#include <cstdint>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "abuopt/common/config_error.hpp"
#include "commands/commands.hpp"

namespace abuopt::app {
// main.cpp's exit-code store, which this target replaces.
void set_exit_code(int) {}
int exit_code() { return 0; }
}  // namespace abuopt::app

namespace {
// Thrown when every option of the input is converted and validated, before any command's action.
struct ParsedOnly {};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 4096) return 0;
  std::vector<std::string> args{"abuopt"};
  std::string cur;
  for (std::size_t i = 0; i < size && args.size() <= 24; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\n') {
      args.push_back(cur);
      cur.clear();
    } else if (c != '\0') {
      cur += c;
    }
  }
  if (!cur.empty() && args.size() <= 24) args.push_back(cur);

  CLI::App app{"abuopt"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "abuopt fuzz");
  abuopt::app::register_all(app);
  // the option-value checks of register_all, then stop before any command runs
  app.parse_complete_callback([&app] {
    abuopt::app::check_option_values(app);
    throw ParsedOnly{};
  });

  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError&) {
  } catch (const abuopt::ConfigError&) {
  } catch (const ParsedOnly&) {
  }
  return 0;
}
