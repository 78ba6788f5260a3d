#include "abuopt/studies/verdicts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "study_text.hpp"

namespace abuopt {

using namespace studies_detail;

namespace {

bool mi_clearly_lower(const CaseSummary& a, const CaseSummary& b) { return a.ci_x[1] < b.ci_x[0]; }
bool mean_clearly_lower(const CaseSummary& a, const CaseSummary& b) {
  return b.mean_x - a.mean_x > kZ95 * std::hypot(a.sem_x, b.sem_x);
}

// The rows with a value, smallest and largest value. Sets v's table; without two such rows marks v
// not tested (the caller returns it) and gives nullopt.
std::optional<std::pair<const CaseSummary*, const CaseSummary*>> value_extremes(const std::vector<CaseSummary>& rows,
                                                                                Verdict& v) {
  if (!rows.empty()) v.table_id = rows.front().table_id;
  const CaseSummary *lo = nullptr, *hi = nullptr;
  for (const CaseSummary& r : rows) {
    if (!r.value || r.ok == 0) continue;
    if (!lo || *r.value < *lo->value) lo = &r;
    if (!hi || *r.value > *hi->value) hi = &r;
  }
  if (!lo || lo == hi) {
    v.outcome = VerdictOutcome::NotTested;
    v.evidence = "needs two cases with different values";
    return std::nullopt;
  }
  return std::make_pair(lo, hi);
}

std::string ref_mi(const CaseSummary& s) { return s.reference.pct_mi ? num(*s.reference.pct_mi, 2) : "-"; }

}  // namespace

std::string to_string(VerdictOutcome v) {
  switch (v) {
    case VerdictOutcome::Confirmed: return "CONFIRMED";
    case VerdictOutcome::Weak: return "WEAK";
    case VerdictOutcome::NotReproduced: return "NOT REPRODUCED";
    case VerdictOutcome::NotTested: return "NOT TESTED";
  }
  return "?";
}

// --- summaries and conclusions -------------------------------------------------------------------

CaseSummary summarize_case(const ReproductionTable& table, const ReproductionCase& c, const MonteCarloResult& result) {
  const MonteCarloStats st = compute_statistics(result);
  CaseSummary s;
  s.table_id = table.id;
  s.case_id = c.id;
  s.label = c.label;
  s.value = c.value;
  s.reference = c.reference;
  s.runs = st.runs;
  s.ok = st.ok;
  s.failed = st.failed;
  s.mean_x = st.report_x.mean * 1e7;
  s.max_x = st.report_x.max * 1e7;
  s.pct_mi_x = st.report_x.pct_mi;
  s.ci_x = st.report_x.pct_mi_ci95;
  s.mean_mag = st.magnitude.mean * 1e7;
  s.max_mag = st.magnitude.max * 1e7;
  s.pct_mi_mag = st.magnitude.pct_mi;
  s.ci_mag = st.magnitude.pct_mi_ci95;
  s.pct_lc = st.pct_lc;
  s.settling_mean_s = st.settling_mean_s;
  s.settling_median_s = st.settling_median_s;
  s.settling_max_s = st.settling_max_s;
  s.amplitude_max_mm = st.amplitude_max_mm;
  s.wall_time_s = result.wall_time_s;
  // Standard error of the mean I_r,x over the ok runs: sample standard deviation / sqrt(n_eff),
  // n_eff = the distinct runs (exchanged starts of identical balls repeat a run: no new
  // information, as for the Wilson interval of %MI).
  double sum = 0, sum2 = 0;
  std::size_t n = 0;
  for (const MonteCarloSample& m : result.samples)
    if (m.outcome.ok()) {
      const double v = m.outcome.residual_imbalance_x_kgm * 1e7;
      sum += v;
      sum2 += v * v;
      ++n;
    }
  const std::size_t n_eff = st.distinct;
  if (n >= 2 && n_eff >= 2) {
    const double mean = sum / static_cast<double>(n);
    const double var = std::max(0.0, (sum2 - static_cast<double>(n) * mean * mean) / static_cast<double>(n - 1));
    s.sem_x = std::sqrt(var / static_cast<double>(n_eff));
  } else {
    s.sem_x = std::numeric_limits<double>::quiet_NaN();
  }
  return s;
}

std::optional<bool> reference_pct_mi_inside(const CaseSummary& s) {
  if (!s.reference.pct_mi || s.ok == 0) return std::nullopt;
  // Half a printed digit of slack: the report prints %MI with two decimals.
  const double r = *s.reference.pct_mi;
  return r >= s.ci_x[0] - 0.005 && r <= s.ci_x[1] + 0.005;
}

std::string Verdict::one_line() const {
  return "(" + conclusion_id + ") [table " + table_id + "] " + to_string(outcome) + ": " + claim +
         (evidence.empty() ? "" : " -- " + evidence);
}

Verdict check_beats_all(const CaseSummary& best, const std::vector<CaseSummary>& others) {
  Verdict v;
  v.table_id = best.table_id;
  if (others.empty() || best.ok == 0) {
    v.outcome = VerdictOutcome::NotTested;
    v.evidence = "no other case to compare with";
    return v;
  }
  bool all_lower = true, all_clear = true;
  const CaseSummary *near_mean = nullptr, *near_mi = nullptr;
  std::size_t clear = 0, total = 0;
  for (const CaseSummary& o : others) {
    if (o.ok == 0) continue;
    const bool lower_mean = best.mean_x < o.mean_x, lower_mi = best.pct_mi_x < o.pct_mi_x;
    const bool clear_mean = mean_clearly_lower(best, o), clear_mi = mi_clearly_lower(best, o);
    all_lower = all_lower && lower_mean && lower_mi;
    all_clear = all_clear && clear_mean && clear_mi;
    clear += static_cast<std::size_t>(clear_mean) + static_cast<std::size_t>(clear_mi);
    total += 2;
    if (!near_mean || o.mean_x < near_mean->mean_x) near_mean = &o;
    if (!near_mi || o.pct_mi_x < near_mi->pct_mi_x) near_mi = &o;
  }
  if (!near_mean) {
    v.outcome = VerdictOutcome::NotTested;
    v.evidence = "every other case failed";
    return v;
  }
  v.outcome = all_clear ? VerdictOutcome::Confirmed : all_lower ? VerdictOutcome::Weak : VerdictOutcome::NotReproduced;
  v.evidence = best.label + ": mean " + mean_text(best) + ", %MI " + mi_text(best) + "; best other on mean: " +
               near_mean->label + " " + mean_text(*near_mean) + "; on %MI: " + near_mi->label + " " + mi_text(*near_mi) +
               "; " + std::to_string(clear) + " of " + std::to_string(total) + " comparisons statistically clear";
  return v;
}

Verdict check_pct_mi_decreases(const std::vector<CaseSummary>& rows) {
  Verdict v;
  const auto ext = value_extremes(rows, v);
  if (!ext) return v;
  const CaseSummary& fast = *ext->first;  // smallest duration
  const CaseSummary& slow = *ext->second;
  v.outcome = mi_clearly_lower(slow, fast)     ? VerdictOutcome::Confirmed
              : slow.pct_mi_x < fast.pct_mi_x ? VerdictOutcome::Weak
                                              : VerdictOutcome::NotReproduced;
  v.evidence = "%MI " + fast.label + ": " + mi_text(fast) + " -> " + slow.label + ": " + mi_text(slow) + " (report " +
               ref_mi(fast) + " -> " + ref_mi(slow) + ")";
  return v;
}

Verdict check_worsens_with_value(const std::vector<CaseSummary>& rows) {
  Verdict v;
  const auto ext = value_extremes(rows, v);
  if (!ext) return v;
  const CaseSummary& lo = *ext->first;
  const CaseSummary& hi = *ext->second;
  const bool up = hi.mean_x > lo.mean_x && hi.pct_mi_x > lo.pct_mi_x;
  const bool clear = mean_clearly_lower(lo, hi) && mi_clearly_lower(lo, hi);
  v.outcome = clear ? VerdictOutcome::Confirmed : up ? VerdictOutcome::Weak : VerdictOutcome::NotReproduced;
  // Monotone steps along the value.
  std::vector<const CaseSummary*> sorted;
  for (const CaseSummary& r : rows)
    if (r.value && r.ok > 0) sorted.push_back(&r);
  std::sort(sorted.begin(), sorted.end(), [](const CaseSummary* a, const CaseSummary* b) { return *a->value < *b->value; });
  std::size_t mean_up = 0, mi_up = 0;
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    mean_up += sorted[i]->mean_x > sorted[i - 1]->mean_x;
    mi_up += sorted[i]->pct_mi_x > sorted[i - 1]->pct_mi_x;
  }
  const std::size_t steps = sorted.size() - 1;
  v.evidence = lo.label + " -> " + hi.label + ": mean " + mean_text(lo) + " -> " + mean_text(hi) + ", %MI " +
               mi_text(lo) + " -> " + mi_text(hi) + "; mean rises in " + std::to_string(mean_up) + " of " +
               std::to_string(steps) + " steps, %MI in " + std::to_string(mi_up) + " of " + std::to_string(steps);
  return v;
}

std::vector<Verdict> check_conclusions(const ReproductionTable& table, const std::vector<CaseSummary>& rows) {
  std::vector<Verdict> out;
  for (const Conclusion& k : table.conclusions) {
    Verdict v;
    switch (k.check) {
      case ConclusionCheck::BeatsAll: {
        const CaseSummary* best = nullptr;
        std::vector<CaseSummary> others;
        for (const CaseSummary& r : rows) {
          if (r.case_id == k.case_id) best = &r;
          else others.push_back(r);
        }
        if (best) {
          v = check_beats_all(*best, others);
        } else {
          v.outcome = VerdictOutcome::NotTested;
          v.evidence = "case " + k.case_id + " was not run";
        }
        break;
      }
      case ConclusionCheck::PctMiDecreasesWithValue: v = check_pct_mi_decreases(rows); break;
      case ConclusionCheck::WorsensWithValue: v = check_worsens_with_value(rows); break;
    }
    v.table_id = table.id;
    v.conclusion_id = k.id;
    v.claim = k.claim;
    out.push_back(std::move(v));
  }
  return out;
}

}  // namespace abuopt
