// Where the balls end, against the set that held them: the final angles of the recommended design and
// of the baseline on the first fresh sample (at most 256 runs), each settled run measured as
// `abuopt eqset --runs` measures it (early/late, depth |U|/r_lock; core/include/abuopt/core/final_states.hpp),
// over the lock set of the nominal ABU (lock gauge <= 1: held at every constant speed; the equilibrium
// set at the operating speed covers the whole torus and says nothing). Two balls only; a few seconds
// (not archived: a rerun recomputes the same numbers).
#include <algorithm>
#include <cmath>

#include "abuopt/core/batch_runner.hpp"
#include "abuopt/core/final_states.hpp"
#include "abuopt/core/monte_carlo.hpp"
#include "study_context.hpp"

namespace abuopt::studies::detail {

namespace {

constexpr std::size_t kLockGrid = 90;  // 4 degree cells

FinalPositions final_states(MonteCarloStudy st, const StartupProfile& p, const AbuParameters& nominal,
                            std::size_t threads, BatchRunner* given) {
  st.setup.profile = p;
  ThreadPoolRunner own(threads);
  const MonteCarloResult r = run_monte_carlo(st, given ? *given : static_cast<BatchRunner&>(own));
  std::vector<FinalStateInput> in;
  for (const auto& s : r.samples) {
    if (s.outcome.beta_final.size() != 2) continue;
    FinalStateInput f;
    f.index = static_cast<long>(s.index);
    f.beta_final = s.outcome.beta_final;
    f.settled = s.outcome.settled;
    f.settling_time_s = s.outcome.settling_time_s;
    f.friction_mu = s.overrides.friction_mu;
    f.imbalance_mass_kg = s.overrides.imbalance_mass_kg;
    f.stiffness_N_per_m = s.overrides.stiffness_N_per_m;
    in.push_back(std::move(f));
  }
  const FinalStateAnalysis a = analyse_final_states(nominal, p, in);
  FinalPositions out;
  for (const auto& rec : a.records) {
    const auto& b = r.samples[static_cast<std::size_t>(rec.index)].outcome.beta_final;
    out.angles_deg.emplace_back(b[0] * 180.0 / M_PI, b[1] * 180.0 / M_PI);
    out.early.push_back(rec.early ? 1 : 0);
    out.depth.push_back(rec.depth);
  }
  out.not_settled = a.not_settled;
  out.early_share = a.early.share;
  out.depth_mean = a.depth_mean;
  out.depth_lo = a.depth_mean_ci.lo;
  out.depth_hi = a.depth_mean_ci.hi;
  out.early_depth_mean = a.early.depth_mean;
  out.late_depth_mean = a.late.depth_mean;
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
  const AbuParameters abu = abu_of_choice(c.file, d.choice);
  v.final_design = final_states(fr.settings.study, d.profile, abu, threads, runner);
  v.final_baseline = final_states(c.baseline_sample(seed, runs).study, c.file.base.setup.profile, abu, threads, runner);
  v.lock_mu = abu.friction_mu;
  std::tie(v.lock_band_lo_hz, v.lock_band_hi_hz) = lock_band_hz(abu);
  v.early_edge_hz = band_edge_hz(abu);
  v.lock_n = kLockGrid;
  v.lock_in_set.assign(kLockGrid * kLockGrid, 0);
  for (std::size_t i = 0; i < kLockGrid; ++i)
    for (std::size_t j = 0; j < kLockGrid; ++j) {
      const double b1 = 2.0 * M_PI * (static_cast<double>(i) + 0.5) / kLockGrid;
      const double b2 = 2.0 * M_PI * (static_cast<double>(j) + 0.5) / kLockGrid;
      v.lock_in_set[i * kLockGrid + j] = lock_gauge(abu, {b1, b2}) <= 1.0 ? 1 : 0;
    }
  c.log("final positions: " + std::to_string(v.final_design.angles_deg.size()) + " and " +
        std::to_string(v.final_baseline.angles_deg.size()) + " settled runs over the lock set");
}

}  // namespace abuopt::studies::detail
