// Long study (ctest label "long"): the whole reproduction of the 2003 report at its own run counts
// (36 Monte Carlo studies, 25 344 startups; ~20 s on two cores) must confirm each of the report's
// four conclusions (docs/validation.md).
#include <gtest/gtest.h>

#include <string>

#include "abuopt_cli.hpp"

TEST(FullReproduction, ConfirmsEveryConclusionOfTheReport) {
  const std::string out = std::string(ABUOPT_BINARY_DIR) + "/full_reproduction_test";
  const auto r = abuopt::test::run_abuopt(
      "reproduce --no-plots --configs " + std::string(ABUOPT_SOURCE_DIR) + "/configs/report --out " + out, "", false);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto at = r.output.find("Verdicts on the report's conclusions");
  ASSERT_NE(at, std::string::npos) << r.output;
  const std::string verdicts = r.output.substr(at);
  for (const char* id : {"(b) [table 4.1] CONFIRMED", "(b) [table 4.2] CONFIRMED", "(a) [table 4.4] CONFIRMED",
                         "(c) [table mu] CONFIRMED"})
    EXPECT_NE(verdicts.find(id), std::string::npos) << id << "\n" << verdicts;
}
