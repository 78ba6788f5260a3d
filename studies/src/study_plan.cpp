// The plan of a study (`abuopt study FILE --check`): what a run of the file would do, without
// simulating anything. The counts follow the stages' code: an optimiser stage evaluates at most its
// max_evaluations per choice, within the one budget; a replicate stage evaluates each choice's
// best and the baseline once per seed; a validate stage the recommended design and the baseline
// once per seed and per map point, and the final positions (two balls) once more.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "abuopt/common/text.hpp"
#include "abuopt/studies/study.hpp"

namespace abuopt::studies {

namespace {

// v rounded to `decimals` places, shortest form ("28.019", not "28.019000000000002")
std::string rounded(double v, int decimals) {
  const double k = std::pow(10.0, decimals);
  return format_number(std::round(v * k) / k);
}

// "12,345,678"
std::string grouped(long long n) {
  const std::string digits = std::to_string(n);
  std::string s;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) s.push_back(',');
    s.push_back(digits[i]);
  }
  return s;
}

// The relative constraints need the baseline's metrics, which only a run has: a placeholder
// (the plan shows the constraints' names, not their bounds).
const std::map<std::string, double> kPlaceholder = {{"amplitude_max_mm", 1.0}, {"amplitude_mean_mm", 1.0}};

}  // namespace

StudyPlan plan_of(const StudyFile& f) {
  StudyPlan p;
  const std::size_t choices = f.ball_counts.size();
  const long long robust = std::max<long long>(1, static_cast<long long>(f.objective.robust_friction_mu.size()));
  const long long runs = static_cast<long long>(f.base.runs) * robust;  // simulations per evaluation
  p.runs_per_evaluation = runs;
  p.simulations = runs;  // the baseline
  long long optimiser = 0;
  for (const StageSpec& s : f.stages)
    if (s.kind == StageKind::Global || s.kind == StageKind::Local)
      optimiser += s.optimizer.max_evaluations * static_cast<long long>(choices);
    else if (s.kind == StageKind::Pareto)
      optimiser += s.optimizer.max_evaluations * static_cast<long long>(choices * s.pareto_bounds.size());
  p.optimiser_evaluations = std::min<long long>(optimiser, f.max_evaluations);
  p.simulations += p.optimiser_evaluations * runs;
  for (const StageSpec& s : f.stages) {
    const long long stage_runs = (s.runs ? static_cast<long long>(s.runs) : static_cast<long long>(f.base.runs)) * robust;
    const long long seeds = static_cast<long long>(s.seeds.size());
    if (s.kind == StageKind::Pareto) {  // each front point and the baseline on every fresh sample
      p.simulations += seeds * static_cast<long long>(choices * s.pareto_bounds.size() + 1) * stage_runs;
    } else if (s.kind == StageKind::Replicate) {
      p.simulations += seeds * static_cast<long long>(choices + 1) * stage_runs;
    } else if (s.kind == StageKind::Validate) {
      p.simulations += 2 * seeds * stage_runs;
      const long long map_runs = s.map_runs ? static_cast<long long>(s.map_runs) : stage_runs / robust;
      p.simulations += 2 * static_cast<long long>(s.map_friction_mu.size() * s.map_imbalance_factor.size()) * map_runs;
      if (f.base.setup.abu.balls.size() == 2 && f.ball_counts.front() == 2)
        p.simulations += 2 * std::min<long long>(stage_runs / robust, 256);  // final positions
    }
  }
  for (std::size_t n : f.ball_counts) {
    const problems::StartupProfileSettings s = settings_of_choice(f, n, kPlaceholder);
    const std::string reach = resonance_reach_text(s.design, s.study.setup.abu.natural_frequency_hz());
    if (!reach.empty()) p.warnings.push_back(std::to_string(n) + " balls: " + reach);
  }
  return p;
}

std::string plan_text(const StudyFile& f) {
  const StudyPlan p = plan_of(f);
  std::ostringstream os;
  os << "study " << f.path << " (" << f.title << "): the file is valid\n";
  const AbuParameters& abu = f.base.setup.abu;
  os << "ABU: " << abu.balls.size() << " balls as given, natural frequency f_n = sqrt(k/M)/2pi = "
     << rounded(abu.natural_frequency_hz(), 2) << " Hz\n";
  os << "baseline: " << f.base.setup.profile.segments().size() << " segments, "
     << rounded(f.base.setup.profile.duration_s(), 3) << " s, ends at "
     << rounded(f.base.setup.profile.segments().back().end_frequency_hz, 2) << " Hz\n";
  os << "choices: ";
  if (f.total_ball_mass_kg) {
    os << "ball counts";
    for (std::size_t n : f.ball_counts) os << " " << n;
    os << " at a total ball mass of " << format_number(*f.total_ball_mass_kg) << " kg (each count optimised)\n";
  } else {
    os << "none (the abu's " << abu.balls.size() << " balls)\n";
  }
  for (std::size_t n : f.ball_counts) {
    const problems::StartupProfileSettings s = settings_of_choice(f, n, kPlaceholder);
    const problems::StartupProfileProblem problem(s);
    os << n << " balls: f_n = " << rounded(s.study.setup.abu.natural_frequency_hz(), 2) << " Hz; free variables"
       << (f.frequencies_natural ? " (frequencies converted from units of f_n)" : "") << ":\n";
    for (const opt::Variable& v : problem.variables()) {
      const bool freq = !v.name.empty() && v.name[0] == 'f';
      os << "  " << v.name << " in [" << rounded(v.lower, 3) << ", " << rounded(v.upper, 3) << "] "
         << (freq ? "Hz" : "s") << "\n";
    }
  }
  os << "objective: " << problems::to_string(f.objective.kind) << "; constraints:";
  {
    const problems::StartupProfileSettings s = settings_of_choice(f, f.ball_counts.front(), kPlaceholder);
    const problems::StartupProfileProblem problem(s);
    const auto names = problem.inequality_names();
    if (names.empty()) os << " none";
    for (const auto& n : names) os << " " << n;
    os << "\n";
  }
  os << "stages:\n";
  for (const StageSpec& s : f.stages) {
    os << "  " << s.name << " (" << to_string(s.kind) << "): ";
    if (s.kind == StageKind::Pareto) {
      os << "the front of the objective against T <=";
      for (std::size_t i = 0; i < s.pareto_bounds.size(); ++i) os << (i ? ", " : " ") << format_number(s.pareto_bounds[i]);
      os << " s; " << s.optimizer.algorithm << ", at most " << s.optimizer.max_evaluations
         << " evaluations per bound and choice";
      if (!s.seeds.empty())
        os << "; each point on " << s.seeds.size() << " fresh samples of " << (s.runs ? s.runs : f.base.runs) << " runs";
      os << "\n";
    } else if (s.kind == StageKind::Global || s.kind == StageKind::Local) {
      os << s.optimizer.algorithm << ", at most " << s.optimizer.max_evaluations << " evaluations per choice, from "
         << (s.kind == StageKind::Global ? "the family's x0" : "the best so far (the family's x0 if none)") << "\n";
    } else {
      os << s.seeds.size() << " fresh samples of " << (s.runs ? s.runs : f.base.runs) << " runs";
      if (!s.map_friction_mu.empty())
        os << "; a map of " << s.map_friction_mu.size() << " x " << s.map_imbalance_factor.size() << " envelope points ("
           << (s.map_runs ? s.map_runs : (s.runs ? s.runs : f.base.runs)) << " runs each)";
      os << "\n";
    }
  }
  os << "budget: " << f.max_evaluations << " optimiser evaluations over every stage and choice (the stages ask for "
     << p.optimiser_evaluations << " at most), " << p.runs_per_evaluation << " runs per evaluation\n";
  os << "estimate: at most " << grouped(p.simulations) << " simulations (the baseline, the optimiser stages' "
     << grouped(p.optimiser_evaluations * p.runs_per_evaluation) << ", the fresh samples' "
     << grouped(p.simulations - p.runs_per_evaluation * (1 + p.optimiser_evaluations)) << ")\n";
  for (const auto& w : p.warnings) os << "warning: " << w << "\n";
  return os.str();
}

}  // namespace abuopt::studies
