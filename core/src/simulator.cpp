// Event-driven simulation of one ABU startup (see simulator.hpp and docs/model.md).
//
// Integration runs in non-dimensional time tbar = omega_n t with SUNDIALS ARKODE (explicit
// ERKStep, a high-order table) in one-step mode. Each ball owns two root functions:
//   slipping ball:  g_a = sigma_i beta_i'             (slip -> stick candidate when it reaches 0)
//                   g_b = 1                            (unused)
//   stuck ball:     g_a = mu fn_i - fw_i + off_a       (stick -> slip forward)
//                   g_b = mu fn_i + fw_i + off_b       (stick -> slip backward)
// The offsets are zero unless a stick phase starts with a (numerically) negative margin: then the
// margin is shifted so that it starts positive and its later crossing is still seen. At every
// root the modes of all balls are chosen together (AbuModel::choose_modes) and the integrator is
// reset. After the profile ends with every ball stuck (ideal motor), the table motion is linear
// and time-invariant; if a bound on its transient proves that no stick margin can reach zero, the
// run is finished in closed form (closed_form_tail).
#include "abuopt/core/simulator.hpp"

#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <deque>
#include <memory>
#include <stdexcept>
#include <sstream>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/abu_model.hpp"
#include "abuopt/core/simulation_config.hpp"
#include "erk_stepper.hpp"

namespace abuopt {

std::string to_string(FrictionMethod m) { return m == FrictionMethod::EventDriven ? "event_driven" : "switch_model"; }
std::string to_string(IntegratorBackend b) { return b == IntegratorBackend::ArkodeErk ? "arkode_erk" : "native"; }
std::string to_string(RunStatus s) {
  switch (s) {
    case RunStatus::Ok: return "ok";
    case RunStatus::SolverFailure: return "solver_failure";
    case RunStatus::ChatterLimit: return "chatter_limit";
    case RunStatus::StepLimit: return "step_limit";
  }
  return "unknown";
}

namespace {

constexpr double kTwoPi = 2.0 * M_PI;

double wrap_angle(double a) {
  double r = std::fmod(a, kTwoPi);
  if (r < 0) r += kTwoPi;
  if (r >= kTwoPi) r = 0;
  return r;
}

// Everything one run needs; ARKODE's user data.
struct RunState {
  AbuParameters params;  // with the run's overrides applied
  NondimParameters nd;
  AbuModel model;
  const StartupProfile* profile = nullptr;
  MotorModel motor;
  SimulationOptions opt;
  double mu = 0;
  double omega_n = 0;
  std::size_t n = 0;
  std::size_t nstate = 0;  // ABU states (+2 motor states for the PI model)
  bool pi_motor = false;
  std::vector<BallMode> modes;
  ModelForces forces;
  std::vector<double> off_a, off_b;
  long rhs_evals = 0;
  // Fast path while every ball is stuck (event-driven, ideal motor): beta' = beta'' = 0, so the
  // table rows reduce to x'' = -h_x, y'' = -h_y with the ball sums sum mbar_i (c_i, s_i) fixed.
  // The full evaluation is still used for the root functions (they need fn, fw).
  bool frozen = false;
  double frozen_sc = 0, frozen_ss = 0;

  explicit RunState(const AbuParameters& p) : params(p), nd(NondimParameters::from(p)), model(nd) {}

  // Call whenever the modes change (event-driven only).
  void modes_changed(const double* y) {
    frozen = !pi_motor && opt.method == FrictionMethod::EventDriven;
    frozen_sc = frozen_ss = 0;
    for (std::size_t i = 0; i < n && frozen; ++i) {
      frozen = modes[i] == BallMode::Stick;
      frozen_sc += nd.mbar[i] * std::cos(y[4 + i]);
      frozen_ss += nd.mbar[i] * std::sin(y[4 + i]);
    }
  }
};

struct Speed {
  double W = 0, Wp = 0;
};

Speed ideal_speed(const RunState& rs, double tbar) {
  const ProfileSample s = rs.profile->sample(tbar / rs.omega_n);
  return {kTwoPi * s.frequency_hz / rs.omega_n, kTwoPi * s.rate_hz_per_s / (rs.omega_n * rs.omega_n)};
}

// Evaluates forces for the current modes into rs.forces and returns the speed used. For the PI
// motor, W comes from the state and W' from the motor equation, whose friction feedback is
// resolved by a short fixed-point iteration (the coupling m_i L^2 / J is ~1e-3: two passes
// converge to rounding).
Speed evaluate_forces(RunState& rs, double tbar, const double* y) {
  if (!rs.pi_motor) {
    const Speed sp = ideal_speed(rs, tbar);
    rs.model.evaluate(y, sp.W, sp.Wp, rs.modes.data(), rs.mu, rs.forces);
    return sp;
  }
  // PI motor: states y[nabu] = delta = theta_ref - theta [rad], y[nabu+1] = W.
  const std::size_t k = 4 + 2 * rs.n;
  const double W = y[k + 1];
  const double delta = y[k];
  const double t = tbar / rs.omega_n;
  const double f_ref = rs.motor.realised_reference_hz(rs.profile->frequency_hz(t));
  const double Omega = W * rs.omega_n;
  const double Omega_ref = kTwoPi * f_ref;
  const double wm = rs.motor.omega_m_rad_s;
  // Bearing torque T_b opposes rotation; regularised below 0.1 rad/s so the drive can start.
  const double load = -rs.motor.bearing_torque_Nm * std::clamp(Omega / 0.1, -1.0, 1.0);
  const double accel0 = 2.0 * rs.motor.xi * wm * (Omega_ref - Omega) + wm * wm * delta + load / rs.motor.inertia_kgm2;
  const double w2 = rs.omega_n * rs.omega_n;
  double Wp = accel0 / w2;
  rs.model.evaluate(y, W, Wp, rs.modes.data(), rs.mu, rs.forces);
  if (rs.motor.friction_feedback) {
    const double L = rs.params.ball_track_radius_m;
    for (int pass = 0; pass < 2; ++pass) {
      double torque = 0;  // reaction of the balls' friction (and viscous damping) on the disc
      for (std::size_t i = 0; i < rs.n; ++i)
        torque += (rs.forces.fw[i] + rs.nd.cbar[i] * y[4 + rs.n + i]) * rs.params.balls[i].mass_kg * w2 * L * L;
      Wp = (accel0 + torque / rs.motor.inertia_kgm2) / w2;
      rs.model.evaluate(y, W, Wp, rs.modes.data(), rs.mu, rs.forces);
    }
  }
  return {W, Wp};
}

// Switch model (Leine): a ball with |beta'| below the band is a stick candidate; modes are chosen
// at every right-hand-side call. A stuck ball's angle is frozen (the report reset beta' = 0 every
// step to the same effect).
void switch_modes(RunState& rs, double tbar, const double* y) {
  // The PI motor's W' depends on the modes through the friction feedback: the W' of the current
  // modes is used to choose the new ones.
  const Speed sp = rs.pi_motor ? evaluate_forces(rs, tbar, y) : ideal_speed(rs, tbar);
  rs.model.choose_modes(y, sp.W, sp.Wp, rs.mu, rs.opt.switch_band, rs.modes.data(), rs.forces);
}

void rhs_plain(double tbar, const double* y, double* yd, void* user) {
  auto& rs = *static_cast<RunState*>(user);
  ++rs.rhs_evals;
  if (rs.frozen) {
    const Speed sp = ideal_speed(rs, tbar);
    const double W = sp.W, Wp = sp.Wp, W2 = W * W, bb = rs.nd.bbar;
    const double x = y[0], yy = y[1], xd = y[2], ydd = y[3];
    const double hx = -2.0 * ydd * W - x * W2 - rs.nd.mbar_I * rs.nd.ebar * W2 - Wp * (yy + rs.frozen_ss) -
                      W2 * rs.frozen_sc + x + 2.0 * bb * (xd - yy * W);
    const double hy = 2.0 * xd * W - yy * W2 + Wp * (x + rs.nd.mbar_I * rs.nd.ebar + rs.frozen_sc) -
                      W2 * rs.frozen_ss + yy + 2.0 * bb * (ydd + x * W);
    yd[0] = xd;
    yd[1] = ydd;
    yd[2] = -hx;
    yd[3] = -hy;
    std::fill(yd + 4, yd + 4 + 2 * rs.n, 0.0);
    return;
  }
  if (rs.opt.method == FrictionMethod::SwitchModel) switch_modes(rs, tbar, y);
  const Speed sp = evaluate_forces(rs, tbar, y);
  const std::size_t n = rs.n;
  yd[0] = y[2];
  yd[1] = y[3];
  yd[2] = rs.forces.xdd;
  yd[3] = rs.forces.ydd;
  for (std::size_t i = 0; i < n; ++i) {
    const bool frozen = rs.modes[i] == BallMode::Stick;
    yd[4 + i] = frozen ? 0.0 : y[4 + n + i];
    yd[4 + n + i] = rs.forces.betadd[i];
  }
  if (rs.pi_motor) {
    const std::size_t k = 4 + 2 * n;
    const double t = tbar / rs.omega_n;
    const double W_ref = kTwoPi * rs.motor.realised_reference_hz(rs.profile->frequency_hz(t)) / rs.omega_n;
    yd[k] = (W_ref - y[k + 1]);  // d delta / dtbar = (Omega_ref - Omega)/omega_n
    yd[k + 1] = sp.Wp;
  }
}

int rhs_arkode(sunrealtype tbar, N_Vector yv, N_Vector ydotv, void* user) {
  rhs_plain(tbar, N_VGetArrayPointer(yv), N_VGetArrayPointer(ydotv), user);
  return 0;
}

void roots_plain(double tbar, const double* y, double* g, void* user) {
  auto& rs = *static_cast<RunState*>(user);
  bool need_forces = false;
  for (std::size_t i = 0; i < rs.n; ++i) need_forces |= rs.modes[i] == BallMode::Stick;
  if (need_forces) evaluate_forces(rs, tbar, y);
  for (std::size_t i = 0; i < rs.n; ++i) {
    if (rs.modes[i] == BallMode::Stick) {
      const double lim = rs.mu * rs.forces.fn[i];
      g[2 * i] = lim - rs.forces.fw[i] + rs.off_a[i];
      g[2 * i + 1] = lim + rs.forces.fw[i] + rs.off_b[i];
    } else {
      g[2 * i] = static_cast<double>(static_cast<signed char>(rs.modes[i])) * y[4 + rs.n + i];
      g[2 * i + 1] = 1.0;
    }
  }
}

int roots_arkode(sunrealtype tbar, N_Vector yv, sunrealtype* g, void* user) {
  roots_plain(tbar, N_VGetArrayPointer(yv), g, user);
  return 0;
}

// Shifts the stick margins that start negative (by rounding) so their crossing is still seen.
void set_root_offsets(RunState& rs, double tbar, const double* y) {
  evaluate_forces(rs, tbar, y);
  for (std::size_t i = 0; i < rs.n; ++i) {
    rs.off_a[i] = rs.off_b[i] = 0;
    if (rs.modes[i] != BallMode::Stick) continue;
    const double lim = rs.mu * rs.forces.fn[i];
    const double scale = 1e-10 * (std::fabs(lim) + std::fabs(rs.forces.fw[i]));
    const double ga = lim - rs.forces.fw[i], gb = lim + rs.forces.fw[i];
    if (ga < scale) rs.off_a[i] = scale - ga;
    if (gb < scale) rs.off_b[i] = scale - gb;
  }
}

bool all_stuck(const RunState& rs, const double* y) {
  for (std::size_t i = 0; i < rs.n; ++i) {
    if (rs.modes[i] != BallMode::Stick) return false;
    if (rs.opt.method == FrictionMethod::SwitchModel && std::fabs(y[4 + rs.n + i]) > rs.opt.switch_band) return false;
  }
  return true;
}

// Closed-form tail: profile over (W constant, W' = 0), every ball stuck, ideal motor. The table
// state z = (x, y, x', y') obeys z' = A z + f; with e = z - z_s, e(t) = V exp(Lambda t) V^-1 e0.
// Every stick margin is affine in z: g(t) = g(z_s) + l^T e(t), |l^T e(t)| <= sum_k |l^T v_k||c_k|.
// If g(z_s) exceeds that bound for every margin, no ball can slip again. Returns true and sets
// the final state (and the amplitude peak of the tail) when proven.
bool closed_form_tail(RunState& rs, double tbar, std::vector<double>& y, double tbar_end, double& peak_amp) {
  const double W = ideal_speed(rs, tbar).W;
  const double bb = rs.nd.bbar;
  if (!(bb > 0)) return false;
  Eigen::Matrix4d A;
  A << 0, 0, 1, 0, 0, 0, 0, 1, W * W - 1, 2 * bb * W, -2 * bb, 2 * W, -2 * bb * W, W * W - 1, -2 * W, -2 * bb;
  // Steady state from the forces with zero table velocity: solve the 2x2 static balance.
  double Cx = rs.nd.mbar_I * rs.nd.ebar, Cy = 0;
  for (std::size_t i = 0; i < rs.n; ++i) {
    Cx += rs.nd.mbar[i] * std::cos(y[4 + i]);
    Cy += rs.nd.mbar[i] * std::sin(y[4 + i]);
  }
  Cx *= W * W;
  Cy *= W * W;
  const double a11 = 1 - W * W, a12 = -2 * bb * W, a21 = 2 * bb * W, a22 = 1 - W * W;
  const double det = a11 * a22 - a12 * a21;
  Eigen::Vector4d zs((Cx * a22 - a12 * Cy) / det, (a11 * Cy - Cx * a21) / det, 0, 0);
  Eigen::Vector4d e0(y[0] - zs[0], y[1] - zs[1], y[2], y[3]);

  Eigen::EigenSolver<Eigen::Matrix4d> es(A);
  const Eigen::Matrix4cd V = es.eigenvectors();
  const Eigen::Vector4cd lam = es.eigenvalues();
  for (int k = 0; k < 4; ++k)
    if (!(lam[k].real() < 0)) return false;
  const Eigen::Vector4cd c = V.partialPivLu().solve(e0.cast<std::complex<double>>());

  // Margins at z_s and their gradients (affine: differences are exact up to rounding).
  std::vector<double> ys(y);
  for (int k = 0; k < 4; ++k) ys[k] = zs[k];
  const std::size_t n = rs.n;
  std::vector<double> ga(n), gb(n);
  auto margins = [&](const std::vector<double>& state, std::vector<double>& oa, std::vector<double>& ob) {
    rs.model.evaluate(state.data(), W, 0.0, rs.modes.data(), rs.mu, rs.forces);
    for (std::size_t i = 0; i < n; ++i) {
      const double lim = rs.mu * rs.forces.fn[i];
      oa[i] = lim - rs.forces.fw[i];
      ob[i] = lim + rs.forces.fw[i];
    }
  };
  margins(ys, ga, gb);
  std::vector<Eigen::Vector4d> la(n), lb(n);
  std::vector<double> pa(n), pb(n);
  for (int k = 0; k < 4; ++k) {
    std::vector<double> yp(ys);
    const double h = 1e-3;
    yp[k] += h;
    margins(yp, pa, pb);
    for (std::size_t i = 0; i < n; ++i) {
      la[i][k] = (pa[i] - ga[i]) / h;
      lb[i][k] = (pb[i] - gb[i]) / h;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    double bound_a = 0, bound_b = 0;
    for (int k = 0; k < 4; ++k) {
      const std::complex<double> va = la[i].cast<std::complex<double>>().dot(V.col(k));
      const std::complex<double> vb = lb[i].cast<std::complex<double>>().dot(V.col(k));
      bound_a += std::abs(va) * std::abs(c[k]);
      bound_b += std::abs(vb) * std::abs(c[k]);
    }
    // margin of safety for rounding in the affine reconstruction
    const double slack = 1e-9 * (std::fabs(ga[i]) + std::fabs(gb[i]));
    if (!(ga[i] - bound_a > slack && gb[i] - bound_b > slack)) return false;
  }

  // Proven: no slip until the end. Amplitude peak of the tail, then the final table state.
  auto state_at = [&](double dt) {
    Eigen::Vector4cd ex;
    for (int k = 0; k < 4; ++k) ex[k] = c[k] * std::exp(lam[k] * dt);
    return Eigen::Vector4d(zs + (V * ex).real());
  };
  double transient = 0;
  for (int k = 0; k < 4; ++k) transient += std::hypot(std::abs(V(0, k)), std::abs(V(1, k))) * std::abs(c[k]);
  const double L_mm = rs.params.ball_track_radius_m * 1e3;
  if ((std::hypot(zs[0], zs[1]) + transient) * L_mm > peak_amp) {
    double slowest = 0, fastest = 0;
    for (int k = 0; k < 4; ++k) {
      slowest = std::max(slowest, -1.0 / lam[k].real());
      fastest = std::max(fastest, std::abs(lam[k].imag()));
    }
    const double span = std::min(tbar_end - tbar, 20.0 * slowest);
    const double dt = fastest > 0 ? std::min(0.05 / fastest * kTwoPi, span / 16) : span / 16;
    for (double s = 0; s <= span; s += std::max(dt, 1e-9)) {
      const Eigen::Vector4d z = state_at(s);
      peak_amp = std::max(peak_amp, std::hypot(z[0], z[1]) * L_mm);
    }
  }
  const Eigen::Vector4d zend = state_at(tbar_end - tbar);
  for (int k = 0; k < 4; ++k) y[k] = zend[k];
  return true;
}

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

// Native stepper (erk_stepper.hpp): ARKODE's tables without ARKODE's per-step overhead.
class NativeIntegrator final : public Integrator {
 public:
  NativeIntegrator(RunState& rs, std::size_t nvar, bool with_roots)
      : st_(table_for(rs.opt.erk_table), nvar, rhs_plain, with_roots ? roots_plain : nullptr,
            with_roots ? 2 * rs.n : 0, &rs, rs.opt.rtol, rs.opt.atol, rs.opt.max_steps) {}
  void reset(double t, const std::vector<double>& y) override { st_.reset(t, y.data()); }
  void set_stop(double t) override { st_.set_stop_time(t); }
  Result step(double& t, std::vector<double>& y, std::vector<int>& roots) override {
    last_ = st_.step();
    t = st_.t();
    y = st_.y();
    if (last_ == detail::ErkStepper::Root) {
      roots = st_.roots_found();
      return Root;
    }
    return last_ < 0 ? Failure : Ok;
  }
  void dense(double t, std::vector<double>& out) override { st_.dense(t, out.data()); }
  long steps() const override { return st_.steps(); }
  std::string failure() const override {
    return last_ == detail::ErkStepper::TooManySteps ? "step limit reached" : "step size became too small";
  }
  bool too_much_work() const override { return last_ == detail::ErkStepper::TooManySteps; }

 private:
  static detail::ButcherTable table_for(const std::string& name) {
    try {
      return detail::ButcherTable::from_arkode(name);
    } catch (const std::invalid_argument& e) {
      throw ConfigError("simulation.erk_table", name, "must be an ARKODE explicit table with an embedding");
    }
  }
  detail::ErkStepper st_;
  detail::ErkStepper::Status last_ = detail::ErkStepper::Ok;
};

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

std::unique_ptr<Integrator> make_integrator(RunState& rs, std::size_t nvar, bool with_roots) {
  if (rs.opt.backend == IntegratorBackend::Native) return std::make_unique<NativeIntegrator>(rs, nvar, with_roots);
  return std::make_unique<ArkodeIntegrator>(rs, nvar, with_roots);
}

}  // namespace

Simulator::Simulator(SimulationSetup setup) : setup_(std::move(setup)) {
  validate(setup_.abu);
  validate(setup_.profile);
  validate(setup_.motor);
  validate(setup_.options);  // the reader's rules, from the one field list (simulation_config.hpp)
  const auto& o = setup_.options;
  if (end_time_s() <= 0)
    throw ConfigError("simulation.end_time_s", std::to_string(o.end_time_s),
                      "must be > 0 when the profile has no segments");
}

Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;

double Simulator::end_time_s() const {
  return setup_.options.end_time_s > 0 ? setup_.options.end_time_s : 2.0 * setup_.profile.duration_s();
}

RunOutcome Simulator::run(const std::vector<double>& beta0, const RunOverrides& ov,
                          std::vector<TrajectoryPoint>* trajectory) const {
  const auto wall0 = std::chrono::steady_clock::now();
  if (beta0.size() != setup_.abu.balls.size())
    throw ConfigError("the ABU has " + std::to_string(setup_.abu.balls.size()) + " balls, but " +
                      std::to_string(beta0.size()) + " initial angles were given");
  AbuParameters p = setup_.abu;
  if (ov.friction_mu) p.friction_mu = *ov.friction_mu;
  if (ov.imbalance_mass_kg) p.imbalance_mass_kg = *ov.imbalance_mass_kg;

  RunState rs(p);
  rs.profile = &setup_.profile;
  rs.motor = setup_.motor;
  rs.opt = setup_.options;
  rs.mu = p.friction_mu;
  rs.omega_n = rs.nd.omega_n;
  rs.n = p.balls.size();
  rs.pi_motor = setup_.motor.kind == MotorKind::PI;
  rs.modes.assign(rs.n, BallMode::Stick);
  rs.forces.resize(rs.n);
  rs.off_a.assign(rs.n, 0);
  rs.off_b.assign(rs.n, 0);
  const std::size_t nabu = 4 + 2 * rs.n;
  const std::size_t nvar = nabu + (rs.pi_motor ? 2 : 0);
  const bool event_driven = rs.opt.method == FrictionMethod::EventDriven;

  std::vector<double> y(nvar, 0.0);
  // Angles relative to the imbalance; an imbalance at angle phi sees the balls at beta - phi.
  for (std::size_t i = 0; i < rs.n; ++i) y[4 + i] = wrap_angle(beta0[i] - ov.imbalance_angle_rad);

  const double w = rs.omega_n;
  const double t_end = end_time_s() * w;
  const double t_profile = setup_.profile.duration_s() * w;
  RunOutcome out;
  out.end_time_s = end_time_s();
  double peak_amp = 0;
  const double L_mm = p.ball_track_radius_m * 1e3;

  // Initial modes from what happens just after t = 0: at rest every force is zero, so decide at
  // a tiny time with the rest state (forces then scale alike and the relative test works).
  {
    const double first = setup_.profile.segments().empty() ? 1.0 : setup_.profile.segments()[0].duration_s;
    const double tiny = 1e-6 * first * w;
    std::vector<double> yprobe(y);
    if (rs.pi_motor) {
      // the reference has moved a little; the disc has not
      const double fr = rs.motor.realised_reference_hz(setup_.profile.frequency_hz(tiny / w));
      yprobe[nabu] = 0.25 * kTwoPi * fr / w * tiny;  // delta ~ integral of the reference speed
    }
    Speed sp = rs.pi_motor ? Speed{0, 0} : ideal_speed(rs, tiny);
    if (rs.pi_motor) {
      rs.modes.assign(rs.n, BallMode::Stick);
      sp.Wp = evaluate_forces(rs, tiny, yprobe.data()).Wp;
    }
    rs.model.choose_modes(yprobe.data(), sp.W, sp.Wp, rs.mu, 0.0, rs.modes.data(), rs.forces);
    rs.modes_changed(y.data());
  }

  std::unique_ptr<Integrator> integ_ptr = make_integrator(rs, nvar, event_driven);
  Integrator& integ = *integ_ptr;
  double t = 0;
  integ.reset(t, y);
  if (event_driven) set_root_offsets(rs, t, y.data());

  std::vector<double> breaks;
  for (double b : setup_.profile.breakpoints_s())
    if (b * w > 0 && b * w < t_end) breaks.push_back(b * w);
  breaks.push_back(t_end);
  std::size_t next_break = 0;
  integ.set_stop(breaks[0]);

  std::vector<int> rinfo(2 * rs.n);
  std::vector<char> fixed(rs.n, 0);
  std::deque<double> recent_events;
  double all_stuck_since = all_stuck(rs, y.data()) ? 0.0 : -1.0;
  double next_tail_check = t_profile;
  double next_traj = 0;
  const double traj_dt = rs.opt.trajectory_interval_s * w;
  std::vector<double> ytraj(nvar);
  auto record = [&](double tt, const std::vector<double>& yy) {
    TrajectoryPoint tp;
    tp.t_s = tt / w;
    tp.frequency_hz = rs.pi_motor ? yy[nabu + 1] * w / kTwoPi : setup_.profile.frequency_hz(tp.t_s);
    tp.x_m = yy[0] * p.ball_track_radius_m;
    tp.y_m = yy[1] * p.ball_track_radius_m;
    for (std::size_t i = 0; i < rs.n; ++i) {
      tp.beta.push_back(wrap_angle(yy[4 + i]));
      tp.mode.push_back(static_cast<int>(static_cast<signed char>(rs.modes[i])));
    }
    trajectory->push_back(std::move(tp));
  };
  if (trajectory && traj_dt > 0) {
    record(0, y);
    next_traj = traj_dt;
  }

  while (t < t_end) {
    const Integrator::Result res = integ.step(t, y, rinfo);
    if (res == Integrator::Failure) {
      out.status = integ.too_much_work() ? RunStatus::StepLimit : RunStatus::SolverFailure;
      out.message = integ.failure() + " at t = " + std::to_string(t / w) + " s";
      break;
    }
    if (trajectory && traj_dt > 0) {
      while (next_traj <= t && next_traj <= t_end) {
        integ.dense(next_traj, ytraj);
        record(next_traj, ytraj);
        next_traj += traj_dt;
      }
    }
    peak_amp = std::max(peak_amp, std::hypot(y[0], y[1]) * L_mm);

    if (!event_driven) {
      // switch model: track the all-stuck period at step ends
      switch_modes(rs, t, y.data());
      if (all_stuck(rs, y.data())) {
        if (all_stuck_since < 0) all_stuck_since = t;
      } else {
        all_stuck_since = -1;
      }
    }

    bool reset_needed = false;
    if (res == Integrator::Root) {
      // A slipping ball whose speed reached zero may stick or reverse: a candidate. A stuck ball
      // whose friction margin reached zero leaves stick in the direction of the force needed to
      // hold it (the net force); the others are re-chosen consistently with that.
      const Speed sp0 = evaluate_forces(rs, t, y.data());
      for (std::size_t i = 0; i < rs.n; ++i) {
        fixed[i] = 0;
        if (rs.modes[i] != BallMode::Stick) {
          if (rinfo[2 * i] != 0) y[4 + rs.n + i] = 0.0;
        } else {
          y[4 + rs.n + i] = 0.0;
          if (rinfo[2 * i] != 0 || rinfo[2 * i + 1] != 0) {
            fixed[i] = 1;
            rs.modes[i] = rs.forces.fw[i] > 0 ? BallMode::SlipForward : BallMode::SlipBackward;
          }
        }
      }
      const Speed sp = rs.pi_motor ? sp0 : ideal_speed(rs, t);
      rs.model.choose_modes(y.data(), sp.W, sp.Wp, rs.mu, 0.0, rs.modes.data(), rs.forces, &fixed);
      rs.modes_changed(y.data());
      ++out.events;
      recent_events.push_back(t);
      while (!recent_events.empty() && (t - recent_events.front()) > rs.opt.chatter_window_s * w) recent_events.pop_front();
      if (static_cast<long>(recent_events.size()) > rs.opt.chatter_events) {
        out.status = RunStatus::ChatterLimit;
        out.message = "more than " + std::to_string(rs.opt.chatter_events) + " stick/slip events within " +
                      std::to_string(rs.opt.chatter_window_s) + " s at t = " + std::to_string(t / w) + " s";
        break;
      }
      if (out.events > rs.opt.max_events) {
        out.status = RunStatus::ChatterLimit;
        out.message = "more than " + std::to_string(rs.opt.max_events) + " stick/slip events";
        break;
      }
      if (all_stuck(rs, y.data())) {
        if (all_stuck_since < 0) all_stuck_since = t;
      } else {
        all_stuck_since = -1;
      }
      reset_needed = true;
    }
    if (next_break < breaks.size() && t >= breaks[next_break]) {
      ++next_break;
      if (next_break < breaks.size()) integ.set_stop(breaks[next_break]);
    }
    if (t >= t_end) break;

    if (event_driven && rs.opt.closed_form_tail && !rs.pi_motor && !(trajectory && traj_dt > 0) && t >= t_profile && t >= next_tail_check &&
        all_stuck_since >= 0) {
      if (closed_form_tail(rs, t, y, t_end, peak_amp)) {
        t = t_end;
        break;
      }
      next_tail_check = t + 0.5 * w;  // the transient decays; try again later
    }
    if (reset_needed) {
      integ.reset(t, y);
      set_root_offsets(rs, t, y.data());
    }
  }

  out.steps = integ.steps();
  out.rhs_evaluations = rs.rhs_evals;
  out.max_amplitude_mm = peak_amp;
  for (std::size_t i = 0; i < rs.n; ++i) out.beta_final.push_back(wrap_angle(y[4 + i]));
  double ix = 0, iy = 0;
  AbuModel::imbalance_vector(p, out.beta_final.data(), ix, iy);
  out.residual_imbalance_kgm = std::hypot(ix, iy);
  out.residual_imbalance_x_kgm = std::fabs(ix);
  out.settled = out.ok() && all_stuck(rs, y.data());
  out.settling_time_s = out.settled ? all_stuck_since / w : 0.0;
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return out;
}

}  // namespace abuopt
