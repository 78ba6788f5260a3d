#pragma once
// The YAML pieces of the design problem that most command-line tests run (`abuopt optimize`,
// `sweep`, `pareto`): the report's ABU at the design friction with the 2003 final profile as the
// template, and the three-segment design of docs/optimize.md. A test adds its own simulation,
// montecarlo, objective, constraints and command sections.
#include <string>

namespace abuopt_test {

// abu (mu 0.02, the report's two balls by default) and the 2003 final profile.
inline const std::string kReportAbuAndProfile = R"(abu:
  friction_mu: 0.02
profile:
  start_frequency_hz: 0
  segments:
    - {end_frequency_hz: 25.0, duration_s: 1.0}
    - {end_frequency_hz: 29.5, duration_s: 10.0}
    - {end_frequency_hz: 100.0, duration_s: 8.0}
)";

// `montecarlo`: `runs` Latin-hypercube starts of seed 7.
inline std::string lhs_montecarlo(int runs) {
  return "montecarlo:\n  design: lhs\n  runs: " + std::to_string(runs) + "\n  seed: 7\n";
}

// The free variables f1, dt1, f2, dt2, dt3 around the 2003 profile (f3 = 100 Hz fixed).
inline const std::string kThreeSegmentDesign = R"(design:
  segments:
    - end_frequency_hz: {min: 15, max: 28, x0: 25}
      duration_s: {min: 0.3, max: 3, x0: 1}
    - end_frequency_hz: {min: 28, max: 32, x0: 29.5}
      duration_s: {min: 1, max: 12, x0: 10}
    - end_frequency_hz: 100
      duration_s: {min: 1, max: 10, x0: 8}
)";

}  // namespace abuopt_test
