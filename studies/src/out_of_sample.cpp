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
      {"best, out-of-sample (" + std::to_string(v.runs) + ")", as_optimised(problem.evaluate_out_of_sample(c.best))},
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

}  // namespace abuopt
