// Where the balls end: the final angles of the recommended design and of the baseline on the first
// fresh sample (at most 256 runs), and the equilibrium set (report section 4.2) at the profiles'
// last frequency and the nominal friction, for the report's scatter over the set. Two balls only;
// a few seconds (not archived: a rerun recomputes the same numbers).
#include <algorithm>
#include <cmath>

#include "abuopt/core/batch_runner.hpp"
#include "abuopt/core/equilibrium_set.hpp"
#include "abuopt/core/monte_carlo.hpp"
#include "study_context.hpp"

namespace abuopt::studies::detail {

namespace {

std::vector<std::pair<double, double>> final_angles_deg(MonteCarloStudy st, const StartupProfile& p,
                                                        std::size_t threads, BatchRunner* given) {
  st.setup.profile = p;
  ThreadPoolRunner own(threads);
  const MonteCarloResult r = run_monte_carlo(st, given ? *given : static_cast<BatchRunner&>(own));
  std::vector<std::pair<double, double>> out;
  for (const auto& s : r.samples)
    if (s.outcome.beta_final.size() == 2)
      out.emplace_back(s.outcome.beta_final[0] * 180.0 / M_PI, s.outcome.beta_final[1] * 180.0 / M_PI);
  return out;
}

}  // namespace

void final_positions(StudyContext& c, const StudyDesign& d, std::uint64_t seed, std::size_t runs) {
  ValidationResult& v = c.result.validation;
  if (d.balls != 2 || c.file.base.setup.abu.balls.size() != 2) {
    c.log("final positions: drawn for two balls only");
    return;
  }
  const StudyContext::Fresh fr = c.fresh(d.choice, seed, runs);
  const std::size_t threads = fr.settings.threads;
  BatchRunner* runner = c.options.runner.get();  // e.g. MPI ranks
  v.final_design = final_angles_deg(fr.settings.study, d.profile, threads, runner);
  v.final_baseline = final_angles_deg(c.baseline_sample(seed, runs).study, c.file.base.setup.profile, threads, runner);
  const AbuParameters abu = abu_of_choice(c.file, d.choice);
  const EquilibriumSet set(abu, abu.friction_mu);
  v.eq_frequency_hz = d.profile.segments().back().end_frequency_hz;
  v.eq_mu = abu.friction_mu;
  v.eq_n = 90;
  v.eq_in_set = set.grid(v.eq_frequency_hz, v.eq_n).in_set;
  c.log("final positions: " + std::to_string(v.final_design.size()) + " runs of each profile over the equilibrium set");
}

}  // namespace abuopt::studies::detail
