// SAO's polish of a sampled problem (docs/sao.md, "Polish on a sampled problem"): a trust region
// that shrinks below 1e-3 of the ranges (or stalls) hands over to a compass search on the exact
// merit whose steps snap to the bounds; only on sampled problems with the global phase on, and
// only when asked for (`global_phase: {polish: true}`; off by default).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <string>
#include <vector>

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/yaml_reader.hpp"
#include "abuopt/optimizer/sao.hpp"
#include "two_basins.hpp"

namespace {

using namespace abuopt;

bool same_history(const opt::OptimizationResult& a, const opt::OptimizationResult& b) {
  if (a.history.size() != b.history.size()) return false;
  for (std::size_t i = 0; i < a.history.size(); ++i)
    if (a.history[i].x != b.history[i].x || a.history[i].objective != b.history[i].objective) return false;
  return true;
}

// A piecewise-constant response with its minimum on a corner of the box, as a Monte Carlo under
// common random numbers is (docs/sao.md, "The large comparison"): a staircase of steps 1/16 in
// d = max(1 - x, y) (ceil(16 d) / 16: 0 only at the corner x = 1, y = 0) plus jumps on a grid of
// cells 0.01 wide, of height in [0, 0.03) from a hash of the cell (smaller than one stair, so the
// corner is the one global minimum: f(corner) < 0.03 < 1/16 <= f elsewhere). Declares itself
// sampled (sample_size 64), so SAO's global phase is on by default.
class CornerStaircase : public opt::FunctionProblem {
 public:
  CornerStaircase()
      : opt::FunctionProblem(
            "corner_staircase", std::vector<opt::Variable>{{"x", 0, 1, 1}, {"y", 0, 1, 1}},
            [](const std::vector<double>& v) {
              opt::Evaluation e;
              e.objective = stairs(v) + jumps(v);
              return e;
            }) {
    set_initial_point({0.3, 0.6});
    set_thread_safe(true);
  }
  std::size_t sample_size() const override { return 64; }
  static double stairs(const std::vector<double>& v) { return std::ceil(16 * std::max(1 - v[0], v[1])) / 16; }
  static double jumps(const std::vector<double>& v) {
    std::uint64_t h = static_cast<std::uint64_t>(std::floor(100 * v[0])) * 1000003ULL +
                      static_cast<std::uint64_t>(std::floor(100 * v[1]));
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    return 0.03 * static_cast<double>(h % 1000) / 1000.0;
  }
};

// With the polish the run reaches the corner exactly (the trust region, clipped by the box, and the
// compass steps, snapped to the bounds, both can) and the result is stationary for the polish's
// last step (0.1 / 2^6 of the ranges): no compass neighbour at that step is lower. The runs with
// and without the polish (the default) agree until the first trust region hands over.
TEST(SaoPolish, ReachesTheCornerOfAPiecewiseConstantResponse) {
  opt::OptimizerOptions o;
  o.max_evaluations = 80;
  opt::SaoOptions on;
  on.global_phase.polish = true;
  CornerStaircase p1, p2;
  const auto with = opt::minimize_sao(p1, o, on);
  const auto without = opt::minimize_sao(p2, o, opt::SaoOptions{});
  std::cout << "[measure] corner staircase, 80 evaluations: polish " << with.brief_report() << " at (" << with.x[0]
            << ", " << with.x[1] << "); no polish " << without.brief_report() << "\n";
  std::cout << "[measure] messages: polish '" << with.message << "'; no polish '" << without.message << "'\n";
  EXPECT_FALSE(same_history(with, without));  // the polish ran ...
  EXPECT_NE(with.message.find("polish"), std::string::npos);  // ... and ended the run
  ASSERT_EQ(with.x.size(), 2u);
  EXPECT_EQ(with.x[0], 1.0);
  EXPECT_EQ(with.x[1], 0.0);
  EXPECT_EQ(with.objective, CornerStaircase::jumps({1.0, 0.0}));
  const double last_step = 0.1 / 64;
  for (int i = 0; i < 2; ++i)
    for (double dir : {1.0, -1.0}) {
      std::vector<double> x = with.x;
      x[i] = std::clamp(x[i] + dir * last_step, 0.0, 1.0);
      EXPECT_GE(CornerStaircase::stairs(x) + CornerStaircase::jumps(x), with.objective);
    }
  ASSERT_FALSE(without.history.empty());
  std::size_t same = 0;
  while (same < std::min(with.history.size(), without.history.size()) &&
         with.history[same].x == without.history[same].x)
    ++same;
  EXPECT_GE(same, 25u);  // at least the start and the global phase (4 (n + 1) = 12 + 12 points)
}

// Only sampled problems polish: a stochastic problem that is not sampled (the noisy benchmarks:
// deterministic pseudo-noise) and a deterministic one run evaluation for evaluation as without it.
TEST(SaoPolish, OnlySampledProblems) {
  opt::OptimizerOptions o;
  o.max_evaluations = 70;
  opt::SaoOptions on;
  on.global_phase.polish = true;
  for (bool stochastic : {true, false}) {
    test::TwoBasins p1(stochastic), p2(stochastic);
    EXPECT_TRUE(same_history(opt::minimize_sao(p1, o, on), opt::minimize_sao(p2, o, opt::SaoOptions{})));
  }
}

TEST(SaoPolish, OptionIsReadAndWritten) {
  auto parsed = [](const std::string& text) {
    YamlReader root = YamlReader::load_string("sao:\n  " + text + "\n");
    YamlReader section = root.child("sao");
    return opt::read_sao_options(section);
  };
  EXPECT_FALSE(opt::SaoOptions{}.global_phase.polish);
  EXPECT_TRUE(parsed("global_phase: {polish: true}").global_phase.polish);
  EXPECT_NE(opt::to_yaml(opt::SaoOptions{}).find("polish: false"), std::string::npos);
  EXPECT_THROW(parsed("global_phase: {polish: 3}"), ConfigError);
}

}  // namespace
