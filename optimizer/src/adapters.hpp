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

// pagmo2 (pagmo_adapter.cpp): PAGMO_CMAES, PAGMO_XNES, PAGMO_SADE, PAGMO_PSO.
bool is_pagmo_algorithm(const std::string& canonical_name);
// The population of a pagmo run on n variables: `requested` (optimizer.population) when > 0, else
// max(8, 4 + floor(3 ln n)).
std::size_t pagmo_population(const std::string& canonical_name, std::size_t n, long requested);
// Before the run: ConfigError naming optimizer.population (below the algorithm's minimum) or
// optimizer.max_evaluations (less than one population).
void check_pagmo(const std::string& canonical_name, std::size_t n, const OptimizerOptions& options);
AdapterOutcome run_pagmo(EvaluationDriver& driver, const AlgorithmInfo& algorithm, const OptimizerOptions& options,
                         const std::vector<double>& x0);

}  // namespace abuopt::opt::detail
