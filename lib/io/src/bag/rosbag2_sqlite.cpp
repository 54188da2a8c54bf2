// rosbag2's SQLite storage (rosbag2_storage_default_plugins, the default up to Humble): tables
//   topics(id, name, type, serialization_format, offered_qos_profiles)
//   messages(id, topic_id, timestamp, data)
// one .db3 file per split of the bag. Messages are CDR ("cdr" serialization format).
#include <map>

#include <sqlite3.h>

#include "container.h"

namespace scenewatch::io::bag {
namespace {

struct Database {
  sqlite3* db = nullptr;
  std::string path;
  ~Database() { sqlite3_close(db); }
};

class Statement {
 public:
  Statement(sqlite3* db, const char* sql) { ok_ = sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr) == SQLITE_OK; }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  bool ok() const { return ok_; }
  sqlite3_stmt* get() { return stmt_; }

 private:
  sqlite3_stmt* stmt_ = nullptr;
  bool ok_ = false;
};

std::string text(sqlite3_stmt* s, int column) {
  const unsigned char* t = sqlite3_column_text(s, column);
  return t ? reinterpret_cast<const char*>(t) : "";
}

class Rosbag2Sqlite final : public Container {
 public:
  const std::vector<Topic>& topics() const override { return topics_; }
  const std::vector<MessageRef>& messages() const override { return messages_; }

  Result<std::vector<std::uint8_t>> read(const MessageRef& m) override {
    Database& d = *databases_[m.where[0]];
    Statement s(d.db, "SELECT data FROM messages WHERE id = ?");
    if (!s.ok()) return fail(d, "cannot read the messages table");
    sqlite3_bind_int64(s.get(), 1, static_cast<sqlite3_int64>(m.where[1]));
    if (sqlite3_step(s.get()) != SQLITE_ROW) return fail(d, "message row " + std::to_string(m.where[1]) + " cannot be read");
    const auto* p = static_cast<const std::uint8_t*>(sqlite3_column_blob(s.get(), 0));
    const int n = sqlite3_column_bytes(s.get(), 0);
    return std::vector<std::uint8_t>(p, p + n);
  }

  std::string locate(const MessageRef& m) const override {
    return databases_[m.where[0]]->path + ", row " + std::to_string(m.where[1]) + " of the messages table";
  }

  Status open(const std::vector<std::string>& files) {
    for (std::size_t f = 0; f < files.size(); ++f) {
      auto d = std::make_unique<Database>();
      d->path = files[f];
      if (sqlite3_open_v2(files[f].c_str(), &d->db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) return fail(*d, "cannot open it");
      databases_.push_back(std::move(d));
      if (auto st = read_index(f); !st) return st;
    }
    return {};
  }

 private:
  Error fail(const Database& d, const std::string& what) const {
    return invalid_argument(d.path + ": " + what + " (SQLite: " + (d.db ? sqlite3_errmsg(d.db) : "no database") + ")");
  }

  Status read_index(std::size_t f) {
    Database& d = *databases_[f];
    std::map<std::int64_t, std::uint32_t> topic_of_id;
    {
      Statement s(d.db, "SELECT id, name, type, serialization_format FROM topics");
      if (!s.ok()) return fail(d, "no topics table: not a rosbag2 SQLite file");
      int rc;
      while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
        const std::string name = text(s.get(), 1), type = text(s.get(), 2), format = text(s.get(), 3);
        if (format != "cdr") {
          return invalid_argument(d.path + ": topic '" + name + "' is serialized as '" + format + "', not 'cdr'");
        }
        std::uint32_t index = 0;
        while (index < topics_.size() && topics_[index].name != name) ++index;
        if (index == topics_.size()) topics_.push_back({name, normalise_type(type), WireFormat::kCdr});
        topic_of_id[sqlite3_column_int64(s.get(), 0)] = index;
      }
      if (rc != SQLITE_DONE) return fail(d, "the topics table cannot be read");
    }
    Statement s(d.db, "SELECT id, topic_id, timestamp FROM messages ORDER BY timestamp, id");
    if (!s.ok()) return fail(d, "no messages table: not a rosbag2 SQLite file");
    int rc;
    while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
      const std::int64_t row = sqlite3_column_int64(s.get(), 0), topic = sqlite3_column_int64(s.get(), 1);
      auto it = topic_of_id.find(topic);
      if (it == topic_of_id.end()) {
        return invalid_argument(d.path + ": message row " + std::to_string(row) + " names topic id " + std::to_string(topic) +
                                ", which the topics table does not have");
      }
      MessageRef m;
      m.topic = it->second;
      m.log_time_ns = sqlite3_column_int64(s.get(), 2);
      m.where[0] = f;
      m.where[1] = static_cast<std::uint64_t>(row);
      messages_.push_back(m);
    }
    if (rc != SQLITE_DONE) return fail(d, "the messages table cannot be read");
    return {};
  }

  std::vector<std::unique_ptr<Database>> databases_;
  std::vector<Topic> topics_;
  std::vector<MessageRef> messages_;
};

}  // namespace

Result<std::unique_ptr<Container>> open_rosbag2_sqlite(const std::vector<std::string>& db3_files) {
  auto bag = std::make_unique<Rosbag2Sqlite>();
  if (auto st = bag->open(db3_files); !st) return st.error();
  return std::unique_ptr<Container>(std::move(bag));
}

}  // namespace scenewatch::io::bag
