// The progress reporter: its line format (rate and ETA from the counts), its quiet rule (Auto shows
// on a terminal only, Always also on a file, Never never) and concurrent updates.
#include "abuopt/common/progress.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <thread>
#include <vector>

namespace abuopt {
namespace {

std::string read_all(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  char buf[512];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
  return s;
}

TEST(Progress, LineHasCountsPercentRateAndEta) {
  // 512 of 1024 in 6 s: 85.33 runs/s, 512 left -> 6 s.
  EXPECT_EQ(format_progress_line("Monte Carlo", "runs", 512, 1024, 6.0),
            "Monte Carlo: 512/1024 runs (50.0 %)  85.3 runs/s  ETA 6 s");
  EXPECT_EQ(format_progress_line("Monte Carlo", "runs", 1024, 1024, 12.0),
            "Monte Carlo: 1024/1024 runs (100.0 %)  85.3 runs/s  done in 12.0 s");
  // 3 of 200 evaluations in 9 s: 0.333/s, 197 left -> 591 s = 9:51.
  EXPECT_EQ(format_progress_line("optimize", "evaluations", 3, 200, 9.0),
            "optimize: 3/200 evaluations (1.5 %)  0.333 evaluations/s  ETA 9:51");
  // Nothing done yet: no rate, no ETA.
  EXPECT_EQ(format_progress_line("x", "runs", 0, 10, 0.5), "x: 0/10 runs (0.0 %)  -- runs/s  ETA --");
  // An optimiser that stopped within its budget: no ETA on its last line.
  EXPECT_EQ(format_progress_line("optimize", "evaluations", 40, 200, 8.0, true),
            "optimize: 40/200 evaluations (20.0 %)  5.0 evaluations/s  ended after 8.0 s");
  // Unknown total: count, rate and elapsed time only.
  EXPECT_EQ(format_progress_line("", "runs", 10, 0, 4.0), "10 runs  2.5 runs/s  4.0 s");
}

TEST(Progress, DurationFormat) {
  EXPECT_EQ(format_duration(42.4), "42 s");
  EXPECT_EQ(format_duration(99.4), "99 s");
  EXPECT_EQ(format_duration(185), "3:05");
  EXPECT_EQ(format_duration(3723), "1:02:03");
  EXPECT_EQ(format_duration(-1), "--");
}

TEST(Progress, QuietRule) {
  EXPECT_TRUE(show_progress(ProgressMode::Auto, true));
  EXPECT_FALSE(show_progress(ProgressMode::Auto, false));
  EXPECT_TRUE(show_progress(ProgressMode::Always, false));
  EXPECT_TRUE(show_progress(ProgressMode::Always, true));
  EXPECT_FALSE(show_progress(ProgressMode::Never, true));
}

TEST(Progress, AutoOnAFileWritesNothingButMessages) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    ProgressReporter bar("mc", "runs", 4, ProgressMode::Auto, f);  // a file is not a terminal
    EXPECT_FALSE(bar.enabled());
    for (int i = 0; i < 4; ++i) bar.add();
    bar.message("case 1 done");
  }
  EXPECT_EQ(read_all(f), "case 1 done\n");
  std::fclose(f);
}

TEST(Progress, AlwaysOnAFileWritesWholeLinesAndALastOne) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    ProgressReporter bar("mc", "runs", 3, ProgressMode::Always, f);
    EXPECT_TRUE(bar.enabled());
    bar.update(1);  // the first update draws (then not again for 5 s)
    bar.update(2);
    bar.update(3);
  }  // the destructor writes the last line
  const std::string s = read_all(f);
  EXPECT_EQ(s.find('\r'), std::string::npos);
  EXPECT_EQ(s.rfind("mc: 1/3 runs (33.3 %)", 0), 0u) << s;
  EXPECT_NE(s.find("\nmc: 3/3 runs (100.0 %)"), std::string::npos) << s;
  EXPECT_NE(s.find("done in"), std::string::npos);
  EXPECT_EQ(s.back(), '\n');
  std::fclose(f);
}

TEST(Progress, TerminalRedrawsInPlaceAndMessagesClearTheBar) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    ProgressReporter bar("mc", "runs", 2, ProgressMode::Auto, f, /*is_terminal=*/true);
    EXPECT_TRUE(bar.enabled());
    bar.update(1);
    bar.message("log line");
    bar.update(2);
    bar.finish();
    bar.finish();  // once only
  }
  const std::string s = read_all(f);
  EXPECT_EQ(s.rfind("\rmc: 1/2 runs", 0), 0u) << s;
  // the message erases the bar, goes on its own line, and the bar comes back below it
  EXPECT_NE(s.find("\r\x1b[Klog line\n\rmc: 1/2 runs"), std::string::npos) << s;
  EXPECT_EQ(s.find("done in"), s.rfind("done in"));
  EXPECT_NE(s.find("mc: 2/2 runs (100.0 %)"), std::string::npos);
  EXPECT_EQ(s.back(), '\n');
  std::fclose(f);
}

TEST(Progress, ConcurrentAddsCountEveryOne) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    ProgressReporter bar("mc", "runs", 4000, ProgressMode::Always, f, /*is_terminal=*/true);
    std::vector<std::thread> th;
    for (int t = 0; t < 4; ++t)
      th.emplace_back([&bar] {
        for (int i = 0; i < 1000; ++i) bar.add();
      });
    for (auto& t : th) t.join();
  }
  const std::string s = read_all(f);
  EXPECT_NE(s.find("mc: 4000/4000 runs (100.0 %)"), std::string::npos) << s.substr(s.size() > 200 ? s.size() - 200 : 0);
  std::fclose(f);
}

}  // namespace
}  // namespace abuopt
