#include "abuopt/common/output_file.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>

#include "abuopt/common/config_error.hpp"

namespace abuopt {

namespace fs = std::filesystem;

namespace {

std::string errno_text(int e) { return std::strerror(e); }

[[noreturn]] void fail(const fs::path& path, const std::string& what, int e) {
  throw OutputError("cannot write " + path.string() + ": " + what + " (" + errno_text(e) + ")");
}

// Writes all of `data` to fd; returns 0 or the errno of the failure.
int write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return 0;
}

fs::path temp_name(const fs::path& path) {
  static std::atomic<unsigned long> counter{0};
  return path.parent_path() /
         (path.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
}

}  // namespace

void write_file_atomic(const fs::path& path, const std::string& text) {
  // A device, FIFO or other special file (/dev/null, /dev/stdout, a pipe) is written directly:
  // renaming a temporary over it would replace the device with a regular file.
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!ec && fs::exists(st) && !fs::is_regular_file(st)) {
    if (fs::is_directory(st)) throw OutputError("cannot write " + path.string() + ": it is a directory");
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) fail(path, "cannot open it", errno);
    int e = write_all(fd, text.data(), text.size());
    if (::close(fd) != 0 && e == 0) e = errno;
    if (e != 0) fail(path, "writing failed", e);
    return;
  }
  const fs::path tmp = temp_name(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail(path, "cannot create " + tmp.string(), errno);
  int e = write_all(fd, text.data(), text.size());
  if (e == 0 && ::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) e = errno;
  if (::close(fd) != 0 && e == 0) e = errno;
  if (e == 0 && ::rename(tmp.c_str(), path.c_str()) != 0) e = errno;
  if (e != 0) {
    ::unlink(tmp.c_str());
    fail(path, "writing failed", e);
  }
}

AtomicFile::AtomicFile(fs::path path) : path_(std::move(path)) {}
AtomicFile::~AtomicFile() = default;

void AtomicFile::commit() {
  if (committed_) return;
  write_file_atomic(path_, buffer_.str());
  committed_ = true;
}

AppendFile::AppendFile(fs::path path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) fail(path_, "cannot create it", errno);
}

void AppendFile::append(const std::string& text) {
  if (fd_ < 0) throw OutputError("cannot write " + path_.string() + ": already closed");
  if (const int e = write_all(fd_, text.data(), text.size()); e != 0) fail(path_, "writing failed", e);
}

void AppendFile::close() {
  if (fd_ < 0) return;
  const int fd = fd_;
  fd_ = -1;
  int e = 0;
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) e = errno;
  if (::close(fd) != 0 && e == 0) e = errno;
  if (e != 0) fail(path_, "closing failed", e);
}

AppendFile::~AppendFile() {
  if (fd_ >= 0) ::close(fd_);
}

OutputDirLock::OutputDirLock(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw OutputError("cannot create the output directory " + dir.string() + " (" + ec.message() + ")");
  const fs::path lock = dir / ".abuopt.lock";
  // The holder removes the file when it ends (no .abuopt.lock is left beside the outputs). A run
  // that opened the file just before it was removed may then lock a file no longer in the folder:
  // it checks that the locked file is still the one at the path, and starts again if not.
  for (int attempt = 0;; ++attempt) {
    fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) fail(lock, "cannot create the lock file", errno);
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) break;  // held by another run: the message below
    struct stat held{}, named{};
    if (attempt >= 100 || (::fstat(fd_, &held) == 0 && ::stat(lock.c_str(), &named) == 0 && held.st_ino == named.st_ino &&
                           held.st_dev == named.st_dev)) {
      const std::string pid = std::to_string(::getpid()) + "\n";
      if (::ftruncate(fd_, 0) == 0) (void)write_all(fd_, pid.data(), pid.size());
      return;
    }
    ::close(fd_);  // the file was removed by the run that held it: lock the new one
  }
  {
    const int e = errno;
    char buf[32] = {};
    const ssize_t n = ::pread(fd_, buf, sizeof buf - 1, 0);
    ::close(fd_);
    fd_ = -1;
    if (e == EWOULDBLOCK) {
      std::string pid = n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string("?");
      while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
      throw ConfigError("output directory", dir.string(),
                        "is in use by another abuopt run (pid " + pid +
                            "); wait for it to finish or choose another output directory");
    }
    fail(lock, "cannot lock it", e);
  }
}

OutputDirLock::~OutputDirLock() {
  if (fd_ < 0) return;
  // Removed while still locked (see the constructor), then the lock released. After kill -9 the
  // file stays; the next run locks and removes it.
  // The locked file's path from the descriptor (the class keeps only the descriptor).
  char path[4096];
  const std::string link = "/proc/self/fd/" + std::to_string(fd_);
  const ssize_t n = ::readlink(link.c_str(), path, sizeof path - 1);
  if (n > 0) {
    path[n] = '\0';
    struct stat held{}, named{};
    if (::fstat(fd_, &held) == 0 && ::stat(path, &named) == 0 && held.st_ino == named.st_ino && held.st_dev == named.st_dev)
      (void)::unlink(path);
  }
  ::close(fd_);
}

}  // namespace abuopt
