#pragma once
// Internal: the algorithm adapters behind minimize(). Each runs its library through the
// EvaluationDriver and reports why the library stopped.
#include <string>
#include <vector>

#include "abuopt/optimizer/algorithms.hpp"
#include "evaluation_driver.hpp"

namespace abuopt::opt::detail {

struct AdapterOutcome {
  TerminationReason reason = TerminationReason::Failure;
  std::string message;
  std::string algorithm_label;  // e.g. "AUGLAG(BOBYQA)"
  long iterations = 0;
  std::vector<IterationRecord> records;  // SAO
};

// `x0` in real units, inside the bounds. `local` is used for AUGLAG / MLSL_LDS and for wrapping a
// bound-only local algorithm in AUGLAG (wrap == true); it may be null otherwise. An algorithm that
// needs a local one without getting it is API misuse: std::invalid_argument.
AdapterOutcome run_nlopt(EvaluationDriver& driver, const AlgorithmInfo& algorithm, const AlgorithmInfo* local,
                         bool wrap_in_auglag, const OptimizerOptions& options, const std::vector<double>& x0);

AdapterOutcome run_ipopt(EvaluationDriver& driver, const OptimizerOptions& options, const std::vector<double>& x0);

// SAO (sao.cpp) with options.sao; `problem` gives the variables (every evaluation goes through the
// driver).
AdapterOutcome run_sao(EvaluationDriver& driver, Problem& problem, const OptimizerOptions& options,
                       const std::vector<double>& x0);
// SAO's sample size schedule against the problem (sao_sampling.cpp), before the run: ConfigError
// naming sao.samples.* when the problem's sample size cannot be chosen or is too small.
void check_sao_sampling(const Problem& problem, const SaoOptions& sao);

}  // namespace abuopt::opt::detail
