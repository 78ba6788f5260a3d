#pragma once
// The optimisation algorithms available by name, and what each one can do.
#include <string>
#include <vector>

namespace abuopt::opt {

enum class AlgorithmFamily { LocalDerivativeFree, LocalGradient, Global, Meta };

struct AlgorithmInfo {
  std::string name;            // canonical upper-case name, e.g. "SLSQP"
  AlgorithmFamily family;
  bool inequality_constraints; // handles g(x) <= 0 itself
  bool equality_constraints;   // handles h(x) = 0 itself
  bool needs_local;            // uses OptimizerOptions::local_algorithm (AUGLAG, MLSL_LDS)
  std::string summary;         // one line: what it suits
};

// Every algorithm, in the order of the documentation.
const std::vector<AlgorithmInfo>& algorithms();
// Canonical names, e.g. {"COBYLA", "BOBYQA", ...}.
std::vector<std::string> algorithm_names();
// Looks a name up case-insensitively; throws abuopt::ConfigError listing the valid names:
//   "<what> = foo: unknown algorithm; valid: COBYLA, BOBYQA, ..."
const AlgorithmInfo& find_algorithm(const std::string& name, const std::string& what = "optimizer.algorithm");
std::string to_string(AlgorithmFamily family);

}  // namespace abuopt::opt
