// Long study (ctest label "long"): the whole reproduction of the 2003 report at its own run counts
// (36 Monte Carlo studies, 25 344 startups; ~20 s on two cores) must confirm each of the report's
// four conclusions (docs/validation.md).
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <string>

TEST(FullReproduction, ConfirmsEveryConclusionOfTheReport) {
  const std::string out = std::string(ABUOPT_BINARY_DIR) + "/full_reproduction_test";
  const std::string cmd = std::string(ABUOPT_EXE) + " reproduce --no-plots --configs " + ABUOPT_SOURCE_DIR +
                          "/configs/report --out " + out + " 2>/dev/null";
  std::array<char, 4096> buf{};
  std::string text;
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  while (fgets(buf.data(), buf.size(), p)) text += buf.data();
  const int st = pclose(p);
  ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << text;
  const std::string verdicts = text.substr(text.find("Verdicts on the report's conclusions"));
  for (const char* id : {"(b) [table 4.1] CONFIRMED", "(b) [table 4.2] CONFIRMED", "(a) [table 4.4] CONFIRMED",
                         "(c) [table mu] CONFIRMED"})
    EXPECT_NE(verdicts.find(id), std::string::npos) << id << "\n" << verdicts;
}
