// The native integrator back end: erk_stepper.hpp behind the simulator's Integrator interface.
#include <stdexcept>

#include "abuopt/common/config_error.hpp"
#include "erk_stepper.hpp"
#include "integrator.hpp"

namespace abuopt::detail {

namespace {

// Native stepper (erk_stepper.hpp): ARKODE's tables without ARKODE's per-step overhead.
class NativeIntegrator final : public Integrator {
 public:
  NativeIntegrator(RunState& rs, std::size_t nvar, bool with_roots)
      : st_(table_for(rs.opt.erk_table), nvar, rhs_plain,
            with_roots ? (rs.contact ? roots_contact : roots_plain) : nullptr, with_roots ? rs.nroots() : 0, &rs, rs.opt.rtol, rs.opt.atol, rs.opt.max_steps) {
    st_.set_polish_roots(rs.contact);  // contact events need exact times (docs/model.md 11.5)
    if (with_roots && rs.contact) {
      st_.set_root_rates(root_rates_contact);  // gaps that close and open in a step
      st_.set_dip_rates(stop_rates_contact);   // clusters that reverse and back in a step (11.11)
    }
  }
  void reset(double t, const std::vector<double>& y) override { st_.reset(t, y.data()); }
  void set_stop(double t) override { st_.set_stop_time(t); }
  Result step(double& t, std::vector<double>& y, std::vector<int>& roots) override {
    last_ = st_.step();
    t = st_.t();
    y = st_.y();
    if (last_ == ErkStepper::Root) {
      roots = st_.roots_found();
      return Root;
    }
    return last_ < 0 ? Failure : Ok;
  }
  void dense(double t, std::vector<double>& out) override { st_.dense(t, out.data()); }
  long steps() const override { return st_.steps(); }
  std::string failure() const override {
    if (last_ == ErkStepper::TooManySteps) return "step limit reached";
    if (last_ == ErkStepper::NotFinite) return "state or step size not finite";
    return "step size became too small";
  }
  bool too_much_work() const override { return last_ == ErkStepper::TooManySteps; }

 private:
  static ButcherTable table_for(const std::string& name) {
    try {
      return ButcherTable::from_arkode(name);
    } catch (const std::invalid_argument& e) {
      throw ConfigError("simulation.erk_table", name, "must be an ARKODE explicit table with an embedding");
    }
  }
  ErkStepper st_;
  ErkStepper::Status last_ = ErkStepper::Ok;
};

}  // namespace

std::unique_ptr<Integrator> make_native_integrator(RunState& rs, std::size_t nvar, bool with_roots) {
  return std::make_unique<NativeIntegrator>(rs, nvar, with_roots);
}

}  // namespace abuopt::detail
