// Stage kind `validate`: the recommended design and the baseline on fresh, larger samples (one per
// seed), each metric as a mean with a 95 % t-interval over the seeds; and, with a map, the ratio
// of their mean |I_r| at fixed points (friction mu, imbalance mass factor) of the envelope (the
// envelope's other parameters, e.g. stiffness, still drawn per run).
#include <cmath>
#include <sstream>

#include "abuopt/common/text.hpp"
#include "study_context.hpp"

namespace abuopt::studies {

Interval interval_of(const std::vector<double>& v) {
  Interval r;
  r.samples = v.size();
  if (v.empty()) return r;
  double s = 0;
  for (double x : v) s += x;
  r.mean = s / static_cast<double>(v.size());
  r.lo = r.hi = r.mean;
  if (v.size() < 2) return r;
  double ss = 0;
  for (double x : v) ss += (x - r.mean) * (x - r.mean);
  const double sd = std::sqrt(ss / static_cast<double>(v.size() - 1));
  // two-sided 95 % Student t quantiles for 1..10 degrees of freedom, then the normal's
  static const double t[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228};
  const std::size_t df = v.size() - 1;
  const double q = df <= 10 ? t[df - 1] : 1.96 + 2.5 / static_cast<double>(df);
  const double h = q * sd / std::sqrt(static_cast<double>(v.size()));
  r.lo = r.mean - h;
  r.hi = r.mean + h;
  return r;
}

namespace detail {

namespace {
const char* const kMetrics[] = {"ir_magnitude_mean", "pct_mi", "amplitude_max_mm", "ir_magnitude_max"};
}

void run_validate_stage(StudyContext& c, const StageSpec& stage) {
  if (!c.result.recommended) {
    c.log("stage " + stage.name + ": no recommended design to validate");
    return;
  }
  const StudyDesign d = c.result.designs[*c.result.recommended];
  ValidationResult& v = c.result.validation;
  v.seeds = stage.seeds;
  std::map<std::string, std::vector<double>> dv, bv;
  std::vector<double> ratio;
  for (std::uint64_t seed : stage.seeds) {
    if (c.stop()) return;
    const StudyContext::Fresh fr = c.fresh(d.choice, seed, stage.runs);
    v.runs = fr.settings.study.runs;
    const opt::Evaluation& be = fr.baseline;
    if (c.stop()) return;
    const opt::Evaluation de = c.evaluate_profile(fr.settings, d.profile);
    for (const char* m : kMetrics) {
      dv[m].push_back(de.metrics.count(m) ? de.metrics.at(m) : NAN);
      bv[m].push_back(be.metrics.count(m) ? be.metrics.at(m) : NAN);
    }
    ratio.push_back(de.metrics.at("ir_magnitude_mean") / be.metrics.at("ir_magnitude_mean"));
  }
  for (const auto& [m, values] : dv) v.design[m] = interval_of(values);
  for (const auto& [m, values] : bv) v.baseline[m] = interval_of(values);
  v.ratio_mean_ir = interval_of(ratio);
  std::ostringstream os;
  os << "stage " << stage.name << ": " << d.label << " vs baseline on " << stage.seeds.size() << " x " << v.runs
     << " fresh runs: mean |I_r| ratio " << format_number(std::round(v.ratio_mean_ir.mean * 1000) / 1000) << " [" 
     << format_number(std::round(v.ratio_mean_ir.lo * 1000) / 1000) << ", "
     << format_number(std::round(v.ratio_mean_ir.hi * 1000) / 1000) << "]";
  c.log(os.str());

  if (!stage.map_friction_mu.empty()) {
    const std::size_t runs = stage.map_runs ? stage.map_runs : v.runs;
    const std::uint64_t seed = stage.seeds.front();
    v.map_mu = stage.map_friction_mu;
    v.map_imbalance = stage.map_imbalance_factor;
    v.map_runs = runs;
    for (double imb : stage.map_imbalance_factor) {
      std::vector<double> row;
      for (double mu : stage.map_friction_mu) {
        if (c.stop()) return;
        const auto at_point = [&](problems::StartupProfileSettings s) {
          s.study.seed = s.study.design.seed = seed;
          s.study.runs = runs;
          s.study.uncertain.envelope.friction_mu = ParameterDistribution::fixed(mu);
          s.study.uncertain.envelope.imbalance_mass_factor = ParameterDistribution::fixed(imb);
          s.objective.robust_friction_mu.clear();
          if (c.options.threads) s.threads = *c.options.threads;
          return s;
        };
        const opt::Evaluation be = c.evaluate_profile(at_point(c.baseline_sample(seed, runs)), c.file.base.setup.profile);
        const opt::Evaluation de = c.evaluate_profile(at_point(settings_of_choice(c.file, d.choice, be.metrics)), d.profile);
        row.push_back(de.ok && be.ok ? de.metrics.at("ir_magnitude_mean") / be.metrics.at("ir_magnitude_mean") : NAN);
      }
      v.map_ratio.push_back(row);
    }
    c.log("stage " + stage.name + ": ratio map over " + std::to_string(v.map_mu.size() * v.map_imbalance.size()) +
          " envelope points (" + std::to_string(runs) + " runs each)");
  }
  if (!c.stop()) final_positions(c, d, stage.seeds.front(), std::min<std::size_t>(v.runs, 256));
  v.done = true;
}

}  // namespace detail
}  // namespace abuopt::studies
