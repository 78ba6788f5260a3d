#pragma once
// The event-driven ABU simulator: one startup from rest, from given initial ball angles.
//
// The model (abu_model.hpp) is const and shared; each run owns its integrator state, so one
// Simulator may run from many threads at once. Coulomb stick/slip is handled exactly: root
// functions locate slip->stick (beta_i' = 0) and stick->slip (needed friction reaches mu fn_i);
// at every event the modes of all balls are chosen together and the integrator restarts. The
// report's own method (Leine's switch model: a thin band |beta'| < eta treated as stick) is an
// option on the same model. Integration uses the native explicit Runge-Kutta stepper with
// ARKODE's Butcher tables by default (IntegratorBackend::Native); SUNDIALS ARKODE's ERKStep is
// the reference back end (ArkodeErk). Numerical trouble is an outcome status, never an exception.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "abuopt/core/motor.hpp"
#include "abuopt/core/outcome.hpp"
#include "abuopt/core/parameters.hpp"
#include "abuopt/core/profile.hpp"

namespace abuopt {

namespace detail {
class StuckForcingTable;
class SimulatorForcing;
}

enum class FrictionMethod { EventDriven, SwitchModel };
// Native: our lean explicit RK stepper with ARKODE's Butcher tables (fast, the default).
// ArkodeErk: SUNDIALS ARKODE ERKStep with its own root finding (the reference; ~20x slower here).
enum class IntegratorBackend { Native, ArkodeErk };
// While every ball is stuck (event-driven, ideal motor): RungeKutta integrates the table rows with
// the back end's stepper; Exact propagates them with the exact solution of the linear table
// (docs/stuck_propagator.md), checking the stick margins on a grid of half a period of their
// fastest oscillation and locating stick -> slip events on the exact solution.
enum class StuckIntegrator { RungeKutta, Exact };
std::string to_string(FrictionMethod m);
std::string to_string(IntegratorBackend b);
std::string to_string(StuckIntegrator s);

struct SimulationOptions {
  FrictionMethod method = FrictionMethod::EventDriven;
  IntegratorBackend backend = IntegratorBackend::Native;
  std::string erk_table = "ARKODE_FEHLBERG_13_7_8";  // ARKODE built-in explicit table
  double rtol = 1e-6;
  double atol = 1e-9;              // on the non-dimensional state
  double end_time_s = 0;           // <= 0: twice the profile duration (report's rule)
  double switch_band = 1e-4;       // switch model: |beta'| / omega_n below this counts as stick
  long max_steps = 2'000'000;
  long max_events = 100'000;       // total events; more ends the run with status EventLimit
  // Chatter guard: more than chatter_events transitions within chatter_window_s ends the run
  // with status ChatterLimit.
  long chatter_events = 200;
  double chatter_window_s = 1e-3;
  // After the profile ends with all balls stuck the system is linear and time-invariant; when a
  // bound proves no ball can slip again the run jumps to the end time in closed form.
  bool closed_form_tail = true;
  StuckIntegrator stuck_integrator = StuckIntegrator::Exact;
  double trajectory_interval_s = 0;  // > 0: record a trajectory point every this many seconds
};

// Per-run deviations from the nominal parameters (uncertain parameters of a Monte Carlo).
struct RunOverrides {
  std::optional<double> friction_mu;
  std::optional<double> imbalance_mass_kg;
  std::optional<double> stiffness_N_per_m;  // > 0
  std::optional<double> ball_restitution;   // in [0, 1] (hard contact)
  double imbalance_angle_rad = 0;  // rotates the imbalance; reported angles stay imbalance-relative
};

struct TrajectoryPoint {
  double t_s, frequency_hz, x_m, y_m;
  std::vector<double> beta;   // rad
  std::vector<int> mode;      // 0 stick, +1 slip forward, -1 slip backward
};

struct SimulationSetup {
  AbuParameters abu;
  StartupProfile profile = StartupProfile::report_final();
  MotorModel motor;
  SimulationOptions options;
};

class Simulator {
 public:
  explicit Simulator(SimulationSetup setup);  // validates; throws ConfigError
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;
  Simulator(Simulator&&) noexcept;

  // beta0.size() must equal the number of balls (std::invalid_argument otherwise: API misuse).
  RunOutcome run(const std::vector<double>& beta0, const RunOverrides& overrides = {},
                 std::vector<TrajectoryPoint>* trajectory = nullptr) const;

  const SimulationSetup& setup() const { return setup_; }
  double end_time_s() const;
  std::size_t ball_count() const { return setup_.abu.balls.size(); }

 private:
  SimulationSetup setup_;
  // The forcing integrals of the exact stuck-phase propagator, built by the first run that needs
  // them and shared by all runs (null when the Runge-Kutta path is used).
  std::shared_ptr<detail::SimulatorForcing> forcing_;
  // What the PI drive is steered with: the profile, or its feed-forward setpoint
  // (motor.feedforward, computed once here).
  std::shared_ptr<const StartupProfile> reference_;
  // The runs' stop times (s, sorted, distinct): the reference's breakpoints and the quantised
  // reference's steps (computed once here, scaled per run).
  std::vector<double> stop_times_s_;
};

}  // namespace abuopt
