// The acceptance measurement of hard ball contact (label long, ~30 s): 1024 random starts of the
// report's final profile for each of three seeds, two balls: every run ends ok and no final state
// overlaps (clearance >= -1e-12 rad, rounding). docs/validation.md has the statistics.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "abuopt/core/ball_contact.hpp"
#include "abuopt/core/simulator.hpp"

using namespace abuopt;

TEST(BallContactLong, NoFinalStateOverlapsIn1024RandomStartsThreeSeeds) {
  SimulationSetup s;
  s.abu.ball_contact = BallContact::Hard;
  Simulator sim(s);
  for (std::uint64_t seed : {12u, 13u, 14u}) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 2 * M_PI);
    int failed = 0, overlaps = 0;
    for (int k = 0; k < 1024; ++k) {
      const RunOutcome o = sim.run({u(rng), u(rng)});
      failed += !o.ok();
      overlaps += min_contact_clearance(s.abu, o.beta_final) < -1e-12;
    }
    EXPECT_EQ(failed, 0) << "seed " << seed;
    EXPECT_EQ(overlaps, 0) << "seed " << seed;
  }
}
