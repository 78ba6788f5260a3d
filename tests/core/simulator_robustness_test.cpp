// The simulator on hostile input (issue 12): non-finite states end a run with a status and a
// message, never a loop; back ends own their resources when construction fails.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <string>

#include "abuopt/common/config_error.hpp"
#include "abuopt/core/simulator.hpp"

using namespace abuopt;

namespace {

// Resident set size of this process [bytes] (Linux /proc/self/statm, second field in pages).
double resident_bytes() {
  std::ifstream f("/proc/self/statm");
  double size = 0, resident = 0;
  f >> size >> resident;
  return resident * 4096.0;
}

// Runs with a wall-clock bound: a loop would make the test fail instead of hanging ctest.
RunOutcome timed_run(const Simulator& sim, const std::vector<double>& beta0, double& seconds) {
  const auto t0 = std::chrono::steady_clock::now();
  RunOutcome o = sim.run(beta0);
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return o;
}

}  // namespace

TEST(SimulatorRobustness, NonFiniteInitialAngleEndsTheRunWithAStatus) {
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()}) {
    for (const IntegratorBackend b : {IntegratorBackend::Native, IntegratorBackend::ArkodeErk}) {
      SimulationSetup s;
      s.options.backend = b;
      Simulator sim(s);
      double sec = 0;
      const RunOutcome o = timed_run(sim, {bad, 1.0}, sec);
      EXPECT_EQ(o.status, RunStatus::SolverFailure) << bad << " " << to_string(b);
      EXPECT_NE(o.message.find("not finite"), std::string::npos) << o.message;
      EXPECT_LT(sec, 5.0);
    }
  }
}

TEST(SimulatorRobustness, AbsurdMotorBandwidthEndsTheRunWithAStatus) {
  // omega_m = 1e200 rad/s: the PI law's terms overflow to inf/NaN in the first step.
  SimulationSetup s;
  s.motor.kind = MotorKind::PI;
  s.motor.omega_m_rad_s = 1e200;
  Simulator sim(s);
  double sec = 0;
  const RunOutcome o = timed_run(sim, {1.0, 2.0}, sec);
  EXPECT_FALSE(o.ok());
  EXPECT_FALSE(o.message.empty());
  EXPECT_LT(sec, 5.0);
  for (double b : o.beta_final) EXPECT_TRUE(std::isfinite(b)) << "a failed run reports the last finite state";
}

TEST(SimulatorRobustness, ArkodeBackendWithABadTableLeaksNothing) {
  // Before: the constructor threw after allocating ARKODE's memory and vector (~10 kB each time).
  SimulationSetup s;
  s.options.backend = IntegratorBackend::ArkodeErk;
#if defined(__SANITIZE_ADDRESS__)  // GCC's name; clang says __has_feature(address_sanitizer)
#define ABUOPT_TEST_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ABUOPT_TEST_UNDER_ASAN 1
#endif
#endif
#ifdef ABUOPT_TEST_UNDER_ASAN
  GTEST_SKIP() << "ASan's quarantine keeps freed memory resident; LeakSanitizer checks this build for leaks instead";
#endif
  s.options.erk_table = "NOT_A_TABLE";
  Simulator sim(s);
  auto attempt = [&] {
    try {
      sim.run({1.0, 2.0});
    } catch (const ConfigError&) {
    }
  };
  for (int k = 0; k < 200; ++k) attempt();  // warm up allocator pools
  const double before = resident_bytes();
  for (int k = 0; k < 4000; ++k) attempt();
  const double grown = resident_bytes() - before;
  EXPECT_LT(grown, 4e6) << "resident set grew by " << grown << " bytes over 4000 failed constructions";
}
