#include "tests/colmap_ext/modern_database.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace rig_calibrator {
namespace testing {
namespace {

// The tables and unique indices COLMAP 3.12 - 4.1 create, as in the COLMAP
// 4.1.1 database of tests/data/colmap_4_1_1 (without its CHECK constraints).
constexpr char kCommonTables[] =
    "CREATE TABLE rigs (rig_id INTEGER PRIMARY KEY AUTOINCREMENT NOT NULL, "
    "ref_sensor_id INTEGER NOT NULL, ref_sensor_type INTEGER NOT NULL);"
    "CREATE UNIQUE INDEX rig_ref_sensor_assignment ON rigs(ref_sensor_id, "
    "ref_sensor_type);"
    "CREATE TABLE rig_sensors (rig_id INTEGER NOT NULL, sensor_id INTEGER NOT "
    "NULL, sensor_type INTEGER NOT NULL, sensor_from_rig BLOB, FOREIGN "
    "KEY(rig_id) REFERENCES rigs(rig_id) ON DELETE CASCADE);"
    "CREATE UNIQUE INDEX rig_sensor_assignment ON rig_sensors(sensor_id, "
    "sensor_type);"
    "CREATE TABLE cameras (camera_id INTEGER PRIMARY KEY AUTOINCREMENT NOT "
    "NULL, model INTEGER NOT NULL, width INTEGER NOT NULL, height INTEGER NOT "
    "NULL, params BLOB, prior_focal_length INTEGER NOT NULL);"
    "CREATE TABLE frames (frame_id INTEGER PRIMARY KEY AUTOINCREMENT NOT "
    "NULL, rig_id INTEGER NOT NULL, FOREIGN KEY(rig_id) REFERENCES "
    "rigs(rig_id) ON DELETE CASCADE);"
    "CREATE TABLE frame_data (frame_id INTEGER NOT NULL, data_id INTEGER NOT "
    "NULL, sensor_id INTEGER NOT NULL, sensor_type INTEGER NOT NULL, FOREIGN "
    "KEY(frame_id) REFERENCES frames(frame_id) ON DELETE CASCADE);"
    "CREATE UNIQUE INDEX frame_sensor_assignment ON frame_data(data_id, "
    "sensor_type);"
    "CREATE TABLE images (image_id INTEGER PRIMARY KEY AUTOINCREMENT NOT "
    "NULL, name TEXT NOT NULL UNIQUE, camera_id INTEGER NOT NULL, FOREIGN "
    "KEY(camera_id) REFERENCES cameras(camera_id));"
    "CREATE TABLE keypoints (image_id INTEGER PRIMARY KEY NOT NULL, rows "
    "INTEGER NOT NULL, cols INTEGER NOT NULL, data BLOB);"
    "CREATE TABLE matches (pair_id INTEGER PRIMARY KEY NOT NULL, rows "
    "INTEGER NOT NULL, cols INTEGER NOT NULL, data BLOB);"
    "CREATE TABLE two_view_geometries (pair_id INTEGER PRIMARY KEY NOT NULL, "
    "rows INTEGER NOT NULL, cols INTEGER NOT NULL, data BLOB, config INTEGER "
    "NOT NULL, F BLOB, E BLOB, H BLOB, qvec BLOB, tvec BLOB);";

// 3.12 and 3.13: descriptors without `type`, pose priors keyed by image.
constexpr char kTables3x[] =
    "CREATE TABLE descriptors (image_id INTEGER PRIMARY KEY NOT NULL, rows "
    "INTEGER NOT NULL, cols INTEGER NOT NULL, data BLOB);"
    "CREATE TABLE pose_priors (image_id INTEGER PRIMARY KEY NOT NULL, "
    "position BLOB, coordinate_system INTEGER NOT NULL, position_covariance "
    "BLOB);";

// 4.0 and 4.1: descriptors with `type`, pose priors of any sensor data.
constexpr char kTables4x[] =
    "CREATE TABLE descriptors (image_id INTEGER PRIMARY KEY NOT NULL, type "
    "INTEGER NOT NULL, rows INTEGER NOT NULL, cols INTEGER NOT NULL, data "
    "BLOB);"
    "CREATE TABLE pose_priors (pose_prior_id INTEGER PRIMARY KEY NOT NULL, "
    "corr_data_id INTEGER NOT NULL, corr_sensor_id INTEGER NOT NULL, "
    "corr_sensor_type INTEGER NOT NULL, position BLOB, position_covariance "
    "BLOB, gravity BLOB, coordinate_system INTEGER NOT NULL);";

bool HasDescriptorType(ColmapSchema schema) {
  return schema == ColmapSchema::k4_0 || schema == ColmapSchema::k4_1;
}

int64_t PairId(uint32_t image_id1, uint32_t image_id2) {
  return 2147483647LL * std::min(image_id1, image_id2) +
         std::max(image_id1, image_id2);
}

}  // namespace

std::string ColmapSchemaName(const ColmapSchema schema) {
  switch (schema) {
    case ColmapSchema::k3_12:
      return "3.12";
    case ColmapSchema::k3_13:
      return "3.13";
    case ColmapSchema::k4_0:
      return "4.0";
    case ColmapSchema::k4_1:
      return "4.1";
  }
  return "";
}

int ColmapSchemaUserVersion(const ColmapSchema schema) {
  switch (schema) {
    case ColmapSchema::k3_12:
    case ColmapSchema::k3_13:
      return 3900;
    case ColmapSchema::k4_0:
      return 4000400;
    case ColmapSchema::k4_1:
      return 4010100;
  }
  return 0;
}

ModernDatabase::ModernDatabase(const std::string& path,
                               const ColmapSchema schema, const bool create)
    : schema_(schema) {
  EXPECT_EQ(sqlite3_open(path.c_str(), &database_), SQLITE_OK) << path;
  if (!create) return;
  Execute(std::string("PRAGMA journal_mode = WAL;") + kCommonTables +
          (HasDescriptorType(schema) ? kTables4x : kTables3x) +
          "PRAGMA user_version = " +
          std::to_string(ColmapSchemaUserVersion(schema)) + ";");
}

ModernDatabase::~ModernDatabase() { Close(); }

void ModernDatabase::Close() {
  if (database_ == nullptr) return;
  sqlite3_wal_checkpoint_v2(database_, nullptr, SQLITE_CHECKPOINT_TRUNCATE,
                            nullptr, nullptr);
  sqlite3_close(database_);
  database_ = nullptr;
}

void ModernDatabase::Execute(const std::string& sql) {
  char* message = nullptr;
  EXPECT_EQ(sqlite3_exec(database_, sql.c_str(), nullptr, nullptr, &message),
            SQLITE_OK)
      << (message != nullptr ? message : "") << " in " << sql;
  sqlite3_free(message);
}

void ModernDatabase::Bind(sqlite3_stmt* statement, const int index,
                          const void* data, const size_t num_bytes) {
  EXPECT_EQ(sqlite3_bind_blob(statement, index, data,
                              static_cast<int>(num_bytes), SQLITE_TRANSIENT),
            SQLITE_OK);
}

uint32_t ModernDatabase::AddCamera(const int model_id, const int width,
                                   const int height,
                                   const std::vector<double>& params,
                                   const bool prior_focal_length) {
  sqlite3_stmt* statement = nullptr;
  sqlite3_prepare_v2(database_,
                     "INSERT INTO cameras (model, width, height, params, "
                     "prior_focal_length) VALUES (?, ?, ?, ?, ?);",
                     -1, &statement, nullptr);
  sqlite3_bind_int(statement, 1, model_id);
  sqlite3_bind_int(statement, 2, width);
  sqlite3_bind_int(statement, 3, height);
  Bind(statement, 4, params.data(), params.size() * sizeof(double));
  sqlite3_bind_int(statement, 5, prior_focal_length ? 1 : 0);
  EXPECT_EQ(sqlite3_step(statement), SQLITE_DONE);
  sqlite3_finalize(statement);
  const uint32_t camera_id =
      static_cast<uint32_t>(sqlite3_last_insert_rowid(database_));
  Execute("INSERT INTO rigs (ref_sensor_id, ref_sensor_type) VALUES (" +
          std::to_string(camera_id) + ", 0);");
  return camera_id;
}

uint32_t ModernDatabase::AddImage(const std::string& name,
                                  const uint32_t camera_id) {
  sqlite3_stmt* statement = nullptr;
  sqlite3_prepare_v2(database_,
                     "INSERT INTO images (name, camera_id) VALUES (?, ?);", -1,
                     &statement, nullptr);
  sqlite3_bind_text(statement, 1, name.c_str(), -1, SQLITE_TRANSIENT);
  sqlite3_bind_int64(statement, 2, camera_id);
  EXPECT_EQ(sqlite3_step(statement), SQLITE_DONE) << name;
  sqlite3_finalize(statement);
  const uint32_t image_id =
      static_cast<uint32_t>(sqlite3_last_insert_rowid(database_));
  const std::string camera = std::to_string(camera_id);
  Execute(
      "INSERT INTO frames (rig_id) SELECT rig_id FROM rigs WHERE "
      "ref_sensor_id = " +
      camera +
      " AND ref_sensor_type = 0;"
      "INSERT INTO frame_data (frame_id, data_id, sensor_id, sensor_type) "
      "VALUES (last_insert_rowid(), " +
      std::to_string(image_id) + ", " + camera + ", 0);");
  return image_id;
}

void ModernDatabase::AddKeypoints(const uint32_t image_id, const int cols,
                                  const std::vector<float>& data) {
  sqlite3_stmt* statement = nullptr;
  sqlite3_prepare_v2(database_,
                     "INSERT INTO keypoints (image_id, rows, cols, data) "
                     "VALUES (?, ?, ?, ?);",
                     -1, &statement, nullptr);
  sqlite3_bind_int64(statement, 1, image_id);
  sqlite3_bind_int64(statement, 2, static_cast<int64_t>(data.size()) / cols);
  sqlite3_bind_int(statement, 3, cols);
  Bind(statement, 4, data.data(), data.size() * sizeof(float));
  EXPECT_EQ(sqlite3_step(statement), SQLITE_DONE);
  sqlite3_finalize(statement);
}

void ModernDatabase::AddSiftDescriptors(const uint32_t image_id,
                                        const std::vector<uint8_t>& data) {
  sqlite3_stmt* statement = nullptr;
  const bool typed = HasDescriptorType(schema_);
  sqlite3_prepare_v2(database_,
                     typed ? "INSERT INTO descriptors (image_id, rows, cols, "
                             "data, type) VALUES (?, ?, ?, ?, 0);"
                           : "INSERT INTO descriptors (image_id, rows, cols, "
                             "data) VALUES (?, ?, ?, ?);",
                     -1, &statement, nullptr);
  sqlite3_bind_int64(statement, 1, image_id);
  sqlite3_bind_int64(statement, 2, static_cast<int64_t>(data.size()) / 128);
  sqlite3_bind_int(statement, 3, 128);
  Bind(statement, 4, data.data(), data.size());
  EXPECT_EQ(sqlite3_step(statement), SQLITE_DONE);
  sqlite3_finalize(statement);
}

void ModernDatabase::AddFloatDescriptors(const uint32_t image_id,
                                         const int type, const int cols,
                                         const std::vector<float>& data) {
  ASSERT_TRUE(HasDescriptorType(schema_));
  sqlite3_stmt* statement = nullptr;
  sqlite3_prepare_v2(database_,
                     "INSERT INTO descriptors (image_id, rows, cols, data, "
                     "type) VALUES (?, ?, ?, ?, ?);",
                     -1, &statement, nullptr);
  sqlite3_bind_int64(statement, 1, image_id);
  sqlite3_bind_int64(statement, 2, static_cast<int64_t>(data.size()) / cols);
  sqlite3_bind_int(statement, 3, cols);
  Bind(statement, 4, data.data(), data.size() * sizeof(float));
  sqlite3_bind_int(statement, 5, type);
  EXPECT_EQ(sqlite3_step(statement), SQLITE_DONE);
  sqlite3_finalize(statement);
}

void ModernDatabase::AddTwoViewGeometry(
    const uint32_t image_id1, const uint32_t image_id2,
    const std::vector<std::pair<uint32_t, uint32_t>>& inliers,
    const int config) {
  // Stored with the smaller image id's keypoint index first.
  std::vector<uint32_t> data;
  for (const auto& [idx1, idx2] : inliers) {
    data.push_back(image_id1 < image_id2 ? idx1 : idx2);
    data.push_back(image_id1 < image_id2 ? idx2 : idx1);
  }
  for (const char* sql :
       {"INSERT INTO matches (pair_id, rows, cols, data) VALUES (?, ?, 2, ?);",
        "INSERT INTO two_view_geometries (pair_id, rows, cols, data, config) "
        "VALUES (?, ?, 2, ?, ?);"}) {
    sqlite3_stmt* statement = nullptr;
    sqlite3_prepare_v2(database_, sql, -1, &statement, nullptr);
    sqlite3_bind_int64(statement, 1, PairId(image_id1, image_id2));
    sqlite3_bind_int64(statement, 2, static_cast<int64_t>(inliers.size()));
    Bind(statement, 3, data.data(), data.size() * sizeof(uint32_t));
    if (sqlite3_bind_parameter_count(statement) == 4) {
      sqlite3_bind_int(statement, 4, config);
    }
    EXPECT_EQ(sqlite3_step(statement), SQLITE_DONE);
    sqlite3_finalize(statement);
  }
}

void ModernDatabase::GroupFrames(
    const std::vector<uint32_t>& camera_ids,
    const std::vector<std::optional<Rigid3d>>& sensor_from_rig,
    const std::vector<std::vector<uint32_t>>& frames) {
  ASSERT_EQ(camera_ids.size(), sensor_from_rig.size());
  for (const uint32_t camera_id : camera_ids) {
    Execute("DELETE FROM rigs WHERE ref_sensor_id = " +
            std::to_string(camera_id) + " AND ref_sensor_type = 0;");
  }
  Execute("INSERT INTO rigs (ref_sensor_id, ref_sensor_type) VALUES (" +
          std::to_string(camera_ids[0]) + ", 0);");
  const int64_t rig_id = sqlite3_last_insert_rowid(database_);
  for (size_t c = 1; c < camera_ids.size(); ++c) {
    sqlite3_stmt* statement = nullptr;
    sqlite3_prepare_v2(database_,
                       "INSERT INTO rig_sensors (rig_id, sensor_id, "
                       "sensor_type, sensor_from_rig) VALUES (?, ?, 0, ?);",
                       -1, &statement, nullptr);
    sqlite3_bind_int64(statement, 1, rig_id);
    sqlite3_bind_int64(statement, 2, camera_ids[c]);
    if (sensor_from_rig[c]) {
      const Rigid3d& pose = *sensor_from_rig[c];
      const double values[7] = {pose.rotation.w(),    pose.rotation.x(),
                                pose.rotation.y(),    pose.rotation.z(),
                                pose.translation.x(), pose.translation.y(),
                                pose.translation.z()};
      Bind(statement, 3, values, sizeof(values));
    }
    EXPECT_EQ(sqlite3_step(statement), SQLITE_DONE);
    sqlite3_finalize(statement);
  }
  for (const std::vector<uint32_t>& frame : frames) {
    Execute("INSERT INTO frames (rig_id) VALUES (" + std::to_string(rig_id) +
            ");");
    const std::string frame_id =
        std::to_string(sqlite3_last_insert_rowid(database_));
    for (const uint32_t image_id : frame) {
      const std::string image = std::to_string(image_id);
      Execute(
          "DELETE FROM frames WHERE frame_id IN (SELECT frame_id FROM "
          "frame_data WHERE data_id = " +
          image +
          " AND sensor_type = 0);"
          "DELETE FROM frame_data WHERE data_id = " +
          image +
          " AND sensor_type = 0;"
          "INSERT INTO frame_data (frame_id, data_id, sensor_id, sensor_type) "
          "SELECT " +
          frame_id + ", image_id, camera_id, 0 FROM images WHERE image_id = " +
          image + ";");
    }
  }
}

}  // namespace testing
}  // namespace rig_calibrator
