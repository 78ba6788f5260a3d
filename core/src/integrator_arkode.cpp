// The SUNDIALS ARKODE (ERKStep) integrator back end: the reference implementation.
#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "abuopt/common/config_error.hpp"
#include "integrator.hpp"

namespace abuopt::detail {

namespace {

bool all_finite(const double* v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

// ARKODE's right-hand side: a non-finite state is unrecoverable (-1); a finite state whose
// derivative is not finite is a recoverable failure (1: ARKODE retries with a smaller step).
int rhs_arkode(sunrealtype tbar, N_Vector yv, N_Vector ydotv, void* user) {
  const double* y = N_VGetArrayPointer(yv);
  double* yd = N_VGetArrayPointer(ydotv);
  const std::size_t n = static_cast<std::size_t>(N_VGetLength_Serial(yv));
  if (!all_finite(y, n)) return -1;
  rhs_plain(tbar, y, yd, user);
  return all_finite(yd, n) ? 0 : 1;
}

int roots_arkode(sunrealtype tbar, N_Vector yv, sunrealtype* g, void* user) {
  if (static_cast<RunState*>(user)->contact)
    roots_contact(tbar, N_VGetArrayPointer(yv), g, user);
  else
    roots_plain(tbar, N_VGetArrayPointer(yv), g, user);
  return 0;
}

void silent_arkode_errors(int, const char*, const char*, char*, void*) {}

std::string flag_name(int flag) {
  char* name = ERKStepGetReturnFlagName(flag);
  std::string s = name ? name : "error " + std::to_string(flag);
  free(name);
  return s;
}

// Setup calls cannot fail with validated options and a working SUNDIALS: a failure is a
// programming or environment error (SUNDIALS examples' check_flag, turned into an exception).
void check(int flag, const char* call) {
  if (flag < 0) throw std::runtime_error(std::string("ARKODE ") + call + " failed: " + flag_name(flag));
}
template <class P>
P* check_ptr(P* p, const char* call) {
  if (!p) throw std::runtime_error(std::string("SUNDIALS ") + call + " returned no object");
  return p;
}

struct ContextFree {
  void operator()(SUNContext c) const { SUNContext_Free(&c); }
};
struct VectorFree {
  void operator()(N_Vector v) const { N_VDestroy(v); }
};
struct ErkStepFree {
  void operator()(void* m) const { ERKStepFree(&m); }
};

// SUNDIALS ARKODE ERKStep with its own root finding: the reference implementation. Every SUNDIALS
// object is owned (unique_ptr), so a constructor that throws (bad erk_table) leaks nothing; every
// return code is checked: setup failures throw, failures while stepping end the run with a status.
class ArkodeIntegrator final : public Integrator {
 public:
  ArkodeIntegrator(RunState& rs, std::size_t nvar, bool with_roots) : nvar_(nvar), nroots_(with_roots ? rs.nroots() : 0) {
    SUNContext ctx = nullptr;
    check(SUNContext_Create(nullptr, &ctx), "SUNContext_Create");
    ctx_.reset(check_ptr(ctx, "SUNContext_Create"));
    y_.reset(check_ptr(N_VNew_Serial(static_cast<sunindextype>(nvar), ctx_.get()), "N_VNew_Serial"));
    mem_.reset(check_ptr(ERKStepCreate(rhs_arkode, 0.0, y_.get(), ctx_.get()), "ERKStepCreate"));
    check(ERKStepSetErrHandlerFn(mem_.get(), silent_arkode_errors, nullptr), "ERKStepSetErrHandlerFn");
    check(ERKStepSetUserData(mem_.get(), &rs), "ERKStepSetUserData");
    check(ERKStepSStolerances(mem_.get(), rs.opt.rtol, rs.opt.atol), "ERKStepSStolerances");
    if (ERKStepSetTableName(mem_.get(), rs.opt.erk_table.c_str()) != ARK_SUCCESS)
      throw ConfigError("simulation.erk_table", rs.opt.erk_table, "must be an ARKODE explicit table name");
    check(ERKStepSetMaxNumSteps(mem_.get(), rs.opt.max_steps), "ERKStepSetMaxNumSteps");
    // The switch model's right-hand side jumps where a ball's speed crosses the band: a step across
    // the jump passes the error test only below h ~ tol / jump, which ARKODE's default of 7 failed
    // tests (the step cut to 0.3 from the third on) does not reach: ARK_ERR_FAILURE. 50 failures
    // reach 1e-24 of the step, like the native stepper, which cuts without a count limit.
    check(ERKStepSetMaxErrTestFails(mem_.get(), 50), "ERKStepSetMaxErrTestFails");
    if (nroots_) {
      check(ERKStepRootInit(mem_.get(), static_cast<int>(nroots_), roots_arkode), "ERKStepRootInit");
      check(ERKStepSetNoInactiveRootWarn(mem_.get()), "ERKStepSetNoInactiveRootWarn");
    }
  }

  void reset(double t, const std::vector<double>& y) override {
    std::copy(y.begin(), y.end(), N_VGetArrayPointer(y_.get()));
    note(ERKStepReset(mem_.get(), t, y_.get()), "ERKStepReset");
  }
  void set_stop(double t) override {
    tstop_ = t;
    note(ERKStepSetStopTime(mem_.get(), t), "ERKStepSetStopTime");
  }
  Result step(double& t, std::vector<double>& y, std::vector<int>& roots) override {
    if (pending_ < 0) {  // a reset or stop time failed: end the run here
      flag_ = pending_;
      return Failure;
    }
    flag_ = ERKStepEvolve(mem_.get(), tstop_, y_.get(), &t, ARK_ONE_STEP);
    const double* p = N_VGetArrayPointer(y_.get());
    if (flag_ >= 0 && !all_finite(p, nvar_)) flag_ = ARK_RHSFUNC_FAIL;
    if (flag_ < 0) return Failure;  // y keeps the last state that was accepted
    std::copy(p, p + nvar_, y.begin());
    if (flag_ == ARK_ROOT_RETURN) {
      roots.resize(nroots_);
      flag_ = ERKStepGetRootInfo(mem_.get(), roots.data());
      if (flag_ < 0) {
        failed_call_ = "ERKStepGetRootInfo";
        return Failure;
      }
      return Root;
    }
    return Ok;
  }
  void dense(double t, std::vector<double>& out) override {
    N_Vector o = N_VMake_Serial(static_cast<sunindextype>(nvar_), out.data(), ctx_.get());
    const int flag = o ? ERKStepGetDky(mem_.get(), t, 0, o) : ARK_MEM_FAIL;
    if (o) N_VDestroy(o);
    if (flag < 0) std::fill(out.begin(), out.end(), std::numeric_limits<double>::quiet_NaN());
    note(flag, "ERKStepGetDky");
  }
  long steps() const override {
    long s = 0;
    return ERKStepGetNumSteps(mem_.get(), &s) == ARK_SUCCESS ? s : 0;
  }
  std::string failure() const override {
    if (flag_ == ARK_RHSFUNC_FAIL || flag_ == ARK_UNREC_RHSFUNC_ERR || flag_ == ARK_REPTD_RHSFUNC_ERR)
      return "state or derivative not finite (ARKODE " + flag_name(flag_) + ")";
    return std::string("ARKODE ") + (failed_call_.empty() ? "" : failed_call_ + ": ") + flag_name(flag_);
  }
  bool too_much_work() const override { return flag_ == ARK_TOO_MUCH_WORK; }

 private:
  // Remembers the first failure of a call between steps; the next step() reports it.
  void note(int flag, const char* call) {
    if (flag < 0 && pending_ >= 0) {
      pending_ = flag;
      failed_call_ = call;
    }
  }
  std::size_t nvar_, nroots_;
  // declaration order = reverse destruction order: the stepper goes first, the context last
  std::unique_ptr<std::remove_pointer_t<SUNContext>, ContextFree> ctx_;
  std::unique_ptr<std::remove_pointer_t<N_Vector>, VectorFree> y_;
  std::unique_ptr<void, ErkStepFree> mem_;
  double tstop_ = 0;
  int flag_ = 0, pending_ = 0;
  std::string failed_call_;
};

}  // namespace

std::unique_ptr<Integrator> make_arkode_integrator(RunState& rs, std::size_t nvar, bool with_roots) {
  return std::make_unique<ArkodeIntegrator>(rs, nvar, with_roots);
}

}  // namespace abuopt::detail
