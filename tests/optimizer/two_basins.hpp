#pragma once
// The two-basins test problem shared by sao_global_test.cpp and sao_restart_test.cpp: a shallow
// basin at (0.2, 0.2) (f = -1) around the start (0.25, 0.15) and a deeper one at (0.8, 0.7)
// (f = -2), both inside the constraint x + y <= 1.6; the global optimum is the deep one.
// `stochastic` only changes what the problem declares (Problem::stochastic()), not its values.
#include <cmath>
#include <string>
#include <vector>

#include "abuopt/optimizer/problem.hpp"

namespace abuopt::test {

class TwoBasins : public opt::FunctionProblem {
 public:
  explicit TwoBasins(bool stochastic)
      : opt::FunctionProblem(
            "two_basins", std::vector<opt::Variable>{{"x", 0, 1, 1}, {"y", 0, 1, 1}},
            [](const std::vector<double>& x) {
              auto bump = [&](double cx, double cy) {
                return std::exp(-((x[0] - cx) * (x[0] - cx) + (x[1] - cy) * (x[1] - cy)) / 0.02);
              };
              opt::Evaluation e;
              e.objective = -bump(0.2, 0.2) - 2 * bump(0.8, 0.7);
              e.inequality = {x[0] + x[1] - 1.6};
              return e;
            },
            std::vector<std::string>{"sum"}),
        stochastic_(stochastic) {
    set_initial_point({0.25, 0.15});
    set_thread_safe(true);
  }
  bool stochastic() const override { return stochastic_; }

 private:
  bool stochastic_;
};

}  // namespace abuopt::test
