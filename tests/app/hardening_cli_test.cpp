// The command line under hostile or unlucky input (issue 12): every case ends with a clear message
// and one of the documented exit statuses (0, 2, 3, 4, 130), never a crash, a hang, NaN printed as
// a result, or "wrote ..." for a file that was not written.
#include <gtest/gtest.h>
#include <sys/file.h>
#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "abuopt_cli.hpp"

namespace abuopt {
namespace {

namespace fs = std::filesystem;
using test::run_abuopt;

const std::string kSrc = ABUOPT_SOURCE_DIR;
const std::string kMc = kSrc + "/configs/montecarlo_final_profile.yaml";
const std::string kSim = kSrc + "/configs/report_final_profile.yaml";

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(ABUOPT_BINARY_DIR) / name;
  fs::remove_all(d);
  return d;
}

#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

TEST(HardeningCli, AFullDiskIsExitFourAndNoHalfWrittenFile) {
  // A file-size limit of 64 kB stands in for a full disk: runs.csv of 1024 runs is larger.
  const fs::path out = fresh_dir("hardening_full_disk");
  const auto r = run_abuopt("montecarlo " + kMc + " --design random --runs 1024 --out " + out.string(),
                            "trap '' XFSZ; ulimit -f 128;");
  EXPECT_EQ(r.status, 4) << r.output;
  EXPECT_HAS(r.output, "runs.csv");
  EXPECT_EQ(r.output.find("wrote"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "runs.csv"));  // nothing half-written under the name
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  fs::remove_all(out);
}

TEST(HardeningCli, ADirectoryAsTheConfigIsBadInput) {
  const auto r = run_abuopt("simulate " + kSrc + "/configs");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "is a directory");
}

TEST(HardeningCli, NonFiniteNumbersAreRejected) {
  auto r = run_abuopt("simulate " + kSim + " --mu nan");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "--mu");
  r = run_abuopt("simulate " + kSim + " --trajectory /dev/null --trajectory-interval nan");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "--trajectory-interval");
  r = run_abuopt("eqset " + kSrc + "/configs/eqset.yaml --freq 1e100 --out " + fresh_dir("hardening_eqset").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "--freq");
  EXPECT_EQ(r.output.find("nan"), std::string::npos) << r.output;
}

TEST(HardeningCli, RequestsThatWouldExhaustMemoryNameTheLimit) {
  auto r = run_abuopt("simulate " + kSim + " --trajectory /dev/null --trajectory-interval 1e-6");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "at most 1e7");
  r = run_abuopt("montecarlo " + kMc + " --design random --runs 4294967295");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "10000000");
  r = run_abuopt("eqset " + kSrc + "/configs/eqset.yaml --freq 29 --grid 65536");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "--grid");
}

TEST(HardeningCli, ABallListIsCappedLikeBallCount) {
  const std::string cfg = std::string(ABUOPT_BINARY_DIR) + "/hardening_500_balls.yaml";
  {
    std::ifstream in(kSim);
    std::ofstream out(cfg);
    std::string line;
    bool skipping = false;
    while (std::getline(in, line)) {
      if (line.rfind("  balls:", 0) == 0) {
        out << "  balls:\n";
        for (int i = 0; i < 500; ++i) out << "    - {mass_kg: 1.4e-4, diameter_m: 3.0e-3}\n";
        skipping = true;
        continue;
      }
      if (skipping && line.rfind("    -", 0) == 0) continue;
      skipping = false;
      out << line << "\n";
    }
  }
  const auto r = run_abuopt("simulate " + cfg);
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "at most 64 balls");
  fs::remove(cfg);
}

TEST(HardeningCli, TwoRunsCannotShareAnOutputDirectory) {
  const fs::path out = fresh_dir("hardening_lock");
  fs::create_directories(out);
  // This test holds the lock as another abuopt run would.
  const int fd = ::open((out / ".abuopt.lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  const auto r = run_abuopt("montecarlo " + kMc + " --design random --runs 4 --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_HAS(r.output, "in use by another abuopt run");
  ::close(fd);
  const auto again = run_abuopt("montecarlo " + kMc + " --design random --runs 4 --out " + out.string());
  EXPECT_EQ(again.status, 0) << again.output;
  fs::remove_all(out);
}

TEST(HardeningCli, RefusedThreadsMeanFewerThreadsNotACrash) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "the address-space limit that refuses the threads also breaks the sanitizer runtime";
#else
  // 500 threads of 8 MB stacks do not fit in a 1.5 GB address space: thread creation fails.
  const auto r = run_abuopt("montecarlo " + kMc + " --design random --runs 600 --threads 500", "ulimit -v 1500000;");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_HAS(r.output, "worker threads");
#endif
}

}  // namespace
}  // namespace abuopt
