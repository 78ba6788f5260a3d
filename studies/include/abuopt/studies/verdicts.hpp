#pragma once
// Verdict statistics of the reproduction: one case's figures in the report's units, and the checks
// of the report's published conclusions on them (reproduction_table.hpp describes the study files).
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "abuopt/core/monte_carlo.hpp"
#include "abuopt/core/monte_carlo_stats.hpp"
#include "abuopt/studies/reproduction_table.hpp"

namespace abuopt {

// --- Results and conclusions ----------------------------------------------------------------------

// One case's figures, in the report's units (1e-7 kg m, percent). Built from the engine's
// statistics plus the standard error of the mean I_r,x (for the conclusion checks).
struct CaseSummary {
  std::string table_id, case_id, label;
  std::optional<double> value;
  std::size_t runs = 0, ok = 0, failed = 0;
  // I_r,x (report eq 4.2): what the report's tables show.
  double mean_x = 0, sem_x = 0, max_x = 0, pct_mi_x = 0;
  std::array<double, 2> ci_x{0, 0};  // 95 % Wilson interval of %MI
  // |I_r| (magnitude): extra columns.
  double mean_mag = 0, max_mag = 0, pct_mi_mag = 0;
  std::array<double, 2> ci_mag{0, 0};
  double pct_lc = 0;
  double settling_mean_s = 0, settling_median_s = 0, settling_max_s = 0;
  double amplitude_max_mm = 0;
  double wall_time_s = 0;
  PublishedRow reference;
};

CaseSummary summarize_case(const ReproductionTable& table, const ReproductionCase& c, const MonteCarloResult& result);

// Is the published %MI inside our Wilson interval? (nullopt when not published.)
std::optional<bool> reference_pct_mi_inside(const CaseSummary& s);

enum class VerdictOutcome {
  Confirmed,      // the claimed direction holds and is statistically clear (see below)
  Weak,           // the direction holds on the point estimates, but intervals overlap
  NotReproduced,  // the direction does not hold
  NotTested,      // the cases needed are missing
};
std::string to_string(VerdictOutcome v);  // "CONFIRMED", "WEAK", "NOT REPRODUCED", "NOT TESTED"

struct Verdict {
  std::string table_id, conclusion_id, claim;
  VerdictOutcome outcome = VerdictOutcome::NotTested;
  std::string evidence;  // the numbers behind the outcome, one line
  std::string one_line() const;  // "(b) [table 4.1] CONFIRMED: <claim> -- <evidence>"
};

// "Statistically clear": for %MI the two Wilson intervals do not overlap; for the mean the gap
// exceeds 1.96 sqrt(sem_a^2 + sem_b^2). A comparison is "better" when lower.
// beats_all: `best` against each of `others`, on mean_x and on pct_mi_x: Confirmed when every
// comparison is lower and clear, Weak when every one is lower, NotReproduced otherwise.
Verdict check_beats_all(const CaseSummary& best, const std::vector<CaseSummary>& others);
// pct_mi_decreases_with_value: the smallest-value row against the largest-value row.
Verdict check_pct_mi_decreases(const std::vector<CaseSummary>& rows);
// worsens_with_value: mean_x AND pct_mi_x of the largest-value row above the smallest-value row;
// the evidence also counts the monotone steps along the value.
Verdict check_worsens_with_value(const std::vector<CaseSummary>& rows);
// Every conclusion of the table on its rows (claim, ids filled in).
std::vector<Verdict> check_conclusions(const ReproductionTable& table, const std::vector<CaseSummary>& rows);

}  // namespace abuopt
