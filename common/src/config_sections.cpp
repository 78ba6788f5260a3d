#include "abuopt/common/config_sections.hpp"

namespace abuopt {

const std::vector<std::string>& config_sections() {
  // simulate/eqset/montecarlo: the model and its run; eqset: its frequencies; montecarlo: initial
  // conditions and uncertain parameters; envelope: the uncertain parameters of robust designs;
  // design..sao: `abuopt optimize` (and the Python StartupProfileProblem); sweep, pareto: those
  // commands on an optimize config.
  static const std::vector<std::string> sections = {
      "abu",       "profile",     "motor",     "simulation", "montecarlo", "envelope", "eqset",
      "design",    "objective",   "constraints", "validation", "optimizer", "sao",    "sweep",
      "pareto"};
  return sections;
}

void finish_config(const YamlReader& root) {
  // A copy that counts the known sections as read: they are accepted unread, and they are the hints
  // of "did you mean" for a misspelt one. The caller's reader is not changed.
  YamlReader r = root;
  for (const std::string& s : config_sections()) r.mark_read(s);
  r.finish();
}

}  // namespace abuopt
