#pragma once
// What one simulation of a startup yields (one Monte Carlo sample).
#include <string>
#include <vector>

namespace abuopt {

enum class RunStatus {
  Ok,             // reached the end time
  SolverFailure,  // the integrator failed (message says how)
  ChatterLimit,   // too many stick/slip events in a short time (chatter guard tripped)
  StepLimit,      // step budget exhausted
  EventLimit,     // event budget (max_events) exhausted
};
std::string to_string(RunStatus s);

struct RunOutcome {
  RunStatus status = RunStatus::Ok;
  std::string message;                   // empty when ok
  std::vector<double> beta_final;        // final ball angles in [0, 2 pi), disc frame, from imbalance
  double residual_imbalance_kgm = 0;     // |I_r|: magnitude of the imbalance vector (physical)
  double residual_imbalance_x_kgm = 0;   // I_r,x: |m_I e + sum m_i L cos beta_i| (report eq 4.2)
  bool settled = false;                  // all balls stuck at the end time
  double settling_time_s = 0;            // from this instant all balls stick for good (if settled)
  double max_amplitude_mm = 0;           // peak of sqrt(x^2 + y^2) over the run
  double end_time_s = 0;
  long events = 0;                       // events (stick/slip transitions, impacts, contacts)
  long impacts = 0;                      // ball-ball impacts (hard contact)
  double min_contact_clearance_rad = 0;  // hard contact: smallest gap - spacing at the end (>= 0)
  long rhs_evaluations = 0;
  long steps = 0;
  double wall_time_s = 0;
  bool ok() const { return status == RunStatus::Ok; }
};

}  // namespace abuopt
