// Issue 33 item 4: the front of startup time T against mean |I_r| by pagmo's NSGA-II
// (opt::minimize_two_objectives) against `abuopt pareto`'s epsilon-constraint series (run_pareto,
// COBYLA per bound with a warm start), at equal evaluations, both validated out of sample, compared
// by hypervolume against one reference point. configs/sweep/pareto_time.yaml at a small size (32
// runs per evaluation, 20 evaluations per run, 256 validation runs), NSGA-II from three seeds. Prints
// [measure] lines; a
// measurement (label long), with checks that the two fronts are real fronts of the same problem.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "abuopt/optimizer/multi_objective.hpp"
#include "abuopt/studies/pareto.hpp"

namespace {

using namespace abuopt;

TEST(Nsga2VsPareto, FrontsAtEqualEvaluationsByHypervolume) {
  YamlReader root = YamlReader::load_file(std::string(ABUOPT_SOURCE_DIR) + "/configs/sweep/pareto_time.yaml");
  YAML::Node node = root.node();
  node["montecarlo"]["runs"] = 32;
  node["validation"]["runs"] = 256;
  node["optimizer"]["max_evaluations"] = 20;
  YamlReader r(node, "");
  const problems::StartupProfileSettings base = problems::read_startup_profile_settings(r);
  YamlReader optimizer = r.child("optimizer");
  opt::OptimizerOptions options = opt::read_optimizer_options(optimizer);
  options.handle_sigint = false;
  const ParetoSettings ps = read_pareto_settings(r.child("pareto"));
  const std::filesystem::path dir = std::filesystem::path(ABUOPT_BINARY_DIR) / "nsga2_vs_pareto";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);

  // the epsilon-constraint series
  const ParetoResult eps = run_pareto(base, options, ps, (dir / "archive.sqlite").string(), "test", "none");
  long budget = 0;
  std::vector<std::pair<double, double>> eps_in, eps_out;
  for (const ParetoPoint& p : eps.points) {
    budget += p.evaluations;
    if (p.x.empty() || !p.result.feasible) continue;
    eps_in.emplace_back(p.result.objective, p.startup_time_s);
    if (p.out_of_sample.ok && opt::is_feasible(p.out_of_sample, options.constraint_tolerance))
      eps_out.emplace_back(p.out_of_sample.objective, p.startup_time_s);
  }

  // NSGA-II with the same number of evaluations on the problem without a bound on T, three seeds
  problems::StartupProfileProblem problem(base);
  struct Front {
    unsigned long seed;
    std::vector<std::pair<double, double>> in, out;
  };
  std::vector<Front> fronts;
  for (unsigned long seed : {7UL, 8UL, 9UL}) {
    opt::OptimizerOptions o = options;
    o.max_evaluations = budget;
    o.population = 20;
    o.seed = seed;
    const opt::TwoObjectiveResult nsga = opt::minimize_two_objectives(problem, "startup_time_s", o);
    EXPECT_EQ(nsga.run.evaluations, budget);
    Front f{seed, nsga.front_objectives(), {}};
    for (std::size_t i : nsga.front) {
      const opt::Evaluation e = problem.evaluate_out_of_sample(problem.profile_at(nsga.run.history[i].x));
      if (e.ok && opt::is_feasible(e, options.constraint_tolerance))
        f.out.emplace_back(e.objective, nsga.run.history[i].metrics.at("startup_time_s"));
    }
    // a front is non-dominated: sorted by objective, T strictly falls
    for (std::size_t k = 1; k < f.in.size(); ++k) {
      EXPECT_GT(f.in[k].first, f.in[k - 1].first);
      EXPECT_LT(f.in[k].second, f.in[k - 1].second);
    }
    fronts.push_back(std::move(f));
  }

  // one reference point for all: 10 % beyond the worst objective of any front, the largest bound
  double f_ref = 0;
  for (const auto* v : {&eps_in, &eps_out})
    for (const auto& p : *v) f_ref = std::max(f_ref, p.first);
  for (const Front& f : fronts)
    for (const auto* v : {&f.in, &f.out})
      for (const auto& p : *v) f_ref = std::max(f_ref, p.first);
  const std::pair<double, double> ref{1.1 * f_ref, ps.max_startup_time_s.back()};
  const double hv_eps_in = opt::hypervolume_2d(eps_in, ref), hv_eps_out = opt::hypervolume_2d(eps_out, ref);
  std::cout << "[measure] equal budget " << budget << " evaluations (32 runs each); reference (" << ref.first << ", "
            << ref.second << " s)\n"
            << "[measure] epsilon-constraint (COBYLA, " << eps.points.size() << " bounds): " << eps_in.size()
            << " feasible points, hypervolume in sample " << hv_eps_in << ", out of sample " << hv_eps_out << " ("
            << eps_out.size() << " feasible out of sample)\n";
  int wins_in = 0, wins_out = 0;
  for (const Front& f : fronts) {
    const double hv_in = opt::hypervolume_2d(f.in, ref), hv_out = opt::hypervolume_2d(f.out, ref);
    wins_in += hv_in > hv_eps_in;
    wins_out += hv_out > hv_eps_out;
    std::cout << "[measure] NSGA-II (population 20, seed " << f.seed << "): " << f.in.size()
              << " front points, hypervolume in sample " << hv_in << ", out of sample " << hv_out << " ("
              << f.out.size() << " feasible out of sample)\n";
    EXPECT_GT(hv_in, 0.0);
  }
  std::cout << "[measure] NSGA-II above the epsilon-constraint front: " << wins_in << "/3 seeds in sample, " << wins_out
            << "/3 out of sample\n";
  ASSERT_FALSE(eps_in.empty());
  EXPECT_GT(hv_eps_in, 0.0);
  std::filesystem::remove_all(dir);
}

}  // namespace
