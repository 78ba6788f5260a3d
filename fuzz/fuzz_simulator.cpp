// libFuzzer target: the simulator over random finite, in-range physical parameters, profiles,
// motors and options (ranges below, wider than any shipped config). Every run must end with a
// status, never hang: a wall-clock guard aborts the process when a run takes longer than
// kGuardSeconds. A run that ends ok must report finite results.
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <memory>
#include <thread>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/simulator.hpp"

namespace {

using namespace abuopt;

constexpr double kGuardSeconds = 60;

double in(FuzzedDataProvider& p, double lo, double hi) { return p.ConsumeFloatingPointInRange(lo, hi); }

SimulationSetup make_setup(FuzzedDataProvider& p) {
  SimulationSetup s;
  AbuParameters& a = s.abu;
  a.table_mass_kg = in(p, 0.05, 2.0);
  a.damping_Ns_per_m = in(p, 0.0, 20.0);
  a.stiffness_N_per_m = in(p, 1e3, 1e5);
  a.ball_track_radius_m = in(p, 0.005, 0.05);
  a.imbalance_mass_kg = in(p, 0.0, 2e-3);
  a.eccentricity_m = in(p, 0.0, 0.01);
  a.friction_mu = in(p, 0.0, 0.3);
  a.ball_damping_Nms = p.ConsumeBool() ? in(p, 0.0, 1e-6) : 0.0;
  a.balls.resize(p.ConsumeIntegralInRange<std::size_t>(1, 4));
  for (Ball& b : a.balls) {
    b.mass_kg = in(p, 2e-5, 1e-3);
    b.diameter_m = in(p, 1e-3, 0.9 * a.ball_track_radius_m);
  }
  std::vector<InclinedSineSegment> segs(p.ConsumeIntegralInRange<std::size_t>(1, 3));
  for (auto& g : segs) {
    g.end_frequency_hz = in(p, 0.0, 100.0);
    g.duration_s = in(p, 0.05, 1.5);
  }
  s.profile = StartupProfile(segs, in(p, 0.0, 30.0));
  if (p.ConsumeBool()) {
    s.motor.kind = MotorKind::PI;
    s.motor.omega_m_rad_s = in(p, 0.5, 50.0);
    s.motor.xi = in(p, 0.1, 2.0);
    s.motor.bearing_torque_Nm = in(p, 0.0, 1e-3);
    s.motor.inertia_kgm2 = in(p, 1e-5, 1e-3);
    s.motor.friction_feedback = p.ConsumeBool();
    s.motor.setpoint_mismatch = p.ConsumeBool();
    s.motor.quantize_setpoint_1hz = p.ConsumeBool();
  }
  SimulationOptions& o = s.options;
  o.method = p.ConsumeBool() ? FrictionMethod::EventDriven : FrictionMethod::SwitchModel;
  o.rtol = std::pow(10.0, in(p, -8.0, -3.0));
  o.atol = std::pow(10.0, in(p, -12.0, -6.0));
  o.closed_form_tail = p.ConsumeBool();
  o.max_steps = 200'000;
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider p(data, size);
  const SimulationSetup setup = make_setup(p);
  std::vector<double> beta0(setup.abu.balls.size());
  for (double& b : beta0) b = in(p, 0.0, 6.283185307179586);

  std::unique_ptr<Simulator> sim;
  try {
    sim = std::make_unique<Simulator>(setup);
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "fuzz_simulator: an in-range setup was rejected: %s\n", e.what());
    std::abort();
  }

  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  RunOutcome out;
  std::thread worker([&] {
    RunOutcome r = sim->run(beta0);
    std::lock_guard<std::mutex> lock(m);
    out = std::move(r);
    done = true;
    cv.notify_one();
  });
  {
    std::unique_lock<std::mutex> lock(m);
    if (!cv.wait_for(lock, std::chrono::duration<double>(kGuardSeconds), [&] { return done; })) {
      std::fprintf(stderr, "fuzz_simulator: a run did not end within %g s (wall-clock guard)\n", kGuardSeconds);
      std::abort();
    }
  }
  worker.join();
  if (out.ok()) {
    bool finite = std::isfinite(out.residual_imbalance_kgm) && std::isfinite(out.residual_imbalance_x_kgm) &&
                  std::isfinite(out.max_amplitude_mm) && std::isfinite(out.settling_time_s);
    for (double b : out.beta_final) finite = finite && std::isfinite(b);
    if (!finite) {
      std::fprintf(stderr, "fuzz_simulator: status ok with a non-finite result\n");
      std::abort();
    }
  }
  return 0;
}
