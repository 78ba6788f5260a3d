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

std::string diameters_mm(const std::vector<Ball>& balls) {
  std::vector<double> d;
  for (const Ball& b : balls)
    if (std::find(d.begin(), d.end(), b.diameter_m) == d.end()) d.push_back(b.diameter_m);
  std::string t;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (i) t.push_back('/');
    t += format_significant(d[i] * 1e3, 4);
  }
  return t;
}

StudyPlan plan_of(const StudyFile& f) {
  StudyPlan p;
  // with the ball count a variable the global stages run once over every count and the later
  // stages polish the chosen count (counted as one; a second global stage may choose another)
  const long long choices = f.ball_count_variable ? 1 : static_cast<long long>(f.choices.size());
  const long long robust = std::max<long long>(1, static_cast<long long>(f.objective.robust_friction_mu.size()));
  const long long runs = static_cast<long long>(f.base.runs) * robust;  // simulations per evaluation
  p.runs_per_evaluation = runs;
  long long optimiser = 0;
  for (const StageSpec& s : f.stages)
    if (s.kind == StageKind::Global || s.kind == StageKind::Local)
      optimiser += s.optimizer.max_evaluations * choices;
    else if (s.kind == StageKind::Pareto)  // a run per bound and choice, or one run per choice (nsga2, moead)
      optimiser += s.optimizer.max_evaluations * choices *
                   (s.pareto_method == "epsilon_constraint" ? static_cast<long long>(s.pareto_bounds.size()) : 1LL);
  p.optimiser_evaluations = std::min<long long>(optimiser, f.max_evaluations);
  p.other_evaluations = 1;  // the baseline
  long long fresh = 0;      // simulations on fresh samples
  const bool two_balls = f.base.setup.abu.balls.size() == 2 && f.choices.front().balls.size() == 2;
  for (const StageSpec& s : f.stages) {
    const long long stage_runs = (s.runs ? static_cast<long long>(s.runs) : static_cast<long long>(f.base.runs)) * robust;
    const long long seeds = static_cast<long long>(s.seeds.size());
    long long n = 0;  // Monte Carlos of stage_runs
    if (s.kind == StageKind::Pareto) {  // each front point and the baseline on every fresh sample
      n = seeds * (choices * static_cast<long long>(s.pareto_method == "epsilon_constraint" ? s.pareto_bounds.size()
                                                                                           : s.pareto_points) +
                   1);
    } else if (s.kind == StageKind::Replicate) {
      n = seeds * (choices + 1);
    } else if (s.kind == StageKind::Validate) {
      n = 2 * seeds;
      const long long map_runs = s.map_runs ? static_cast<long long>(s.map_runs) : stage_runs / robust;
      const long long points = static_cast<long long>(s.map_friction_mu.size() * s.map_imbalance_factor.size());
      p.other_evaluations += 2 * points;
      fresh += 2 * points * map_runs;
      if (two_balls) fresh += 2 * std::min<long long>(stage_runs / robust, 256);  // final positions
    }
    p.other_evaluations += n;
    fresh += n * stage_runs;
  }
  p.simulations = runs * (1 + p.optimiser_evaluations) + fresh;
  for (std::size_t i = 0; i < f.choices.size(); ++i) {
    const problems::StartupProfileSettings s = settings_of_choice(f, i, kPlaceholder);
    const std::string reach = resonance_reach_text(s.design, s.study.setup.abu.natural_frequency_hz());
    if (!reach.empty()) p.warnings.push_back(choice_name(f.choices[i]) + ": " + reach);
    if (f.ball_count_variable) break;  // the same family and f_n for every count
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
  if (f.ball_count_variable) {
    os << "the ball count a variable of the global stages,";
    for (const BallChoice& ch : f.choices) os << " " << ch.balls.size();
    os << " balls at a total ball mass of " << format_number(f.total_ball_mass_kg.value_or(0))
       << " kg; the later stages polish the chosen count\n";
  } else if (f.total_ball_mass_kg) {
    os << "ball counts";
    for (const BallChoice& ch : f.choices) os << " " << ch.balls.size();
    os << " at a total ball mass of " << format_number(*f.total_ball_mass_kg) << " kg (each count optimised)\n";
  } else if (f.choices.size() > 1) {
    os << "ball sets (each optimised):";
    for (const BallChoice& ch : f.choices) {
      double m = 0;
      for (const Ball& b : ch.balls) m += b.mass_kg;
      os << " " << ch.label << " (" << ch.balls.size() << " balls, " << format_significant(m, 6) << " kg in all, "
         << diameters_mm(ch.balls) << " mm)";
    }
    os << "\n";
  } else {
    os << "none (the abu's " << abu.balls.size() << " balls)\n";
  }
  for (std::size_t i = 0; i < f.choices.size(); ++i) {
    const problems::StartupProfileSettings s =
        f.ball_count_variable ? settings_of_variable_count(f, kPlaceholder) : settings_of_choice(f, i, kPlaceholder);
    const problems::StartupProfileProblem problem(s);
    os << (f.ball_count_variable ? std::string("the global stages") : choice_name(f.choices[i])) << ": f_n = "
       << rounded(s.study.setup.abu.natural_frequency_hz(), 2) << " Hz; free variables"
       << (f.frequencies_natural ? " (frequencies converted from units of f_n)" : "") << ":\n";
    for (const opt::Variable& v : problem.variables()) {
      const bool freq = !v.name.empty() && v.name[0] == 'f';
      const bool balls = v.name == "balls";
      os << "  " << v.name << " in [" << rounded(v.lower, 3) << ", " << rounded(v.upper, 3) << "] "
         << (balls ? "(rounded to the nearest count)" : freq ? "Hz" : "s") << "\n";
    }
    if (f.ball_count_variable) break;
  }
  os << "objective: " << problems::to_string(f.objective.kind) << "; constraints:";
  {
    const problems::StartupProfileSettings s = settings_of_choice(f, 0, kPlaceholder);
    const problems::StartupProfileProblem problem(s);
    const auto names = problem.inequality_names();
    if (names.empty()) os << " none";
    for (const auto& n : names) os << " " << n;
    os << "\n";
  }
  os << "stages:\n";
  for (const StageSpec& s : f.stages) {
    os << "  " << s.name << " (" << to_string(s.kind) << "): ";
    if (s.kind == StageKind::Pareto && s.pareto_method != "epsilon_constraint") {
      os << "the front of the objective against T by " << (s.pareto_method == "moead" ? "MOEA/D" : "NSGA-II")
         << " (population " << s.pareto_population << "), " << s.optimizer.max_evaluations
         << " evaluations per choice, from the best so far; at most " << s.pareto_points << " front points kept";
      if (!s.seeds.empty())
        os << "; each point on " << s.seeds.size() << " fresh samples of " << (s.runs ? s.runs : f.base.runs) << " runs";
      os << "\n";
    } else if (s.kind == StageKind::Pareto) {
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
