// ontology.sqlite: round trip, migration from a version 1 file made by hand, clear errors on
// damaged and foreign files, and a writer killed with SIGKILL mid-write.
#include <gtest/gtest.h>

#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "scenewatch/ontology/class_catalog.h"
#include "scenewatch/ontology/class_library.h"
#include "scenewatch/ontology/class_store.h"
#include "test_data.h"

namespace scenewatch::ontology {
namespace {

ObjectClass ball(double max_radius_m = 0.1) {
  ObjectClass c;
  c.name = "ball";
  c.shape = ClassShape::kSphere;
  c.radius_m = {0.02, max_radius_m};
  c.axis = ClassAxis::kAny;
  c.grasps = {{"top", GraspKind::kTop, 0.5}};
  c.allowed_dofs = {"x", "y", "z"};
  return c;
}

void run_sql(const std::filesystem::path& file, const char* sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql, nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

TEST(ClassStoreTest, RoundTrip) {
  test::TempDir dir("class-store");
  const auto file = dir / "ontology.sqlite";
  {
    auto store = ClassStore::open(file);
    ASSERT_TRUE(store.ok()) << store.error().message;
    EXPECT_EQ(store->opened_version(), 0);  // new
    ASSERT_TRUE(store->put_class(ball(), 1.0).ok());
    ASSERT_TRUE(store->put_class(ball(0.2), 2.0).ok());  // replaces
    ASSERT_TRUE(store->add_instance({0, "ball", R"({"radius_m":0.045})", 3.0}).ok());
    ASSERT_TRUE(store->put_constraint({"ball", "roll", true, 4.0}).ok());
    EXPECT_FALSE(store->put_constraint({"ball", "spin", true, 4.0}).ok());
    ObjectClass bad = ball();
    bad.radius_m = {0.3, 0.1};
    EXPECT_FALSE(store->put_class(bad, 5.0).ok());
  }
  auto store = ClassStore::open(file);
  ASSERT_TRUE(store.ok()) << store.error().message;
  EXPECT_EQ(store->opened_version(), ClassStore::kSchemaVersion);
  auto classes = store->classes();
  ASSERT_TRUE(classes.ok()) << classes.error().message;
  ASSERT_EQ(classes->size(), 1u);
  EXPECT_EQ(to_yaml((*classes)[0]), to_yaml(ball(0.2)));
  auto instances = store->instances("ball");
  ASSERT_TRUE(instances.ok());
  ASSERT_EQ(instances->size(), 1u);
  EXPECT_EQ((*instances)[0].parameters_json, R"({"radius_m":0.045})");
  EXPECT_DOUBLE_EQ((*instances)[0].time_s, 3.0);
  auto constraints = store->constraints();
  ASSERT_TRUE(constraints.ok());
  ASSERT_EQ(constraints->size(), 1u);
  EXPECT_EQ((*constraints)[0].dof, "roll");
}

// A version 1 file written by hand (the schema of the first release: classes without defined_s,
// no constraints table) is upgraded on open, its contents kept.
TEST(ClassStoreTest, MigratesVersion1) {
  test::TempDir dir("class-store-v1");
  const auto file = dir / "ontology.sqlite";
  const std::string yaml = to_yaml(std::vector<ObjectClass>{ball()});
  const std::string sql =
      "CREATE TABLE schema_version (version INTEGER NOT NULL); INSERT INTO schema_version VALUES (1);"
      "CREATE TABLE classes (name TEXT PRIMARY KEY NOT NULL, yaml TEXT NOT NULL);"
      "CREATE TABLE instances (id INTEGER PRIMARY KEY AUTOINCREMENT, class_name TEXT NOT NULL, parameters TEXT NOT NULL, time_s REAL NOT NULL);"
      "INSERT INTO classes VALUES ('ball', '" + yaml + "');"
      "INSERT INTO instances (class_name, parameters, time_s) VALUES ('ball', '{}', 7.5);";
  run_sql(file, sql.c_str());
  auto store = ClassStore::open(file);
  ASSERT_TRUE(store.ok()) << store.error().message;
  EXPECT_EQ(store->opened_version(), 1);
  auto classes = store->classes();
  ASSERT_TRUE(classes.ok());
  ASSERT_EQ(classes->size(), 1u);
  EXPECT_EQ((*classes)[0].name, "ball");
  auto instances = store->instances();
  ASSERT_TRUE(instances.ok());
  ASSERT_EQ(instances->size(), 1u);
  EXPECT_DOUBLE_EQ((*instances)[0].time_s, 7.5);
  // Version 2's additions work.
  EXPECT_TRUE(store->put_constraint({"ball", "yaw", false, 8.0}).ok());
  EXPECT_TRUE(store->put_class(ball(0.15), 9.0).ok());
  auto again = ClassStore::open(file);
  ASSERT_TRUE(again.ok()) << again.error().message;
  EXPECT_EQ(again->opened_version(), 2);
}

TEST(ClassStoreTest, DamagedForeignAndNewerFilesAreRefusedByName) {
  test::TempDir dir("class-store-bad");
  const auto garbage = dir / "garbage.sqlite";
  {
    std::ofstream out(garbage);
    out << std::string(4096, 'x');
  }
  auto a = ClassStore::open(garbage);
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.error().message.find(garbage.string()), std::string::npos) << a.error().message;
  EXPECT_NE(a.error().message.find("not a readable SQLite database"), std::string::npos) << a.error().message;

  const auto foreign = dir / "foreign.sqlite";
  run_sql(foreign, "CREATE TABLE photos (id INTEGER);");
  auto b = ClassStore::open(foreign);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("something else"), std::string::npos) << b.error().message;

  const auto newer = dir / "newer.sqlite";
  run_sql(newer, "CREATE TABLE schema_version (version INTEGER); INSERT INTO schema_version VALUES (99);");
  auto c = ClassStore::open(newer);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find("newer scenewatch (schema version 99"), std::string::npos) << c.error().message;

  auto d = ClassStore::open(dir / "no-such-folder" / "ontology.sqlite");
  EXPECT_FALSE(d.ok());
}

// A child writes batches of 20 instances, one transaction each, until it is killed with SIGKILL;
// the file then opens, passes SQLite's integrity check and holds whole batches only.
TEST(ClassStoreTest, SurvivesKillNineMidWrite) {
  test::TempDir dir("class-store-kill");
  const auto file = dir / "ontology.sqlite";
  ASSERT_TRUE(ClassStore::open(file).ok());
  constexpr int kBatch = 20;
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    auto store = ClassStore::open(file);
    if (!store.ok()) _exit(2);
    std::vector<InstanceRecord> batch(kBatch, InstanceRecord{0, "can", std::string(200, 'p'), 1.0});
    for (;;) {
      if (!store->add_instances(batch).ok()) _exit(3);
    }
  }
  // Let it write for a while, then kill it wherever it is.
  std::size_t seen = 0;
  for (int i = 0; i < 200 && seen < 5 * kBatch; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (auto reader = ClassStore::open(file); reader.ok()) {
      if (auto rows = reader->instances(); rows.ok()) seen = rows->size();
    }
  }
  ASSERT_EQ(kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the writer stopped on its own, status " << status;
  auto store = ClassStore::open(file);
  ASSERT_TRUE(store.ok()) << store.error().message;
  auto rows = store->instances();
  ASSERT_TRUE(rows.ok()) << rows.error().message;
  std::printf("killed after %zu instances were committed\n", rows->size());
  EXPECT_GT(rows->size(), 0u);
  EXPECT_EQ(rows->size() % kBatch, 0u) << "a batch was stored in part";
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* st = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "PRAGMA integrity_check", -1, &st, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(st), SQLITE_ROW);
  EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(st, 0)), "ok");
  sqlite3_finalize(st);
  sqlite3_close(db);
}

TEST(ClassCatalogTest, StoredClassesOverlayTheFileAndPersist) {
  test::TempDir dir("class-catalog");
  const auto classes_file = test::source_dir() / "config/ontology.yaml";
  const auto store = dir / kClassStoreFile;
  {
    auto catalog = ClassCatalog::open(classes_file, store);
    ASSERT_TRUE(catalog.ok()) << catalog.error().message;
    EXPECT_DOUBLE_EQ((*catalog)->library().find("ball")->radius_m.max, 0.12);  // the file's
    ASSERT_TRUE((*catalog)->define(ball(0.3), 1.0).ok());
    ObjectClass kettle = ball();
    kettle.name = "kettle";
    ASSERT_TRUE((*catalog)->define(kettle, 1.0).ok());
    kettle.name = "Bad Name";
    EXPECT_FALSE((*catalog)->define(kettle, 1.0).ok());
  }
  auto catalog = ClassCatalog::open(classes_file, store);
  ASSERT_TRUE(catalog.ok()) << catalog.error().message;
  const ClassLibrary library = (*catalog)->library();
  EXPECT_DOUBLE_EQ(library.find("ball")->radius_m.max, 0.3);  // the defined one, after a restart
  EXPECT_NE(library.find("kettle"), nullptr);
  EXPECT_NE(library.find("cup"), nullptr);
}

// What the daemon records: instances, and the learnt motions of a class from its handled
// instances (union of their free DoFs; the rest frozen), visible at once, in the store after a
// flush, and back after a restart. An unhandled instance teaches nothing; unknown objects never do.
TEST(ClassCatalogTest, RecordsInstancesAndLearntMotionsThatPersist) {
  test::TempDir dir("class-catalog-learnt");
  const auto classes_file = test::source_dir() / "config/ontology.yaml";
  const auto store = dir / kClassStoreFile;
  DofFlags turned{};  // carried and turned about its axis: x y z yaw
  turned[static_cast<std::size_t>(Dof::kX)] = turned[static_cast<std::size_t>(Dof::kY)] = true;
  turned[static_cast<std::size_t>(Dof::kZ)] = turned[static_cast<std::size_t>(Dof::kYaw)] = true;
  DofFlags tilted{};  // only tilted
  tilted[static_cast<std::size_t>(Dof::kRoll)] = true;
  {
    auto catalog = ClassCatalog::open(classes_file, store);
    ASSERT_TRUE(catalog.ok()) << catalog.error().message;
    ClassCatalog& c = **catalog;
    c.record({0, "cup", R"({"radius_m":0.04})", 1.0});  // seen, not handled
    EXPECT_TRUE(c.learnt().empty());
    c.record({0, "cup", R"({"radius_m":0.04})", 2.0}, turned);
    c.record({0, "unknown", "{}", 2.5}, tilted);  // no class to teach
    ASSERT_EQ(c.learnt().size(), 1u);
    EXPECT_EQ(c.learnt().at("cup").names(true), (std::vector<std::string>{"x", "y", "z", "yaw"}));
    EXPECT_EQ(c.learnt().at("cup").names(false), (std::vector<std::string>{"roll", "pitch"}));
    c.record({0, "cup", R"({"radius_m":0.041})", 3.0}, tilted);  // a second cup, tilted: roll joins
    EXPECT_EQ(c.learnt().at("cup").names(false), (std::vector<std::string>{"pitch"}));
    ASSERT_TRUE(c.flush().ok());
    auto reader = ClassStore::open(store);  // a second connection sees the committed rows
    ASSERT_TRUE(reader.ok()) << reader.error().message;
    auto instances = reader->instances();
    ASSERT_TRUE(instances.ok());
    ASSERT_EQ(instances->size(), 4u);
    EXPECT_EQ((*instances)[3].parameters_json, R"({"radius_m":0.041})");
    EXPECT_DOUBLE_EQ((*instances)[3].time_s, 3.0);
    auto constraints = reader->constraints();
    ASSERT_TRUE(constraints.ok());
    EXPECT_EQ(constraints->size(), 6u) << "one row per DoF of cup, none of unknown";
    c.record({0, "cup", "{}", 4.0});  // queued only: written when the catalog closes
  }
  auto catalog = ClassCatalog::open(classes_file, store);
  ASSERT_TRUE(catalog.ok()) << catalog.error().message;
  const auto learnt = (*catalog)->learnt();
  ASSERT_EQ(learnt.count("cup"), 1u);
  EXPECT_EQ(learnt.at("cup").names(true), (std::vector<std::string>{"x", "y", "z", "roll", "yaw"}));
  EXPECT_EQ(learnt.at("cup").names(false), (std::vector<std::string>{"pitch"}));
  auto reader = ClassStore::open(store);
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ(reader->instances("cup")->size(), 4u);
}

// Without a store the learnt motions live in memory and flush has nothing to wait for.
TEST(ClassCatalogTest, LearnsWithoutAStore) {
  auto catalog = ClassCatalog::open(test::source_dir() / "config/ontology.yaml", {});
  ASSERT_TRUE(catalog.ok()) << catalog.error().message;
  DofFlags free{};
  free[static_cast<std::size_t>(Dof::kZ)] = true;
  (*catalog)->record({0, "ball", "{}", 1.0}, free);
  EXPECT_TRUE((*catalog)->flush().ok());
  EXPECT_EQ((*catalog)->learnt().at("ball").names(true), (std::vector<std::string>{"z"}));
}

}  // namespace
}  // namespace scenewatch::ontology
