#pragma once
// Files abuopt writes are whole or absent, and a failed write is an error, never "wrote ...".
//
//   write_file_atomic(path, text)   writes <path>.tmp-<pid>-<n> in the same folder, checks every
//                                   write, flush and close, then renames it to `path`; on failure
//                                   the temporary is removed and `path` keeps its old content.
//                                   A device or FIFO (/dev/null, /dev/stdout) is written in place.
//   AtomicFile f(path); f.stream() << ...; f.commit();   the same for files built piece by piece
//                                   (destroyed without commit(): the temporary is removed).
//   OutputDirLock lock(dir);        one abuopt run per output folder (flock on <dir>/.abuopt.lock,
//                                   released when the process ends, even by kill -9).
//
// OutputError is what a failed write throws: the app exits with status 4 and prints the message
// (it names the file and the system's reason, e.g. "No space left on device").
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace abuopt {

class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void write_file_atomic(const std::filesystem::path& path, const std::string& text);

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream() { return buffer_; }
  template <class T>
  AtomicFile& operator<<(const T& v) {
    buffer_ << v;
    return *this;
  }
  const std::filesystem::path& path() const { return path_; }
  // Writes the collected text to the final name (write_file_atomic). Throws OutputError.
  void commit();

 private:
  std::filesystem::path path_;
  std::ostringstream buffer_;
  bool committed_ = false;
};

// A file that grows while a long study runs (one line per finished case, so nothing computed is
// lost if the study is interrupted): every append is flushed and checked.
class AppendFile {
 public:
  explicit AppendFile(std::filesystem::path path);  // truncates; throws OutputError
  void append(const std::string& text);             // throws OutputError
  void close();                                     // throws OutputError
  ~AppendFile();

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

class OutputDirLock {
 public:
  // Creates `dir` if needed and locks it. Throws ConfigError ("output directory <dir>: is in use by
  // another abuopt run (pid N)") when another process holds it; OutputError when the folder
  // cannot be created.
  explicit OutputDirLock(const std::filesystem::path& dir);
  ~OutputDirLock();
  OutputDirLock(const OutputDirLock&) = delete;
  OutputDirLock& operator=(const OutputDirLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace abuopt
