#include "abuopt/studies/out_of_sample.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace abuopt {

namespace {

std::string metric_cell(const opt::Evaluation& e, const std::string& key, int width, int precision = 3) {
  std::ostringstream os;
  auto it = e.metrics.find(key);
  if (it == e.metrics.end() || !std::isfinite(it->second))
    os << std::setw(width) << "-";
  else
    os << std::setw(width) << std::fixed << std::setprecision(precision) << it->second;
  return os.str();
}

}  // namespace

OutOfSampleComparison compare_out_of_sample(const problems::StartupProfileProblem& problem,
                                            const opt::OptimizationResult& r,
                                            const opt::PenaltyProblem* penalty) {
  auto as_optimised = [&](opt::Evaluation e) { return penalty ? penalty->penalise(std::move(e)) : e; };
  const auto& st = problem.settings();
  const auto& v = st.validation;
  OutOfSampleComparison c{problem.profile_at(r.x), StartupProfile::report_final(), {}};
  opt::Evaluation best_in;
  best_in.objective = r.objective;
  best_in.inequality = r.inequality;
  best_in.metrics = r.metrics;
  c.rows = {
      {"best, in-sample (" + std::to_string(st.study.runs) + ")", best_in},
      {"best, out-of-sample (" + std::to_string(v.runs) + ")", as_optimised(problem.evaluate_out_of_sample_at(r.x))},
      {"report profile, in-sample", as_optimised(problem.evaluate_profile(c.report))},
      {"report profile, out-of-sample", as_optimised(problem.evaluate_out_of_sample(c.report))},
  };
  return c;
}

std::string comparison_table(const std::vector<ComparisonRow>& rows) {
  std::ostringstream os;
  os << std::left << std::setw(34) << "  design, sample" << std::right << std::setw(10) << "objective" << std::setw(10)
     << "mean|Ir|" << std::setw(10) << "mean Irx" << std::setw(9) << "%MI|Ir|" << std::setw(8) << "%MI Irx"
     << std::setw(7) << "%LC" << std::setw(9) << "amp[mm]" << std::setw(8) << "T[s]" << std::setw(7) << "failed"
     << "\n";
  for (const auto& r : rows) {
    os << std::left << std::setw(34) << ("  " + r.label) << std::right;
    if (std::isfinite(r.e.objective))
      os << std::setw(10) << std::fixed << std::setprecision(4) << r.e.objective;
    else
      os << std::setw(10) << "failed";
    os << metric_cell(r.e, "ir_magnitude_mean", 10) << metric_cell(r.e, "ir_x_mean", 10)
       << metric_cell(r.e, "pct_mi_magnitude", 9, 2) << metric_cell(r.e, "pct_mi_x", 8, 2)
       << metric_cell(r.e, "pct_lc", 7, 2) << metric_cell(r.e, "amplitude_max_mm", 9) << metric_cell(r.e, "startup_time_s", 8, 2)
       << metric_cell(r.e, "failed_runs", 7, 0) << "\n";
  }
  os << "  (I_r in 1e-7 kg m; amp = max over runs of the peak amplitude; T = startup time)\n";
  return os.str();
}

OutOfSampleVerdict out_of_sample_verdict(const std::vector<ComparisonRow>& rows) {
  OutOfSampleVerdict v;
  if (rows.size() < 4) return v;
  const opt::Evaluation& best = rows[1].e;
  const opt::Evaluation& report = rows[3].e;
  struct Quantity {
    const char* key;
    const char* name;
    int digits;
  };
  static const Quantity quantities[] = {{"ir_magnitude_mean", "mean |I_r|", 3},
                                        {"ir_x_mean", "mean I_r,x", 3},
                                        {"pct_mi_magnitude", "%MI |I_r|", 2},
                                        {"pct_mi_x", "%MI I_r,x", 2}};
  std::ostringstream os;
  os << "  best vs report profile, out-of-sample (lower is better):\n";
  bool any = false;
  for (const Quantity& q : quantities) {
    auto b = best.metrics.find(q.key);
    auto r = report.metrics.find(q.key);
    if (b == best.metrics.end() || r == report.metrics.end() || !std::isfinite(b->second) || !std::isfinite(r->second))
      continue;
    any = true;
    const bool worse = b->second > r->second;
    if (worse) v.worse.push_back(q.name);
    os << "    " << std::left << std::setw(11) << q.name << std::right << std::fixed << std::setprecision(q.digits)
       << std::setw(9) << b->second << " vs " << std::setw(9) << r->second << "  "
       << (b->second < r->second ? "better" : worse ? "WORSE" : "equal") << "\n";
  }
  if (!any) return v;
  if (!v.worse.empty()) {
    os << "    WORSE than the report's profile on ";
    for (std::size_t i = 0; i < v.worse.size(); ++i) os << (i ? ", " : "") << v.worse[i];
    os << ": the objective optimised another quantity (objective.kind and .definition, docs/optimize.md)\n";
  }
  v.text = os.str();
  return v;
}

}  // namespace abuopt
