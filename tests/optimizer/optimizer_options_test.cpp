// Options: defaults are valid, YAML keys read with paths in messages, bad values rejected.
#include "abuopt/optimizer/optimizer_options.hpp"

#include <gtest/gtest.h>

#include "abuopt/common/config_error.hpp"
#include "abuopt/optimizer/algorithms.hpp"

namespace {

using namespace abuopt::opt;
using abuopt::YamlReader;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const abuopt::ConfigError& e) {
    return e.what();
  }
  return "<no error>";
}

OptimizerOptions read(const std::string& yaml) {
  YamlReader root = YamlReader::load_string(yaml);
  YamlReader section = root.child("optimizer");
  return read_optimizer_options(section);
}

TEST(OptimizerOptions, DefaultsAreValid) {
  OptimizerOptions o;
  EXPECT_NO_THROW(o.validate());
  EXPECT_EQ(o.algorithm, "cobyla");
  EXPECT_EQ(o.max_evaluations, 1000);
  EXPECT_EQ(o.finite_difference, FiniteDifference::Forward);
  EXPECT_FALSE(o.target.has_value());
}

TEST(OptimizerOptions, ReadsEveryKey) {
  const OptimizerOptions o = read(
      "optimizer:\n  algorithm: AugLag\n  local_algorithm: slsqp\n  max_evaluations: 250\n  max_time_s: 60\n"
      "  max_iterations: 40\n  xtol_rel: 1e-5\n  ftol_rel: 1e-7\n  ftol_abs: 1e-9\n  target: 0.5\n"
      "  constraint_tolerance: 1e-4\n  finite_difference: central\n  fd_relative_step: 1e-3\n  seed: 42\n"
      "  population: 30\n  initial_step: 0.1\n  print_level: 5\n  handle_sigint: false\n  keep_history: false\n");
  EXPECT_EQ(o.algorithm, "AugLag");
  EXPECT_EQ(o.local_algorithm, "slsqp");
  EXPECT_EQ(o.max_evaluations, 250);
  EXPECT_EQ(o.max_time_s, 60);
  EXPECT_EQ(o.max_iterations, 40);
  EXPECT_EQ(o.xtol_rel, 1e-5);
  EXPECT_EQ(o.ftol_rel, 1e-7);
  EXPECT_EQ(o.ftol_abs, 1e-9);
  EXPECT_EQ(o.target, 0.5);
  EXPECT_EQ(o.constraint_tolerance, 1e-4);
  EXPECT_EQ(o.finite_difference, FiniteDifference::Central);
  EXPECT_EQ(o.fd_relative_step, 1e-3);
  EXPECT_EQ(o.seed, 42u);
  EXPECT_EQ(o.population, 30);
  EXPECT_EQ(o.initial_step, 0.1);
  EXPECT_EQ(o.print_level, 5);
  EXPECT_FALSE(o.handle_sigint);
  EXPECT_FALSE(o.keep_history);
}

TEST(OptimizerOptions, AbsentSectionGivesDefaults) {
  const OptimizerOptions o = read("other: 1\n");
  EXPECT_EQ(o.algorithm, "cobyla");
}

TEST(OptimizerOptions, UnknownAlgorithmListsTheValidNames) {
  const std::string msg = error_of([] { read("optimizer:\n  algorithm: cobila\n"); });
  EXPECT_EQ(msg.rfind("optimizer.algorithm = cobila: unknown algorithm; valid (case-insensitive): COBYLA, BOBYQA, ", 0),
            0u)
      << msg;
  for (const auto& name : algorithm_names()) EXPECT_NE(msg.find(name), std::string::npos) << name;
  EXPECT_EQ(error_of([] {
              OptimizerOptions o;
              o.local_algorithm = "direct_l";
              o.validate();
            }),
            "optimizer.local_algorithm = direct_l: must be a local algorithm (not global or AUGLAG)");
}

TEST(OptimizerOptions, BadValuesNameKeyValueAndRule) {
  EXPECT_EQ(error_of([] { read("optimizer:\n  max_evaluations: 0\n"); }), "optimizer.max_evaluations = 0: must be > 0");
  EXPECT_EQ(error_of([] { read("optimizer:\n  finite_difference: backward\n"); }),
            "optimizer.finite_difference = backward: must be one of: forward, central");
  EXPECT_EQ(error_of([] { read("optimizer:\n  max_evals: 10\n"); }),
            "optimizer.max_evals = 10: unknown key (misspelt, or not valid here)");
  EXPECT_EQ(error_of([] {
              OptimizerOptions o;
              o.xtol_rel = -1;
              o.validate();
            }),
            "optimizer.xtol_rel = -1: must be >= 0");
  EXPECT_EQ(error_of([] {
              OptimizerOptions o;
              o.fd_relative_step = 0.7;
              o.validate();
            }),
            "optimizer.fd_relative_step = 0.7: must be in [0, 0.5) (0: automatic)");
}

TEST(Algorithms, NamesAreCaseInsensitive) {
  EXPECT_EQ(find_algorithm("neldermead").name, "NELDERMEAD");
  EXPECT_EQ(find_algorithm("Ipopt").name, "IPOPT");
  EXPECT_TRUE(find_algorithm("slsqp").equality_constraints);
  EXPECT_FALSE(find_algorithm("mma").equality_constraints);
  EXPECT_TRUE(find_algorithm("auglag").needs_local);
  EXPECT_EQ(algorithm_names().size(), algorithms().size());
  EXPECT_EQ(find_algorithm("sao").name, "SAO");
  EXPECT_TRUE(find_algorithm("Sao").inequality_constraints);
}

// SAO is an algorithm name like the others; its settings come from optimizer.sao or from a
// section the caller passes (e.g. a top-level sao:), never both, and only with algorithm SAO.
TEST(OptimizerOptions, SaoSettingsFromTheNestedOrAPassedSection) {
  OptimizerOptions o = read("optimizer:\n  algorithm: SAO\n  sao: {initial_radius: 0.2, doe_points_factor: 2}\n");
  EXPECT_EQ(o.algorithm, "SAO");
  EXPECT_DOUBLE_EQ(o.sao.initial_radius, 0.2);
  EXPECT_DOUBLE_EQ(o.sao.doe_points_factor, 2.0);
  EXPECT_DOUBLE_EQ(read("optimizer:\n  algorithm: sao\n").sao.initial_radius, SaoOptions{}.initial_radius);

  YamlReader root = YamlReader::load_string("optimizer: {algorithm: sao}\nsao: {max_radius: 0.7}\n");
  YamlReader section = root.child("optimizer");
  YamlReader outer = root.child("sao");
  EXPECT_DOUBLE_EQ(read_optimizer_options(section, &outer).sao.max_radius, 0.7);

  EXPECT_EQ(error_of([] { read("optimizer:\n  algorithm: cobyla\n  sao: {initial_radius: 0.2}\n"); }),
            "optimizer.sao = <section>: only used with optimizer.algorithm: SAO (algorithm is cobyla)");
  EXPECT_EQ(error_of([] { read("optimizer:\n  algorithm: sao\n  sao: {min_radius: 0}\n"); }),
            "optimizer.sao.min_radius = 0: must be in (0, initial_radius = 0.1]");
  EXPECT_EQ(error_of([] { read("optimizer:\n  algorithm: sao\n  sao: {radius: 1}\n"); }).rfind("optimizer.sao.radius", 0),
            0u);
  EXPECT_EQ(error_of([] {
              YamlReader r = YamlReader::load_string("optimizer: {algorithm: sao, sao: {}}\nsao: {max_radius: 0.7}\n");
              YamlReader s = r.child("optimizer");
              YamlReader t = r.child("sao");
              read_optimizer_options(s, &t);
            }).rfind("optimizer.sao = <section>: SAO settings are given twice", 0),
            0u);
  EXPECT_EQ(error_of([] {
              OptimizerOptions bad;
              bad.local_algorithm = "sao";
              bad.validate();
            }),
            "optimizer.local_algorithm = sao: SAO cannot be a local algorithm of NLopt");
  EXPECT_EQ(error_of([] {
              OptimizerOptions bad;
              bad.algorithm = "SAO";
              bad.sao.shrink_factor = 2;
              bad.validate();
            }),
            "sao.shrink_factor = 2: must be in (0, 1)");
}

}  // namespace

namespace {

// read -> write -> read gives the same options (the one field list serves both), for a config
// with every key away from its default, SAO settings included.
TEST(OptimizerOptions, RoundTripThroughTheFieldList) {
  const OptimizerOptions a = read(
      "optimizer:\n  algorithm: SAO\n  max_evaluations: 77\n  max_time_s: 12.5\n  max_iterations: 9\n"
      "  xtol_rel: 1.0e-4\n  ftol_rel: 0\n  ftol_abs: 0.001\n  target: -3.25\n  constraint_tolerance: 1.0e-5\n"
      "  finite_difference: central\n  fd_relative_step: 0.001\n  seed: 42\n  population: 12\n"
      "  initial_step: 0.2\n  print_level: 3\n  handle_sigint: false\n  keep_history: false\n"
      "  sao: {surrogate: kriging, doe: lhs, doe_points: 7, initial_radius: 0.2, max_radius: 0.8,\n"
      "        intervening: reciprocal, intervening_objective: linear, subproblem_solver: cobyla,\n"
      "        correction: false, kriging_nugget: 0.01, stall_iterations: 3}\n");
  const std::string text = to_yaml(a);
  const OptimizerOptions b = read("optimizer:\n" + [&] {
    std::string indented;
    std::size_t start = 0;
    while (start < text.size()) {
      const std::size_t end = text.find('\n', start);
      indented += "  " + text.substr(start, end - start) + "\n";
      start = end + 1;
    }
    return indented;
  }());
  EXPECT_EQ(to_yaml(b), text);
  EXPECT_EQ(b.max_evaluations, 77);
  EXPECT_EQ(b.target, -3.25);
  EXPECT_EQ(b.finite_difference, FiniteDifference::Central);
  EXPECT_EQ(b.seed, 42u);
  EXPECT_FALSE(b.keep_history);
  EXPECT_EQ(b.sao.surrogate, SurrogateKind::Kriging);
  EXPECT_EQ(b.sao.doe_points, 7);
  EXPECT_EQ(b.sao.intervening, InterveningKind::Reciprocal);
  EXPECT_EQ(b.sao.intervening_objective, InterveningKind::Linear);
  EXPECT_FALSE(b.sao.intervening_constraints.has_value());
  EXPECT_EQ(b.sao.subproblem_solver, SubproblemSolver::Cobyla);
  EXPECT_FALSE(b.sao.correction);
  EXPECT_EQ(b.sao.kriging_nugget, 0.01);
  // the defaults round-trip too, and a non-SAO algorithm writes no sao section
  const OptimizerOptions d;
  EXPECT_EQ(to_yaml(d).find("sao"), std::string::npos);
  EXPECT_NE(to_yaml(d).find("algorithm: cobyla"), std::string::npos);
}

}  // namespace
