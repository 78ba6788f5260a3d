#pragma once
// The integrator back ends of the simulator: the native stepper (integrator_native.cpp) and
// SUNDIALS ARKODE (integrator_arkode.cpp), behind one interface.
#include <memory>
#include <string>
#include <vector>

#include "sim_run_state.hpp"

namespace abuopt::detail {

// The simulator's view of an integrator: one accepted step at a time, stopping at roots of the
// stick/slip functions and at a stop time.
class Integrator {
 public:
  enum Result { Ok, Root, Failure };
  virtual ~Integrator() = default;
  virtual void reset(double t, const std::vector<double>& y) = 0;
  virtual void set_stop(double t) = 0;
  virtual Result step(double& t, std::vector<double>& y, std::vector<int>& roots) = 0;
  virtual void dense(double t, std::vector<double>& out) = 0;
  virtual long steps() const = 0;
  virtual std::string failure() const = 0;
  virtual bool too_much_work() const = 0;
};

std::unique_ptr<Integrator> make_native_integrator(RunState& rs, std::size_t nvar, bool with_roots);
std::unique_ptr<Integrator> make_arkode_integrator(RunState& rs, std::size_t nvar, bool with_roots);

inline std::unique_ptr<Integrator> make_integrator(RunState& rs, std::size_t nvar, bool with_roots) {
  if (rs.opt.backend == IntegratorBackend::Native) return make_native_integrator(rs, nvar, with_roots);
  return make_arkode_integrator(rs, nvar, with_roots);
}

}  // namespace abuopt::detail
