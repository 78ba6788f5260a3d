// The SUNDIALS ARKODE (ERKStep) integrator back end: the reference implementation.
#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "abuopt/common/config_error.hpp"
#include "integrator.hpp"

namespace abuopt::detail {

namespace {

int rhs_arkode(sunrealtype tbar, N_Vector yv, N_Vector ydotv, void* user) {
  rhs_plain(tbar, N_VGetArrayPointer(yv), N_VGetArrayPointer(ydotv), user);
  return 0;
}

int roots_arkode(sunrealtype tbar, N_Vector yv, sunrealtype* g, void* user) {
  roots_plain(tbar, N_VGetArrayPointer(yv), g, user);
  return 0;
}

void silent_arkode_errors(int, const char*, const char*, char*, void*) {}

// SUNDIALS ARKODE ERKStep with its own root finding: the reference implementation.
class ArkodeIntegrator final : public Integrator {
 public:
  ArkodeIntegrator(RunState& rs, std::size_t nvar, bool with_roots) : nvar_(nvar), nroots_(with_roots ? 2 * rs.n : 0) {
    if (SUNContext_Create(nullptr, &ctx_) != 0) throw std::runtime_error("SUNContext_Create failed");
    y_ = N_VNew_Serial(static_cast<sunindextype>(nvar), ctx_);
    mem_ = ERKStepCreate(rhs_arkode, 0.0, y_, ctx_);
    if (!mem_) throw std::runtime_error("ERKStepCreate failed");
    ERKStepSetErrHandlerFn(mem_, silent_arkode_errors, nullptr);
    ERKStepSetUserData(mem_, &rs);
    ERKStepSStolerances(mem_, rs.opt.rtol, rs.opt.atol);
    if (ERKStepSetTableName(mem_, rs.opt.erk_table.c_str()) != ARK_SUCCESS)
      throw ConfigError("simulation.erk_table", rs.opt.erk_table, "must be an ARKODE explicit table name");
    ERKStepSetMaxNumSteps(mem_, rs.opt.max_steps);
    if (nroots_) {
      ERKStepRootInit(mem_, static_cast<int>(nroots_), roots_arkode);
      ERKStepSetNoInactiveRootWarn(mem_);
    }
  }
  ~ArkodeIntegrator() override {
    if (mem_) ERKStepFree(&mem_);
    if (y_) N_VDestroy(y_);
    if (ctx_) SUNContext_Free(&ctx_);
  }
  ArkodeIntegrator(const ArkodeIntegrator&) = delete;
  ArkodeIntegrator& operator=(const ArkodeIntegrator&) = delete;

  void reset(double t, const std::vector<double>& y) override {
    std::copy(y.begin(), y.end(), N_VGetArrayPointer(y_));
    ERKStepReset(mem_, t, y_);
  }
  void set_stop(double t) override {
    tstop_ = t;
    ERKStepSetStopTime(mem_, t);
  }
  Result step(double& t, std::vector<double>& y, std::vector<int>& roots) override {
    flag_ = ERKStepEvolve(mem_, tstop_, y_, &t, ARK_ONE_STEP);
    const double* p = N_VGetArrayPointer(y_);
    std::copy(p, p + nvar_, y.begin());
    if (flag_ < 0) return Failure;
    if (flag_ == ARK_ROOT_RETURN) {
      roots.resize(nroots_);
      ERKStepGetRootInfo(mem_, roots.data());
      return Root;
    }
    return Ok;
  }
  void dense(double t, std::vector<double>& out) override {
    N_Vector o = N_VMake_Serial(static_cast<sunindextype>(nvar_), out.data(), ctx_);
    ERKStepGetDky(mem_, t, 0, o);
    N_VDestroy(o);
  }
  long steps() const override {
    long s = 0;
    ERKStepGetNumSteps(mem_, &s);
    return s;
  }
  std::string failure() const override {
    char* name = ERKStepGetReturnFlagName(flag_);
    std::string s = std::string("ARKODE ") + (name ? name : "error");
    free(name);
    return s;
  }
  bool too_much_work() const override { return flag_ == ARK_TOO_MUCH_WORK; }

 private:
  std::size_t nvar_, nroots_;
  SUNContext ctx_ = nullptr;
  N_Vector y_ = nullptr;
  void* mem_ = nullptr;
  double tstop_ = 0;
  int flag_ = 0;
};

}  // namespace

std::unique_ptr<Integrator> make_arkode_integrator(RunState& rs, std::size_t nvar, bool with_roots) {
  return std::make_unique<ArkodeIntegrator>(rs, nvar, with_roots);
}

}  // namespace abuopt::detail
