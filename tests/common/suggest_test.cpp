// "Did you mean": the edit distance (hand-counted cases) and which candidate is suggested.
#include "abuopt/common/suggest.hpp"

#include <gtest/gtest.h>

namespace abuopt {
namespace {

TEST(Suggest, EditDistanceCountsInsertDeleteSubstituteSwap) {
  EXPECT_EQ(edit_distance("", ""), 0u);
  EXPECT_EQ(edit_distance("abc", ""), 3u);
  EXPECT_EQ(edit_distance("rtoll", "rtol"), 1u);            // one deletion
  EXPECT_EQ(edit_distance("duraton_s", "duration_s"), 1u);  // one insertion
  EXPECT_EQ(edit_distance("frcition", "friction"), 1u);     // one swap of neighbours
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);        // the textbook example
  EXPECT_EQ(edit_distance("max-evaluations", "max_evaluations"), 0u);  // '-' == '_'
  EXPECT_EQ(edit_distance("Seed", "seed"), 0u);
}

TEST(Suggest, NearestCloseCandidateWins) {
  const std::vector<std::string> keys = {"duration_s", "frequency_hz", "kind", "rtol", "atol"};
  EXPECT_EQ(closest_match("duraton_s", keys).value_or(""), "duration_s");
  EXPECT_EQ(closest_match("rtoll", keys).value_or(""), "rtol");  // rtol (1) before atol (2)
  EXPECT_EQ(closest_match("frequncy_hz", keys).value_or(""), "frequency_hz");
  EXPECT_FALSE(closest_match("colour", keys));      // nothing near
  EXPECT_FALSE(closest_match("kind", keys));        // itself is not a suggestion
  EXPECT_FALSE(closest_match("xi", {"mu"}));        // short words must match closely
  EXPECT_EQ(closest_match("dur", keys).value_or(""), "duration_s");  // the one key it begins
  EXPECT_FALSE(closest_match("dur", {"duration_s", "durability"}));  // two: no guess
  EXPECT_EQ(closest_match("montecarol", {"simulate", "montecarlo", "eqset"}).value_or(""), "montecarlo");
  EXPECT_EQ(closest_match("--seeds", {"--seed", "--runs"}).value_or(""), "--seed");
}

TEST(Suggest, HintText) {
  EXPECT_EQ(did_you_mean("rtoll", {"rtol"}), "; did you mean 'rtol'?");
  EXPECT_EQ(did_you_mean("zzz", {"rtol"}), "");
}

}  // namespace
}  // namespace abuopt
