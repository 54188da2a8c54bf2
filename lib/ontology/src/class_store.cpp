// ontology.sqlite through SQLite's C API: schema, migrations, transactional writes.
#include "scenewatch/ontology/class_store.h"

#include <sqlite3.h>

#include <functional>
#include <system_error>

#include "scenewatch/ontology/class_library.h"

namespace scenewatch::ontology {
namespace fs = std::filesystem;

namespace {

/// One migration: the SQL that turns version N into N+1 (index N-1 holds 1 -> 2, and so on).
/// Version 1 is created by kCreateV1; a new file is created at 1 and migrated like an old one, so
/// every migration runs in every test that creates a store.
const char* kCreateV1 =
    "CREATE TABLE schema_version (version INTEGER NOT NULL);"
    "INSERT INTO schema_version (version) VALUES (1);"
    "CREATE TABLE classes (name TEXT PRIMARY KEY NOT NULL, yaml TEXT NOT NULL);"
    "CREATE TABLE instances (id INTEGER PRIMARY KEY AUTOINCREMENT, class_name TEXT NOT NULL,"
    " parameters TEXT NOT NULL, time_s REAL NOT NULL);"
    "CREATE INDEX instances_by_class ON instances (class_name);";

const char* kMigrations[] = {
    // 1 -> 2: learnt motion constraints; when a class was defined.
    "CREATE TABLE constraints (class_name TEXT NOT NULL, dof TEXT NOT NULL, allowed INTEGER NOT NULL,"
    " time_s REAL NOT NULL, PRIMARY KEY (class_name, dof));"
    "ALTER TABLE classes ADD COLUMN defined_s REAL NOT NULL DEFAULT 0;",
};
static_assert(sizeof(kMigrations) / sizeof(kMigrations[0]) == ClassStore::kSchemaVersion - 1,
              "one migration per schema version step");

}  // namespace

struct ClassStore::Impl {
  sqlite3* db = nullptr;
  fs::path path;
  int opened_version = 0;

  ~Impl() {
    if (db) sqlite3_close_v2(db);
  }

  Error fail(const std::string& what) const {
    const int code = db ? sqlite3_errcode(db) : SQLITE_ERROR;
    std::string message = path.string() + ": " + what + ": " + (db ? sqlite3_errmsg(db) : "no database");
    if (code == SQLITE_NOTADB || code == SQLITE_CORRUPT) {
      message = path.string() + ": not a readable SQLite database (damaged, or a file of something else): " + what;
    }
    return code == SQLITE_IOERR || code == SQLITE_CANTOPEN || code == SQLITE_FULL || code == SQLITE_READONLY
               ? io_error(message)
               : invalid_argument(message);
  }

  Status exec(const char* sql, const std::string& what) const {
    char* error = nullptr;
    if (sqlite3_exec(db, sql, nullptr, nullptr, &error) != SQLITE_OK) {
      sqlite3_free(error);
      return fail(what);
    }
    return {};
  }

  /// Runs `body` in one IMMEDIATE transaction; rolls back on error.
  Status transaction(const std::string& what, const std::function<Status()>& body) const {
    if (Status s = exec("BEGIN IMMEDIATE", what); !s) return s;
    Status s = body();
    if (s) s = exec("COMMIT", what);
    if (!s) sqlite3_exec(db, "ROLLBACK", nullptr, nullptr, nullptr);
    return s;
  }
};

namespace {

/// A prepared statement, finalized on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const char* sql) { ok_ = sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) == SQLITE_OK; }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  bool ok() const { return ok_; }
  sqlite3_stmt* get() const { return stmt_; }
  void bind(int i, const std::string& s) { sqlite3_bind_text(stmt_, i, s.c_str(), static_cast<int>(s.size()), SQLITE_TRANSIENT); }
  void bind(int i, double v) { sqlite3_bind_double(stmt_, i, v); }
  void bind(int i, int v) { sqlite3_bind_int(stmt_, i, v); }
  int step() { return sqlite3_step(stmt_); }
  std::string text(int i) const {
    const auto* t = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, i));
    return t ? std::string(t) : std::string();
  }

 private:
  sqlite3_stmt* stmt_ = nullptr;
  bool ok_ = false;
};

}  // namespace

Result<ClassStore> ClassStore::open(const fs::path& path) {
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  std::error_code ec;
  const bool existed = fs::exists(path, ec);
  if (existed && !fs::is_regular_file(path, ec)) return invalid_argument(path.string() + ": not a regular file");
  if (sqlite3_open_v2(path.c_str(), &impl->db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, nullptr) !=
      SQLITE_OK) {
    return impl->fail("cannot open");
  }
  sqlite3_busy_timeout(impl->db, 5000);
  // The first read tells a database from anything else (SQLITE_NOTADB).
  Statement tables(impl->db, "SELECT name FROM sqlite_master WHERE type = 'table'");
  if (!tables.ok()) return impl->fail("cannot read its tables");
  bool has_version = false;
  int table_count = 0;
  for (int rc; (rc = tables.step()) != SQLITE_DONE;) {
    if (rc != SQLITE_ROW) return impl->fail("cannot read its tables");
    ++table_count;
    if (tables.text(0) == "schema_version") has_version = true;
  }
  if (table_count > 0 && !has_version) {
    return invalid_argument(path.string() + ": an SQLite database of something else (it has tables but no schema_version table)");
  }
  if (Status s = impl->exec("PRAGMA journal_mode = WAL", "cannot switch to WAL"); !s) return s.error();
  if (Status s = impl->exec("PRAGMA synchronous = FULL", "cannot set synchronous"); !s) return s.error();
  if (table_count == 0) {
    if (Status s = impl->transaction("cannot create the schema", [&] { return impl->exec(kCreateV1, "cannot create the schema"); }); !s) {
      return s.error();
    }
  }
  int version = 0;
  {
    Statement v(impl->db, "SELECT version FROM schema_version");
    if (!v.ok() || v.step() != SQLITE_ROW) return invalid_argument(path.string() + ": its schema_version table holds no version");
    version = sqlite3_column_int(v.get(), 0);
  }
  impl->opened_version = table_count == 0 ? 0 : version;
  if (version < 1) return invalid_argument(path.string() + ": schema version " + std::to_string(version) + " is not valid");
  if (version > kSchemaVersion) {
    return invalid_argument(path.string() + ": written by a newer scenewatch (schema version " + std::to_string(version) +
                            ", this build reads up to " + std::to_string(kSchemaVersion) + ")");
  }
  for (; version < kSchemaVersion; ++version) {
    const std::string what = "cannot migrate from schema version " + std::to_string(version) + " to " + std::to_string(version + 1);
    Status s = impl->transaction(what, [&]() -> Status {
      if (Status m = impl->exec(kMigrations[version - 1], what); !m) return m;
      const std::string set = "UPDATE schema_version SET version = " + std::to_string(version + 1);
      return impl->exec(set.c_str(), what);
    });
    if (!s) return s.error();
  }
  return ClassStore(std::move(impl));
}

ClassStore::ClassStore(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ClassStore::ClassStore(ClassStore&&) noexcept = default;
ClassStore& ClassStore::operator=(ClassStore&&) noexcept = default;
ClassStore::~ClassStore() = default;

int ClassStore::opened_version() const { return impl_->opened_version; }
const fs::path& ClassStore::path() const { return impl_->path; }

Status ClassStore::put_class(const ObjectClass& c, double time_s) {
  if (Status s = validate(c); !s) return s;
  return impl_->transaction("cannot store class '" + c.name + "'", [&]() -> Status {
    Statement st(impl_->db, "INSERT OR REPLACE INTO classes (name, yaml, defined_s) VALUES (?, ?, ?)");
    if (!st.ok()) return impl_->fail("cannot store class '" + c.name + "'");
    st.bind(1, c.name);
    st.bind(2, to_yaml(std::vector<ObjectClass>{c}));
    st.bind(3, time_s);
    if (st.step() != SQLITE_DONE) return impl_->fail("cannot store class '" + c.name + "'");
    return {};
  });
}

Result<std::vector<ObjectClass>> ClassStore::classes() const {
  Statement st(impl_->db, "SELECT name, yaml FROM classes ORDER BY name");
  if (!st.ok()) return impl_->fail("cannot read the classes");
  std::vector<ObjectClass> out;
  for (int rc; (rc = st.step()) != SQLITE_DONE;) {
    if (rc != SQLITE_ROW) return impl_->fail("cannot read the classes");
    auto parsed = parse_classes(st.text(1), impl_->path.string() + " (class '" + st.text(0) + "')");
    if (!parsed) return parsed.error();
    for (const auto& c : parsed->classes()) out.push_back(c);
  }
  return out;
}

Status ClassStore::add_instance(const InstanceRecord& instance) { return add_instances({instance}); }

Status ClassStore::add_instances(const std::vector<InstanceRecord>& instances) {
  return impl_->transaction("cannot store instances", [&]() -> Status {
    Statement st(impl_->db, "INSERT INTO instances (class_name, parameters, time_s) VALUES (?, ?, ?)");
    if (!st.ok()) return impl_->fail("cannot store instances");
    for (const auto& i : instances) {
      sqlite3_reset(st.get());
      st.bind(1, i.class_name);
      st.bind(2, i.parameters_json);
      st.bind(3, i.time_s);
      if (st.step() != SQLITE_DONE) return impl_->fail("cannot store instances");
    }
    return {};
  });
}

Result<std::vector<InstanceRecord>> ClassStore::instances(const std::string& class_name) const {
  Statement st(impl_->db, class_name.empty() ? "SELECT id, class_name, parameters, time_s FROM instances ORDER BY id"
                                             : "SELECT id, class_name, parameters, time_s FROM instances WHERE class_name = ? ORDER BY id");
  if (!st.ok()) return impl_->fail("cannot read the instances");
  if (!class_name.empty()) st.bind(1, class_name);
  std::vector<InstanceRecord> out;
  for (int rc; (rc = st.step()) != SQLITE_DONE;) {
    if (rc != SQLITE_ROW) return impl_->fail("cannot read the instances");
    out.push_back({sqlite3_column_int64(st.get(), 0), st.text(1), st.text(2), sqlite3_column_double(st.get(), 3)});
  }
  return out;
}

Status ClassStore::put_constraint(const ConstraintRecord& c) {
  static const char* kDofs[] = {"x", "y", "z", "roll", "pitch", "yaw"};
  bool known = false;
  for (const char* d : kDofs) known = known || c.dof == d;
  if (!known) return invalid_argument("constraint of '" + c.class_name + "': dof '" + c.dof + "' is not one of x, y, z, roll, pitch, yaw");
  return impl_->transaction("cannot store a constraint", [&]() -> Status {
    Statement st(impl_->db, "INSERT OR REPLACE INTO constraints (class_name, dof, allowed, time_s) VALUES (?, ?, ?, ?)");
    if (!st.ok()) return impl_->fail("cannot store a constraint");
    st.bind(1, c.class_name);
    st.bind(2, c.dof);
    st.bind(3, c.allowed ? 1 : 0);
    st.bind(4, c.time_s);
    if (st.step() != SQLITE_DONE) return impl_->fail("cannot store a constraint");
    return {};
  });
}

Result<std::vector<ConstraintRecord>> ClassStore::constraints() const {
  Statement st(impl_->db, "SELECT class_name, dof, allowed, time_s FROM constraints ORDER BY class_name, dof");
  if (!st.ok()) return impl_->fail("cannot read the constraints");
  std::vector<ConstraintRecord> out;
  for (int rc; (rc = st.step()) != SQLITE_DONE;) {
    if (rc != SQLITE_ROW) return impl_->fail("cannot read the constraints");
    out.push_back({st.text(0), st.text(1), sqlite3_column_int(st.get(), 2) != 0, sqlite3_column_double(st.get(), 3)});
  }
  return out;
}

}  // namespace scenewatch::ontology
