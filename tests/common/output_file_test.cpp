// Whole-or-nothing output files and the output-directory lock (issue 12: on a full disk every
// command said "wrote ..." and left truncated files). A full disk is simulated with the file-size
// limit (RLIMIT_FSIZE, SIGXFSZ ignored): write() then fails with EFBIG as it would with ENOSPC.
#include "abuopt/common/output_file.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "abuopt/common/config_error.hpp"

namespace abuopt {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::path(ABUOPT_BINARY_DIR) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Only the given names are in the folder (no temporary left behind).
std::size_t entries(const fs::path& d) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(d)) ++n;
  return n;
}

// Limits the size of any file this process writes while alive.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &old_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit lim = old_;
    lim.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &lim);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit old_{};
  void (*old_handler_)(int) = nullptr;
};

TEST(OutputFile, WritesTheWholeTextUnderTheName) {
  const fs::path d = fresh_dir("output_file_test_ok");
  write_file_atomic(d / "a.csv", "x,y\n1,2\n");
  EXPECT_EQ(read(d / "a.csv"), "x,y\n1,2\n");
  AtomicFile f(d / "b.txt");
  f << "n = " << 3 << "\n";
  EXPECT_FALSE(fs::exists(d / "b.txt"));  // nothing under the name before commit()
  f.commit();
  EXPECT_EQ(read(d / "b.txt"), "n = 3\n");
  EXPECT_EQ(entries(d), 2u);
  fs::remove_all(d);
}

TEST(OutputFile, AFailedWriteIsAnErrorAndLeavesTheOldFileWhole) {
  const fs::path d = fresh_dir("output_file_test_full");
  write_file_atomic(d / "summary.json", "{\"old\": true}\n");
  const std::string big(1 << 20, 'x');
  try {
    FileSizeLimit limit(4096);
    write_file_atomic(d / "summary.json", big);
    FAIL() << "a write past the file-size limit did not throw";
  } catch (const OutputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("summary.json"), std::string::npos) << m;
    EXPECT_NE(m.find("too large"), std::string::npos) << m;  // strerror(EFBIG): "File too large"
  }
  EXPECT_EQ(read(d / "summary.json"), "{\"old\": true}\n");  // untouched
  EXPECT_EQ(entries(d), 1u);                                  // and no temporary left
  // A new file that cannot be written whole does not appear at all.
  {
    FileSizeLimit limit(4096);
    EXPECT_THROW(write_file_atomic(d / "runs.csv", big), OutputError);
  }
  EXPECT_FALSE(fs::exists(d / "runs.csv"));
  EXPECT_EQ(entries(d), 1u);
  fs::remove_all(d);
}

TEST(OutputFile, AnUnwritableFolderIsAnOutputError) {
  EXPECT_THROW(write_file_atomic("/proc/abuopt_no_such_dir/x.csv", "1\n"), OutputError);
}

TEST(OutputFile, ADeviceIsWrittenInPlaceNeverReplaced) {
  // /dev/full fails every write with ENOSPC: the error is reported and the device stays a device.
  EXPECT_THROW(write_file_atomic("/dev/full", "1\n"), OutputError);
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
  EXPECT_NO_THROW(write_file_atomic("/dev/null", "1\n"));
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

TEST(OutputDirLock, ASecondHolderIsRefusedUntilTheFirstEnds) {
  const fs::path d = fresh_dir("output_file_test_lock");
  {
    const OutputDirLock first(d);
    try {
      const OutputDirLock second(d);
      FAIL() << "two locks on one directory";
    } catch (const ConfigError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("in use by another abuopt run"), std::string::npos) << m;
      EXPECT_NE(m.find(d.string()), std::string::npos) << m;
    }
  }
  EXPECT_NO_THROW(OutputDirLock again(d));  // released with the first
  fs::remove_all(d);
}

TEST(OutputDirLock, NoLockFileIsLeftBesideTheOutputs) {
  const fs::path d = fresh_dir("output_file_test_lock_file");
  {
    const OutputDirLock lock(d);
    EXPECT_TRUE(fs::exists(d / ".abuopt.lock"));
  }
  EXPECT_FALSE(fs::exists(d / ".abuopt.lock"));
  // A file left by a killed run is taken over, and removed at the end.
  std::ofstream(d / ".abuopt.lock") << "12345\n";
  {
    const OutputDirLock lock(d);
  }
  EXPECT_FALSE(fs::exists(d / ".abuopt.lock"));
  fs::remove_all(d);
}

}  // namespace
}  // namespace abuopt
