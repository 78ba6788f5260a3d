#include "abuopt/optimizer/evaluation_archive.hpp"

#include <sqlite3.h>

#include <chrono>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "abuopt/common/output_file.hpp"

#include "abuopt/common/config_error.hpp"
#include "abuopt/common/provenance.hpp"

namespace abuopt::opt {

namespace {

using json = nlohmann::json;

std::string hex_of(const std::vector<double>& v) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  s.reserve(16 * v.size());
  for (double d : v) {
    std::uint64_t bits;
    std::memcpy(&bits, &d, sizeof bits);
    for (int shift = 60; shift >= 0; shift -= 4) s.push_back(digits[(bits >> shift) & 0xf]);
  }
  return s;
}

std::vector<double> doubles_of_hex(const std::string& s) {
  if (s.size() % 16 != 0) throw std::runtime_error("evaluation archive: corrupt hex field");
  std::vector<double> v(s.size() / 16);
  for (std::size_t i = 0; i < v.size(); ++i) {
    std::uint64_t bits = std::stoull(s.substr(16 * i, 16), nullptr, 16);
    std::memcpy(&v[i], &bits, sizeof bits);
  }
  return v;
}

json number_json(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return v;
}

double json_number(const json& j) {
  if (j.is_number()) return j.get<double>();
  if (j.is_string()) {
    const std::string s = j.get<std::string>();
    if (s == "inf") return INFINITY;
    if (s == "-inf") return -INFINITY;
  }
  return NAN;
}

json vector_json(const std::vector<double>& v) {
  json a = json::array();
  for (double d : v) a.push_back(number_json(d));
  return a;
}

constexpr int kSchemaVersion = 2;

// FNV-1a, 64 bits, as 16 hex digits: any single changed byte changes it (each step is a bijection
// of the state for a given byte, and distinct bytes give distinct states).
std::string fnv1a64_hex(const std::string& text) {
  std::uint64_t h = 14695981039346656037ULL;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  char out[17];
  std::snprintf(out, sizeof out, "%016llx", static_cast<unsigned long long>(h));
  return out;
}

// The checksum of a row: every field that is read back, separated by a byte no field contains.
std::string row_checksum(const std::string& problem_id, const std::string& x_key, long runs,
                         const std::string& values_hex, long n_inequality, const std::string& metrics, long ok,
                         const std::string& message) {
  const char sep = '\x1f';
  std::string text = problem_id;
  text += sep;
  text += x_key;
  text += sep;
  text += std::to_string(runs);
  text += sep;
  text += values_hex;
  text += sep;
  text += std::to_string(n_inequality);
  text += sep;
  text += metrics;
  text += sep;
  text += std::to_string(ok);
  text += sep;
  text += message;
  return fnv1a64_hex(text);
}

// SQLite's own verdict on a damaged file (as opposed to a busy or full one).
bool is_corruption(int rc) { return (rc & 0xff) == SQLITE_CORRUPT || (rc & 0xff) == SQLITE_NOTADB; }
// The file cannot be written (disk full, a file-size limit, no permission, read-only): an output
// failure like any other file's (OutputError: exit status 4), not a failed computation.
// "file:/abs/path?immutable=1": a read-only WAL archive in a directory the reader cannot write
// (no -shm can be created beside it) is readable only as immutable.
std::string immutable_uri(const std::string& path) {
  std::string out = "file:";
  for (const unsigned char c : std::filesystem::absolute(path).string()) {
    if (std::isalnum(c) || std::strchr("/-._~", c)) {
      out += static_cast<char>(c);
    } else {
      static const char* hex = "0123456789ABCDEF";
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out + "?immutable=1";
}

bool is_write_failure(int rc) {
  const int p = rc & 0xff;
  return p == SQLITE_FULL || p == SQLITE_IOERR || p == SQLITE_READONLY || p == SQLITE_CANTOPEN || p == SQLITE_PERM;
}

std::string now_utc() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const long ms =
      static_cast<long>(std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[40];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  char out[48];
  std::snprintf(out, sizeof out, "%s.%03ldZ", buf, ms);
  return out;
}

// RAII prepared statement.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& path, const char* sql) : db_(db), path_(path) {
    const int rc = sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr);
    if (rc != SQLITE_OK) fail(rc);
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  void bind(int i, const std::string& s) { sqlite3_bind_text(stmt_, i, s.c_str(), -1, SQLITE_TRANSIENT); }
  void bind(int i, double d) {
    if (std::isnan(d)) sqlite3_bind_null(stmt_, i);
    else sqlite3_bind_double(stmt_, i, d);
  }
  void bind_int(int i, long v) { sqlite3_bind_int64(stmt_, i, v); }
  void reset() { sqlite3_reset(stmt_); }
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    fail(rc);
  }
  // A damaged file is the user's to repair (ConfigError); anything else is an I/O failure.
  [[noreturn]] void fail(int rc) const {
    const std::string why = sqlite3_errmsg(db_);
    if (is_corruption(rc))
      throw ConfigError("evaluation archive '" + path_ + "' is damaged (" + why +
                        "): move it away or delete it (its evaluations are recomputed)");
    if (is_write_failure(rc)) throw OutputError("cannot write the evaluation archive " + path_ + ": " + why);
    throw std::runtime_error("evaluation archive '" + path_ + "': " + why);
  }
  std::string text(int col) const {
    const unsigned char* t = sqlite3_column_text(stmt_, col);
    return t ? reinterpret_cast<const char*>(t) : "";
  }
  double real(int col) const { return sqlite3_column_double(stmt_, col); }
  long integer(int col) const { return static_cast<long>(sqlite3_column_int64(stmt_, col)); }

 private:
  sqlite3* db_;
  std::string path_;
  sqlite3_stmt* stmt_ = nullptr;
};

// Columns from `first`: values_hex, ok, message, metrics, n_inequality, checksum (then the caller's
// problem id, x_key and runs complete the checksum). nullopt: the row fails its checksum or does
// not parse (damaged).
std::optional<Evaluation> intact_evaluation_of(const Statement& s, int first, const std::string& problem_id,
                                               const std::string& x_key, long runs);

// Columns: values_hex, ok, message, metrics, n_inequality
Evaluation evaluation_of(const Statement& s, int first) {
  Evaluation e;
  const std::vector<double> values = doubles_of_hex(s.text(first));
  e.ok = s.integer(first + 1) != 0;
  e.message = s.text(first + 2);
  const json metrics = json::parse(s.text(first + 3));
  for (auto it = metrics.begin(); it != metrics.end(); ++it) e.metrics[it.key()] = json_number(it.value());
  const std::size_t n_ineq = static_cast<std::size_t>(s.integer(first + 4));
  if (values.empty() || values.size() < 1 + n_ineq) throw std::runtime_error("evaluation archive: corrupt values");
  e.objective = values[0];
  e.inequality.assign(values.begin() + 1, values.begin() + 1 + static_cast<long>(n_ineq));
  e.equality.assign(values.begin() + 1 + static_cast<long>(n_ineq), values.end());
  return e;
}

std::optional<Evaluation> intact_evaluation_of(const Statement& s, int first, const std::string& problem_id,
                                               const std::string& x_key, long runs) {
  const std::string expected = row_checksum(problem_id, x_key, runs, s.text(first), s.integer(first + 4),
                                            s.text(first + 3), s.integer(first + 1), s.text(first + 2));
  if (expected != s.text(first + 5)) return std::nullopt;
  try {
    return evaluation_of(s, first);
  } catch (const std::exception&) {  // right checksum, unreadable content: damaged all the same
    return std::nullopt;
  }
}

}  // namespace

std::string EvaluationArchive::key_of(const std::vector<double>& x) { return hex_of(x); }

EvaluationArchive::EvaluationArchive(const std::string& path, std::string problem_id, OpenMode mode)
    : path_(path), problem_id_(std::move(problem_id)), read_only_(mode == OpenMode::ReadOnly) {
  const int flags = read_only_ ? SQLITE_OPEN_READONLY | SQLITE_OPEN_FULLMUTEX
                               : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX;
  if (const int rc = sqlite3_open_v2(path.c_str(), &db_, flags, nullptr); rc != SQLITE_OK) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    if (is_write_failure(rc)) throw OutputError("cannot write the evaluation archive " + path + ": " + why);
    throw ConfigError("evaluation archive '" + path + "' cannot be opened: " + why);
  }
  if (read_only_ && !std::filesystem::exists(path + "-wal")) {
    // A WAL archive opened read-only needs its -shm file, which a read-only directory cannot hold:
    // the first read fails (SQLITE_READONLY / SQLITE_CANTOPEN). With no -wal file beside it no writer
    // is active and the file alone is the archive: it is then read as immutable.
    const int rc = sqlite3_exec(db_, "SELECT COUNT(*) FROM sqlite_master", nullptr, nullptr, nullptr) & 0xff;
    if (rc == SQLITE_READONLY || rc == SQLITE_CANTOPEN) {
      sqlite3_close(db_);
      db_ = nullptr;
      if (const int rc2 = sqlite3_open_v2(immutable_uri(path).c_str(), &db_,
                                          SQLITE_OPEN_READONLY | SQLITE_OPEN_URI | SQLITE_OPEN_FULLMUTEX, nullptr);
          rc2 != SQLITE_OK) {
        const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
        sqlite3_close(db_);
        db_ = nullptr;
        throw ConfigError("evaluation archive '" + path + "' cannot be opened: " + why);
      }
    }
  }
  sqlite3_busy_timeout(db_, 10000);
  try {
    // SQLite's own check of the file (pages, indexes): garbage in it ends here, naming the file
    {
      Statement check(db_, path_, "PRAGMA quick_check");
      const std::string verdict = check.step() ? check.text(0) : "no answer";
      if (verdict != "ok")
        throw ConfigError("evaluation archive '" + path_ + "' is damaged (" + verdict +
                          "): move it away or delete it (its evaluations are recomputed)");
    }
    long found = 0;
    bool existing = false;
    {  // (statements end before the journal mode changes: no open read transaction)
      Statement version(db_, path_, "PRAGMA user_version");
      version.step();
      found = version.integer(0);
      Statement tables(db_, path_,
                       "SELECT COUNT(*) FROM sqlite_master WHERE type = 'table' AND name = 'evaluations'");
      tables.step();
      existing = tables.integer(0) > 0;
    }
    if (existing && found != kSchemaVersion)
      throw ConfigError("evaluation archive '" + path_ + "' has schema version " + std::to_string(found) +
                        "; this abuopt reads version " + std::to_string(kSchemaVersion) +
                        " (checksums and run counts per evaluation): move it away or delete it (its evaluations "
                        "are recomputed)");
    if (read_only_) {
      if (!existing)
        throw ConfigError("archive", path_,
                          "is not an evaluation archive (no evaluations table: an empty or foreign file; "
                          "archives are written by optimize, sweep or pareto)");
      warn_ = [](const std::string& w) { std::cerr << "warning: " << w << "\n"; };
      return;  // a reader writes nothing: no journal mode, no schema
    }
    exec("PRAGMA journal_mode=WAL");
    exec("PRAGMA synchronous=NORMAL");
    // The schema (three tables and the version) in one transaction: a process killed while it
    // creates the archive leaves no schema or all of it, never tables without their version
    // (which the check above would refuse on resume).
    // (an existing archive needs no write lock here: at most the metadata table is added, one statement)
    if (!existing) exec("BEGIN IMMEDIATE");
    try {
      exec(
          "CREATE TABLE IF NOT EXISTS evaluations ("
          " id INTEGER PRIMARY KEY AUTOINCREMENT,"
          " problem_id TEXT NOT NULL,"
          " x_key TEXT NOT NULL,"        // hex of the bits of x (exact)
          " runs INTEGER NOT NULL,"      // Monte Carlo runs of the value (0: not a sampled problem)
          " x TEXT NOT NULL,"            // JSON array (readable)
          " objective REAL,"             // readable; NULL for NaN
          " values_hex TEXT NOT NULL,"   // hex of objective, g..., h... (exact)
          " n_inequality INTEGER NOT NULL,"
          " inequality TEXT NOT NULL,"   // JSON (readable)
          " equality TEXT NOT NULL,"     // JSON (readable)
          " metrics TEXT NOT NULL,"      // JSON object
          " ok INTEGER NOT NULL,"
          " message TEXT NOT NULL,"
          " wall_time_s REAL,"
          " timestamp TEXT NOT NULL,"
          " checksum TEXT NOT NULL,"     // row_checksum() of the fields read back
          " UNIQUE(problem_id, x_key, runs))");
      exec(
          "CREATE TABLE IF NOT EXISTS problems ("
          " problem_id TEXT PRIMARY KEY, name TEXT, variables TEXT, inequality TEXT, equality TEXT,"
          " created TEXT)");
      exec(
          "CREATE TABLE IF NOT EXISTS metadata ("
          " id INTEGER PRIMARY KEY AUTOINCREMENT, problem_id TEXT NOT NULL, timestamp TEXT NOT NULL,"
          " abuopt_version TEXT NOT NULL, git_commit TEXT NOT NULL, command TEXT NOT NULL, config TEXT NOT NULL,"
          " config_hash TEXT NOT NULL)");
      if (!existing) exec(("PRAGMA user_version = " + std::to_string(kSchemaVersion)).c_str());
      if (!existing) exec("COMMIT");
    } catch (...) {
      if (!existing) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
      throw;
    }
  } catch (const ConfigError&) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  } catch (const OutputError&) {  // cannot be written: exit 4 as for any output file
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  } catch (const std::exception& e) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw ConfigError("evaluation archive '" + path + "' is not usable: " + e.what());
  }
  warn_ = [](const std::string& w) { std::cerr << "warning: " << w << "\n"; };
}

int EvaluationArchive::schema_version() { return kSchemaVersion; }

void EvaluationArchive::set_warning_handler(std::function<void(const std::string&)> handler) {
  std::lock_guard<std::mutex> lock(mutex_);
  warn_ = std::move(handler);
}

void EvaluationArchive::discard_damaged(long id, const std::string& what) const {
  if (!read_only_) {  // a reader leaves the file as it is: the row is only left out
    Statement d(db_, path_, "DELETE FROM evaluations WHERE id = ?1");
    d.bind_int(1, id);
    d.step();
  }
  ++damaged_;
  if (warn_)
    warn_("evaluation archive '" + path_ + "': stored evaluation #" + std::to_string(id) +
          " fails its checksum (damaged): " + what);
}

EvaluationArchive::~EvaluationArchive() {
  if (db_) sqlite3_close(db_);
}

void EvaluationArchive::exec(const char* sql) const {
  char* err = nullptr;
  const int rc = sqlite3_exec(db_, sql, nullptr, nullptr, &err);
  if (rc != SQLITE_OK) {
    const std::string why = err ? err : "unknown error";
    sqlite3_free(err);
    if (is_corruption(rc))
      throw ConfigError("evaluation archive '" + path_ + "' is damaged (" + why +
                        "): move it away or delete it (its evaluations are recomputed)");
    if (is_write_failure(rc)) throw OutputError("cannot write the evaluation archive " + path_ + ": " + why);
    throw std::runtime_error("evaluation archive '" + path_ + "': " + why);
  }
}

std::optional<Evaluation> EvaluationArchive::find(const std::vector<double>& x, long runs) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string key = hex_of(x);
  Statement s(db_, path_,
              "SELECT values_hex, ok, message, metrics, n_inequality, checksum, id FROM evaluations"
              " WHERE problem_id = ?1 AND x_key = ?2 AND runs = ?3");
  s.bind(1, problem_id_);
  s.bind(2, key);
  s.bind_int(3, runs);
  if (!s.step()) return std::nullopt;
  std::optional<Evaluation> e = intact_evaluation_of(s, 0, problem_id_, key, runs);
  if (!e) {
    const long id = s.integer(6);
    s.reset();
    discard_damaged(id, "recomputed");
    return std::nullopt;
  }
  e->from_archive = true;
  return e;
}

void EvaluationArchive::store(const std::vector<double>& x, const Evaluation& e, double wall_time_s, long runs) {
  std::vector<double> values{e.objective};
  values.insert(values.end(), e.inequality.begin(), e.inequality.end());
  values.insert(values.end(), e.equality.begin(), e.equality.end());
  json metrics = json::object();
  for (const auto& [k, v] : e.metrics) metrics[k] = number_json(v);
  const std::string key = hex_of(x), values_hex = hex_of(values), metrics_text = metrics.dump();
  const long n_inequality = static_cast<long>(e.inequality.size()), ok = e.ok ? 1 : 0;
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_, path_,
              "INSERT OR IGNORE INTO evaluations (problem_id, x_key, runs, x, objective, values_hex, n_inequality,"
              " inequality, equality, metrics, ok, message, wall_time_s, timestamp, checksum)"
              " VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15)");
  s.bind(1, problem_id_);
  s.bind(2, key);
  s.bind_int(3, runs);
  s.bind(4, vector_json(x).dump());
  s.bind(5, e.objective);
  s.bind(6, values_hex);
  s.bind_int(7, n_inequality);
  s.bind(8, vector_json(e.inequality).dump());
  s.bind(9, vector_json(e.equality).dump());
  s.bind(10, metrics_text);
  s.bind_int(11, ok);
  s.bind(12, e.message);
  s.bind(13, wall_time_s);
  s.bind(14, now_utc());
  s.bind(15, row_checksum(problem_id_, key, runs, values_hex, n_inequality, metrics_text, ok, e.message));
  s.step();  // autocommit: one transaction per store
}

long EvaluationArchive::count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_, path_, "SELECT COUNT(*) FROM evaluations WHERE problem_id = ?1");
  s.bind(1, problem_id_);
  s.step();
  return s.integer(0);
}

std::vector<EvaluationArchive::Entry> EvaluationArchive::entries() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_, path_,
              "SELECT id, x_key, wall_time_s, timestamp, values_hex, ok, message, metrics, n_inequality, checksum,"
              " runs FROM evaluations WHERE problem_id = ?1 ORDER BY id");
  s.bind(1, problem_id_);
  std::vector<Entry> out;
  std::vector<long> damaged;
  while (s.step()) {
    Entry en;
    en.id = s.integer(0);
    en.runs = s.integer(10);
    const std::string key = s.text(1);
    std::optional<Evaluation> e = intact_evaluation_of(s, 4, problem_id_, key, en.runs);
    if (e) {
      try {
        en.x = doubles_of_hex(key);
      } catch (const std::exception&) {
        e.reset();
      }
    }
    if (!e) {
      damaged.push_back(en.id);
      continue;
    }
    en.wall_time_s = s.real(2);
    en.timestamp = s.text(3);
    en.evaluation = std::move(*e);
    en.evaluation.from_archive = true;
    out.push_back(std::move(en));
  }
  s.reset();
  for (long id : damaged) discard_damaged(id, "left out");
  return out;
}

void EvaluationArchive::check_signature(const Problem& problem) {
  json vars = json::array();
  for (const Variable& v : problem.variables()) vars.push_back(v.name);
  const std::string variables = vars.dump();
  const std::string ineq = json(problem.inequality_names()).dump();
  const std::string eq = json(problem.equality_names()).dump();
  std::lock_guard<std::mutex> lock(mutex_);
  Statement q(db_, path_, "SELECT variables, inequality, equality FROM problems WHERE problem_id = ?1");
  q.bind(1, problem_id_);
  if (q.step()) {
    auto differ = [&](const char* what, const std::string& stored, const std::string& now) {
      if (stored != now)
        throw ConfigError("evaluation archive '" + path_ + "': problem id '" + problem_id_ + "' was recorded with " +
                          what + " " + stored + ", this problem has " + now +
                          " (use another problem id for a different problem)");
    };
    differ("variables", q.text(0), variables);
    differ("inequality constraints", q.text(1), ineq);
    differ("equality constraints", q.text(2), eq);
    return;
  }
  Statement s(db_, path_,
              "INSERT INTO problems (problem_id, name, variables, inequality, equality, created)"
              " VALUES (?1, ?2, ?3, ?4, ?5, ?6)");
  s.bind(1, problem_id_);
  s.bind(2, problem.name());
  s.bind(3, variables);
  s.bind(4, ineq);
  s.bind(5, eq);
  s.bind(6, now_utc());
  s.step();
}

void EvaluationArchive::record_metadata(const std::string& command, const std::string& config,
                                        const std::string& config_hash) {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_, path_,
              "INSERT INTO metadata (problem_id, timestamp, abuopt_version, git_commit, command, config, config_hash)"
              " VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)");
  s.bind(1, problem_id_);
  s.bind(2, now_utc());
  s.bind(3, abuopt_version());
  s.bind(4, abuopt_git_commit());
  s.bind(5, command);
  s.bind(6, config);
  s.bind(7, config_hash);
  s.step();
}

std::vector<EvaluationArchive::Metadata> EvaluationArchive::metadata() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (read_only_) {  // an archive older than the metadata table: a writer adds it, a reader finds none
    Statement t(db_, path_, "SELECT COUNT(*) FROM sqlite_master WHERE type = 'table' AND name = 'metadata'");
    t.step();
    if (t.integer(0) == 0) return {};
  }
  Statement s(db_, path_,
              "SELECT id, problem_id, timestamp, abuopt_version, git_commit, command, config, config_hash"
              " FROM metadata WHERE problem_id = ?1 ORDER BY id");
  s.bind(1, problem_id_);
  std::vector<Metadata> out;
  while (s.step())
    out.push_back({s.integer(0), s.text(1), s.text(2), s.text(3), s.text(4), s.text(5), s.text(6), s.text(7)});
  return out;
}

std::vector<EvaluationArchive::ProblemRecord> EvaluationArchive::problems() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Statement s(db_, path_,
              "SELECT problem_id, name, variables, inequality, equality, created FROM problems ORDER BY rowid");
  auto names = [](const std::string& text) {
    std::vector<std::string> v;
    try {
      for (const auto& n : json::parse(text)) v.push_back(n.get<std::string>());
    } catch (const std::exception&) {
      throw std::runtime_error("evaluation archive: unreadable name list " + text);
    }
    return v;
  };
  std::vector<ProblemRecord> out;
  while (s.step()) out.push_back({s.text(0), s.text(1), names(s.text(2)), names(s.text(3)), names(s.text(4)), s.text(5)});
  return out;
}

ArchivedProblem::ArchivedProblem(Problem& inner, EvaluationArchive& archive) : inner_(inner), archive_(archive) {
  archive_.check_signature(inner_);
}

Evaluation ArchivedProblem::evaluate(const std::vector<double>& x) { return evaluate_shared(x, 1); }

Evaluation ArchivedProblem::evaluate_shared(const std::vector<double>& x, std::size_t concurrent) {
  return evaluate_sampled(x, inner_.sample_size(), concurrent);
}

long ArchivedProblem::runs_key(std::size_t n) const {
  return n == inner_.sample_size() ? 0 : static_cast<long>(n);
}

Evaluation ArchivedProblem::evaluate_sampled(const std::vector<double>& x, std::size_t n, std::size_t concurrent) {
  const long runs = runs_key(n);
  if (std::optional<Evaluation> hit = archive_.find(x, runs)) {
    ++hits_;
    return *hit;
  }
  const auto t0 = std::chrono::steady_clock::now();
  // an exception propagates and nothing is stored
  Evaluation e = runs != 0             ? inner_.evaluate_sampled(x, n, concurrent)
                 : concurrent > 1      ? inner_.evaluate_shared(x, concurrent)
                                       : inner_.evaluate(x);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  e.from_archive = false;
  archive_.store(x, e, wall, runs);
  ++misses_;
  return e;
}

std::vector<BatchEvaluation> ArchivedProblem::evaluate_batch(const std::vector<std::vector<double>>& xs,
                                                             EvaluationScheduler& scheduler) {
  return evaluate_batch_sampled(xs, inner_.sample_size(), scheduler);
}

std::vector<BatchEvaluation> ArchivedProblem::evaluate_batch_sampled(const std::vector<std::vector<double>>& xs,
                                                                     std::size_t n, EvaluationScheduler& scheduler) {
  const long runs = runs_key(n);
  std::vector<BatchEvaluation> out(xs.size());
  std::vector<std::size_t> miss;
  std::vector<std::vector<double>> miss_x;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    if (std::optional<Evaluation> hit = archive_.find(xs[i], runs)) {
      ++hits_;
      out[i].evaluation = std::move(*hit);
    } else {
      miss.push_back(i);
      miss_x.push_back(xs[i]);
    }
  }
  if (miss.empty()) return out;
  std::vector<BatchEvaluation> computed =
      runs != 0 ? inner_.evaluate_batch_sampled(miss_x, n, scheduler) : inner_.evaluate_batch(miss_x, scheduler);
  for (std::size_t k = 0; k < miss.size(); ++k) {
    BatchEvaluation& b = computed[k];
    if (!b.error) {  // a point whose evaluation threw is not stored
      b.evaluation.from_archive = false;
      archive_.store(miss_x[k], b.evaluation, b.wall_time_s, runs);
      ++misses_;
    }
    out[miss[k]] = std::move(b);
  }
  return out;
}

}  // namespace abuopt::opt
