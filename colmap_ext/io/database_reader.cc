#include "colmap_ext/io/database_reader.h"

#include <colmap/base/camera_models.h>
#include <sqlite3.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "colmap_ext/io/colmap_camera_models.h"

namespace rig_calibrator {
namespace {

// COLMAP's kMaxNumImages (base/database.h): pair ids are
// kMaxNumImages * min_id + max_id.
constexpr uint64_t kMaxNumImages = 2147483647;

const char* const kColmap38Tables[] = {"cameras",   "images",
                                       "keypoints", "descriptors",
                                       "matches",   "two_view_geometries"};
// The rig tables of COLMAP >= 3.12: all four or none.
const char* const kRigTables[] = {"rigs", "rig_sensors", "frames",
                                  "frame_data"};

// COLMAP's sensor type of a camera in rig_sensors and frame_data.
constexpr int kSensorTypeCamera = 0;

// The `type` of COLMAP 4.x descriptors (src/colmap/feature/types.h).
constexpr int kSiftDescriptorType = 0;
std::string DescriptorTypeName(const int type) {
  switch (type) {
    case -1:
      return "UNDEFINED (-1)";
    case 0:
      return "SIFT (0)";
    case 1:
      return "ALIKED_N16ROT (1)";
    case 2:
      return "ALIKED_N32 (2)";
    default:
      return "unknown type " + std::to_string(type);
  }
}

// Column names of a table.
std::set<std::string> TableColumns(sqlite3* database,
                                   const std::string& table) {
  std::set<std::string> columns;
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v2(database,
                         ("PRAGMA table_info(" + table + ");").c_str(), -1,
                         &statement, nullptr) == SQLITE_OK) {
    while (sqlite3_step(statement) == SQLITE_ROW) {
      columns.insert(
          reinterpret_cast<const char*>(sqlite3_column_text(statement, 1)));
    }
  }
  sqlite3_finalize(statement);
  return columns;
}

// Percent-encodes a file path for an SQLite "file:" URI (RFC 3986 unreserved
// characters and '/' stay as they are).
std::string EscapeUriPath(const std::string& path) {
  static const char kHex[] = "0123456789ABCDEF";
  std::string escaped;
  for (const unsigned char c : path) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '_' || c == '.' ||
        c == '~') {
      escaped += static_cast<char>(c);
    } else {
      escaped += '%';
      escaped += kHex[c >> 4];
      escaped += kHex[c & 15];
    }
  }
  return escaped;
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string joined;
  for (const std::string& name : names) {
    joined += (joined.empty() ? "" : ", ") + name;
  }
  return joined;
}

// Resets and clears the bindings of a statement when leaving a scope, so a
// cached statement never keeps a read transaction open.
class StatementScope {
 public:
  explicit StatementScope(sqlite3_stmt* statement) : statement_(statement) {}
  ~StatementScope() {
    sqlite3_reset(statement_);
    sqlite3_clear_bindings(statement_);
  }

 private:
  sqlite3_stmt* statement_;
};

// The (rows, cols, data) columns of the row a statement stepped to: COLMAP's
// layout of keypoints, descriptors and matches.
struct BlobMatrix {
  int64_t rows = 0;
  int64_t cols = 0;
  int num_bytes = 0;
  const void* data = nullptr;

  static BlobMatrix OfRow(sqlite3_stmt* statement) {
    return {
        sqlite3_column_int64(statement, 0), sqlite3_column_int64(statement, 1),
        sqlite3_column_bytes(statement, 2), sqlite3_column_blob(statement, 2)};
  }
  // "(rows x cols, num_bytes bytes)".
  std::string ShapeText() const {
    return "(" + std::to_string(rows) + "x" + std::to_string(cols) + ", " +
           std::to_string(num_bytes) + " bytes)";
  }
};

// Steps the keypoints or descriptors `statement` for `image_id`; false with
// "<what> are missing" when the image has none.
bool StepFeatureRow(sqlite3_stmt* statement, const colmap::image_t image_id,
                    const std::string& what, BlobMatrix* blob,
                    std::string* error) {
  sqlite3_bind_int64(statement, 1, image_id);
  if (sqlite3_step(statement) != SQLITE_ROW) {
    *error = what + " are missing (run `colmap feature_extractor` on it)";
    return false;
  }
  *blob = BlobMatrix::OfRow(statement);
  return true;
}

// A regular file that starts with the 16-byte SQLite header: checking it
// first gives a clear message instead of SQLite's "file is not a database".
bool CheckSqliteFile(const std::string& path, std::string* problem) {
  namespace fs = std::filesystem;
  std::error_code fs_error;
  if (!fs::exists(path, fs_error)) {
    *problem = "no such file";
    return false;
  }
  if (!fs::is_regular_file(path, fs_error)) {
    *problem = "not a regular file";
    return false;
  }
  static const char kSqliteHeader[16] = "SQLite format 3";
  char header[16] = {};
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    *problem = "cannot be opened for reading";
    return false;
  }
  file.read(header, sizeof(header));
  if (file.gcount() != sizeof(header) ||
      std::memcmp(header, kSqliteHeader, sizeof(header)) != 0) {
    *problem =
        "not an SQLite file, so not a COLMAP database (create one with "
        "`colmap feature_extractor --database_path ...`)";
    return false;
  }
  return true;
}

// COLMAP leaves its databases in WAL mode. A read-only connection to a WAL
// database creates "-shm"/"-wal" files next to it; `immutable=1` avoids
// that (no locks, no side files). A non-empty "-wal" file holds committed
// data not yet copied into the database (COLMAP still running or killed),
// which only a normal read-only connection reads.
std::string ReadOnlyUri(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code fs_error;
  const fs::path wal_path = path + "-wal";
  const bool has_pending_wal =
      fs::exists(wal_path, fs_error) && fs::file_size(wal_path, fs_error) > 0;
  const std::string absolute_path = fs::absolute(path, fs_error).string();
  return "file:" + EscapeUriPath(absolute_path) +
         (has_pending_wal ? "?mode=ro" : "?mode=ro&immutable=1");
}

}  // namespace

DatabaseReader::DatabaseReader() = default;

DatabaseReader::~DatabaseReader() { Close(); }

void DatabaseReader::Close() {
  for (sqlite3_stmt** statement :
       {&read_camera_, &count_keypoints_, &count_descriptors_, &read_keypoints_,
        &read_descriptors_, &read_inlier_matches_}) {
    sqlite3_finalize(*statement);
    *statement = nullptr;
  }
  if (database_ != nullptr) {
    sqlite3_close(database_);
    database_ = nullptr;
  }
  images_.clear();
  rigs_.clear();
  frames_.clear();
  has_rigs_ = false;
  descriptors_have_type_ = false;
  images_have_priors_ = false;
  image_index_by_name_.clear();
  image_index_by_id_.clear();
  user_version_ = 0;
}

bool DatabaseReader::Open(const std::string& path, std::string* error) {
  Close();
  path_ = path;
  const std::string prefix = "database " + path + ": ";
  std::string problem;
  if (!CheckSqliteFile(path, &problem)) {
    *error = prefix + problem;
    return false;
  }
  const std::string uri = ReadOnlyUri(path);
  if (sqlite3_open_v2(
          uri.c_str(), &database_,
          SQLITE_OPEN_READONLY | SQLITE_OPEN_URI | SQLITE_OPEN_FULLMUTEX,
          nullptr) != SQLITE_OK) {
    *error = prefix + "SQLite cannot open it read-only: " +
             (database_ != nullptr ? sqlite3_errmsg(database_) : "no memory");
    Close();
    return false;
  }
  if (!CheckSchema(error) || !ReadImages(error) || !ReadRigsAndFrames(error) ||
      !PrepareStatements(error)) {
    *error = prefix + *error;
    Close();
    return false;
  }
  return true;
}

bool DatabaseReader::PrepareStatements(std::string* error) {
  const struct {
    sqlite3_stmt** statement;
    const char* sql;
  } statements[] = {
      {&read_camera_,
       "SELECT model, width, height, params, prior_focal_length FROM cameras "
       "WHERE camera_id = ?;"},
      {&count_keypoints_, "SELECT rows FROM keypoints WHERE image_id = ?;"},
      {&count_descriptors_, "SELECT rows FROM descriptors WHERE image_id = ?;"},
      {&read_keypoints_,
       "SELECT rows, cols, data FROM keypoints WHERE image_id = ?;"},
      {&read_descriptors_,
       descriptors_have_type_
           ? "SELECT rows, cols, data, type FROM descriptors WHERE image_id = "
             "?;"
           : "SELECT rows, cols, data FROM descriptors WHERE image_id = ?;"},
      {&read_inlier_matches_,
       "SELECT rows, cols, data FROM two_view_geometries WHERE pair_id = ?;"},
  };
  for (const auto& [statement, sql] : statements) {
    if (sqlite3_prepare_v2(database_, sql, -1, statement, nullptr) !=
        SQLITE_OK) {
      *error = std::string("unexpected schema: ") + sqlite3_errmsg(database_);
      return false;
    }
  }
  return true;
}

bool DatabaseReader::CheckSchema(std::string* error) {
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v2(database_,
                         "SELECT name FROM sqlite_master WHERE type='table';",
                         -1, &statement, nullptr) != SQLITE_OK) {
    *error = std::string("not a readable SQLite database: ") +
             sqlite3_errmsg(database_);
    return false;
  }
  std::set<std::string> tables;
  while (sqlite3_step(statement) == SQLITE_ROW) {
    tables.insert(
        reinterpret_cast<const char*>(sqlite3_column_text(statement, 0)));
  }
  sqlite3_finalize(statement);

  if (sqlite3_prepare_v2(database_, "PRAGMA user_version;", -1, &statement,
                         nullptr) == SQLITE_OK &&
      sqlite3_step(statement) == SQLITE_ROW) {
    user_version_ = sqlite3_column_int(statement, 0);
  }
  sqlite3_finalize(statement);

  std::vector<std::string> missing;
  for (const char* table : kColmap38Tables) {
    if (tables.count(table) == 0) missing.push_back(table);
  }
  if (missing.size() == std::size(kColmap38Tables)) {
    *error =
        "an SQLite file but not a COLMAP database (none of the tables "
        "cameras, images, keypoints, descriptors, matches, "
        "two_view_geometries)";
    return false;
  }
  if (!missing.empty()) {
    *error = "not a complete COLMAP database: missing table(s) " +
             JoinNames(missing) +
             (tables.count("inlier_matches") > 0
                  ? " (it is from COLMAP older than 3.5; open a copy of it "
                    "with COLMAP 3.8, e.g. `colmap database_creator`, to "
                    "upgrade it)"
                  : "");
    return false;
  }
  std::vector<std::string> rig_tables;
  std::vector<std::string> missing_rig_tables;
  for (const char* table : kRigTables) {
    (tables.count(table) > 0 ? rig_tables : missing_rig_tables)
        .push_back(table);
  }
  if (!rig_tables.empty() && !missing_rig_tables.empty()) {
    *error = "not a complete COLMAP >= 3.12 database: it has the table(s) " +
             JoinNames(rig_tables) + " but not " +
             JoinNames(missing_rig_tables);
    return false;
  }
  has_rigs_ = !rig_tables.empty();
  images_have_priors_ = TableColumns(database_, "images").count("prior_qw") > 0;
  descriptors_have_type_ =
      TableColumns(database_, "descriptors").count("type") > 0;
  return CheckDescriptorTypes(error);
}

bool DatabaseReader::CheckDescriptorTypes(std::string* error) {
  if (!descriptors_have_type_) return true;
  // One row per image with descriptors: the scan reads each row's header,
  // not its blob.
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v2(database_,
                         "SELECT type, COUNT(*), MIN(image_id) FROM "
                         "descriptors GROUP BY type ORDER BY type;",
                         -1, &statement, nullptr) != SQLITE_OK) {
    *error = std::string("cannot read the descriptors table: ") +
             sqlite3_errmsg(database_);
    return false;
  }
  std::string other_types;
  while (sqlite3_step(statement) == SQLITE_ROW) {
    const int type = sqlite3_column_int(statement, 0);
    if (type == kSiftDescriptorType) continue;
    other_types += (other_types.empty() ? "" : ", ") +
                   DescriptorTypeName(type) + " for " +
                   std::to_string(sqlite3_column_int64(statement, 1)) +
                   " image(s), e.g. image id " +
                   std::to_string(sqlite3_column_int64(statement, 2));
  }
  sqlite3_finalize(statement);
  if (!other_types.empty()) {
    *error = "the descriptors are not all SIFT: " + other_types +
             ". rig_calibrator matches SIFT descriptors (type 0) only: "
             "extract the features of the map and rig images with COLMAP's "
             "SIFT extractor (the default of `colmap feature_extractor`)";
    return false;
  }
  return true;
}

std::string DatabaseReader::SchemaDescription() const {
  std::string version;
  if (user_version_ >= 4000000) {
    const int major = user_version_ / 1000000;
    const int minor = user_version_ / 10000 % 100;
    const int patch = user_version_ / 100 % 100;
    version = "COLMAP " + std::to_string(major) + "." + std::to_string(minor) +
              "." + std::to_string(patch);
    if (user_version_ > 4019999) version += " (newer than 4.1, read as 4.1)";
  } else if (user_version_ == 3900 || (user_version_ == 0 && has_rigs_)) {
    version = "COLMAP 3.12 or 3.13";
  } else if (images_have_priors_) {
    version = "COLMAP 3.8 or older";
  } else {
    // pose_priors without rigs: 3.10 and 3.11.
    version = "COLMAP 3.10 or 3.11";
  }
  return version + " schema (user_version " + std::to_string(user_version_) +
         ")";
}

bool DatabaseReader::ReadRigsAndFrames(std::string* error) {
  if (!has_rigs_) return true;
  auto fail = [&](const std::string& table) {
    *error =
        "cannot read the " + table + " table: " + sqlite3_errmsg(database_);
    return false;
  };
  std::unordered_map<uint32_t, size_t> rig_index;
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v2(database_,
                         "SELECT rig_id, ref_sensor_id, ref_sensor_type FROM "
                         "rigs ORDER BY rig_id;",
                         -1, &statement, nullptr) != SQLITE_OK) {
    return fail("rigs");
  }
  while (sqlite3_step(statement) == SQLITE_ROW) {
    DatabaseRig rig;
    rig.rig_id = static_cast<uint32_t>(sqlite3_column_int64(statement, 0));
    if (sqlite3_column_int(statement, 2) == kSensorTypeCamera) {
      rig.ref_camera_id =
          static_cast<colmap::camera_t>(sqlite3_column_int64(statement, 1));
    }
    rig_index[rig.rig_id] = rigs_.size();
    rigs_.push_back(rig);
  }
  sqlite3_finalize(statement);

  if (sqlite3_prepare_v2(database_,
                         "SELECT rig_id, sensor_id, sensor_from_rig FROM "
                         "rig_sensors WHERE sensor_type = 0 ORDER BY rig_id, "
                         "sensor_id;",
                         -1, &statement, nullptr) != SQLITE_OK) {
    return fail("rig_sensors");
  }
  while (sqlite3_step(statement) == SQLITE_ROW) {
    const uint32_t rig_id =
        static_cast<uint32_t>(sqlite3_column_int64(statement, 0));
    const auto rig = rig_index.find(rig_id);
    if (rig == rig_index.end()) continue;  // COLMAP deletes them in cascade
    DatabaseRig::Sensor sensor;
    sensor.camera_id =
        static_cast<colmap::camera_t>(sqlite3_column_int64(statement, 1));
    // 7 doubles qw, qx, qy, qz, tx, ty, tz; NULL when unknown.
    if (sqlite3_column_type(statement, 2) != SQLITE_NULL) {
      if (sqlite3_column_bytes(statement, 2) != 7 * sizeof(double)) {
        sqlite3_finalize(statement);
        *error = "rig_sensors: the sensor_from_rig of camera " +
                 std::to_string(sensor.camera_id) + " in rig " +
                 std::to_string(rig_id) + " is not 7 doubles";
        return false;
      }
      double v[7];
      std::memcpy(v, sqlite3_column_blob(statement, 2), sizeof(v));
      sensor.sensor_from_rig =
          Rigid3d(Eigen::Quaterniond(v[0], v[1], v[2], v[3]).normalized(),
                  Eigen::Vector3d(v[4], v[5], v[6]));
    }
    rigs_[rig->second].cameras.push_back(sensor);
  }
  sqlite3_finalize(statement);

  std::unordered_map<uint32_t, size_t> frame_index;
  if (sqlite3_prepare_v2(database_,
                         "SELECT frame_id, rig_id FROM frames ORDER BY "
                         "frame_id;",
                         -1, &statement, nullptr) != SQLITE_OK) {
    return fail("frames");
  }
  while (sqlite3_step(statement) == SQLITE_ROW) {
    DatabaseFrame frame;
    frame.frame_id = static_cast<uint32_t>(sqlite3_column_int64(statement, 0));
    frame.rig_id = static_cast<uint32_t>(sqlite3_column_int64(statement, 1));
    frame_index[frame.frame_id] = frames_.size();
    frames_.push_back(frame);
  }
  sqlite3_finalize(statement);
  if (sqlite3_prepare_v2(database_,
                         "SELECT frame_id, data_id FROM frame_data WHERE "
                         "sensor_type = 0 ORDER BY frame_id, data_id;",
                         -1, &statement, nullptr) != SQLITE_OK) {
    return fail("frame_data");
  }
  while (sqlite3_step(statement) == SQLITE_ROW) {
    const auto frame = frame_index.find(
        static_cast<uint32_t>(sqlite3_column_int64(statement, 0)));
    if (frame == frame_index.end()) continue;
    frames_[frame->second].image_ids.push_back(
        static_cast<colmap::image_t>(sqlite3_column_int64(statement, 1)));
  }
  sqlite3_finalize(statement);
  return true;
}

bool DatabaseReader::ReadImages(std::string* error) {
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v2(
          database_,
          "SELECT image_id, name, camera_id FROM images ORDER BY image_id;", -1,
          &statement, nullptr) != SQLITE_OK) {
    *error = std::string("cannot read the images table: ") +
             sqlite3_errmsg(database_);
    return false;
  }
  int rc;
  while ((rc = sqlite3_step(statement)) == SQLITE_ROW) {
    DatabaseImage image;
    image.image_id =
        static_cast<colmap::image_t>(sqlite3_column_int64(statement, 0));
    const unsigned char* name = sqlite3_column_text(statement, 1);
    image.name = name != nullptr ? reinterpret_cast<const char*>(name) : "";
    image.camera_id =
        static_cast<colmap::camera_t>(sqlite3_column_int64(statement, 2));
    image_index_by_name_[image.name] = images_.size();
    image_index_by_id_[image.image_id] = images_.size();
    images_.push_back(std::move(image));
  }
  sqlite3_finalize(statement);
  if (rc != SQLITE_DONE) {
    *error = std::string("cannot read the images table: ") +
             sqlite3_errmsg(database_);
    return false;
  }
  return true;
}

const DatabaseImage* DatabaseReader::FindImageWithName(
    const std::string& name) const {
  const auto it = image_index_by_name_.find(name);
  return it == image_index_by_name_.end() ? nullptr : &images_[it->second];
}

const DatabaseImage* DatabaseReader::FindImageWithId(
    const colmap::image_t image_id) const {
  const auto it = image_index_by_id_.find(image_id);
  return it == image_index_by_id_.end() ? nullptr : &images_[it->second];
}

bool DatabaseReader::ReadCamera(const colmap::camera_t camera_id,
                                DatabaseCamera* camera,
                                std::string* error) const {
  std::lock_guard<std::mutex> lock(mutex_);
  StatementScope scope(read_camera_);
  sqlite3_bind_int64(read_camera_, 1, camera_id);
  if (sqlite3_step(read_camera_) != SQLITE_ROW) {
    *error = "database " + path_ + ": no camera with id " +
             std::to_string(camera_id);
    return false;
  }
  *camera = DatabaseCamera();
  camera->camera_id = camera_id;
  camera->model_id = sqlite3_column_int(read_camera_, 0);
  camera->model_name = ColmapCameraModelName(camera->model_id);
  camera->known_to_colmap38 = colmap::ExistsCameraModelWithId(camera->model_id);
  camera->width = static_cast<size_t>(sqlite3_column_int64(read_camera_, 1));
  camera->height = static_cast<size_t>(sqlite3_column_int64(read_camera_, 2));
  camera->prior_focal_length = sqlite3_column_int(read_camera_, 4) != 0;
  const int num_bytes = sqlite3_column_bytes(read_camera_, 3);
  const int num_params = ColmapCameraModelNumParams(camera->model_id);
  if (num_params >= 0 &&
      static_cast<size_t>(num_bytes) != num_params * sizeof(double)) {
    *error = "database " + path_ + ": camera " + std::to_string(camera_id) +
             " has " + std::to_string(num_bytes / sizeof(double)) +
             " parameters, its model " + camera->model_name + " needs " +
             std::to_string(num_params);
    return false;
  }
  camera->params.resize(num_bytes / sizeof(double));
  if (!camera->params.empty()) {
    std::memcpy(camera->params.data(), sqlite3_column_blob(read_camera_, 3),
                camera->params.size() * sizeof(double));
  }
  return true;
}

bool DatabaseReader::ReadCamera(const colmap::camera_t camera_id,
                                colmap::Camera* camera,
                                std::string* error) const {
  DatabaseCamera database_camera;
  if (!ReadCamera(camera_id, &database_camera, error)) return false;
  if (!ToColmapCamera(database_camera, camera, error)) {
    *error = "database " + path_ + ": " + *error;
    return false;
  }
  return true;
}

bool ToColmapCamera(const DatabaseCamera& database_camera,
                    colmap::Camera* camera, std::string* error) {
  if (!database_camera.known_to_colmap38) {
    *error = "camera " + std::to_string(database_camera.camera_id) +
             " has the model " +
             DescribeColmapCameraModel(database_camera.model_id) +
             ", which COLMAP 3.8 (this build) does not know";
    return false;
  }
  camera->SetCameraId(database_camera.camera_id);
  camera->SetModelId(database_camera.model_id);
  camera->SetWidth(database_camera.width);
  camera->SetHeight(database_camera.height);
  camera->SetParams(database_camera.params);
  camera->SetPriorFocalLength(database_camera.prior_focal_length);
  return true;
}

std::string DatabaseReader::ImageLabel(const colmap::image_t image_id) const {
  const DatabaseImage* image = FindImageWithId(image_id);
  return "image " + (image != nullptr ? image->name + " (id " : "(id ") +
         std::to_string(image_id) + ")";
}

int DatabaseReader::CountRows(sqlite3_stmt* statement,
                              const colmap::image_t image_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  StatementScope scope(statement);
  sqlite3_bind_int64(statement, 1, image_id);
  if (sqlite3_step(statement) != SQLITE_ROW) return -1;
  return sqlite3_column_int(statement, 0);
}

int DatabaseReader::NumKeypoints(const colmap::image_t image_id) const {
  return CountRows(count_keypoints_, image_id);
}

int DatabaseReader::NumDescriptors(const colmap::image_t image_id) const {
  return CountRows(count_descriptors_, image_id);
}

bool DatabaseReader::ReadKeypoints(const colmap::image_t image_id,
                                   colmap::FeatureKeypoints* keypoints,
                                   std::string* error) const {
  std::lock_guard<std::mutex> lock(mutex_);
  StatementScope scope(read_keypoints_);
  const std::string what =
      "database " + path_ + ": keypoints of " + ImageLabel(image_id);
  BlobMatrix blob;
  if (!StepFeatureRow(read_keypoints_, image_id, what, &blob, error)) {
    return false;
  }
  const int64_t rows = blob.rows;
  const int64_t cols = blob.cols;
  // rows > num_bytes first: the product could overflow.
  if (rows < 0 || (rows > 0 && cols != 2 && cols != 4 && cols != 6) ||
      rows > blob.num_bytes ||
      blob.num_bytes != rows * cols * static_cast<int64_t>(sizeof(float))) {
    *error = what + " are malformed " + blob.ShapeText();
    return false;
  }
  const float* data = static_cast<const float*>(blob.data);
  keypoints->resize(rows);
  for (int64_t i = 0; i < rows; ++i) {
    const float* row = data + i * cols;
    // COLMAP's FeatureKeypoint aborts on a negative scale (CHECK).
    if (!std::all_of(row, row + cols,
                     [](float v) { return std::isfinite(v); }) ||
        (cols == 4 && row[2] < 0)) {
      *error = what + " are malformed: keypoint " + std::to_string(i) +
               " has a non-finite value or a negative scale";
      return false;
    }
    if (cols == 2) {
      (*keypoints)[i] = colmap::FeatureKeypoint(row[0], row[1]);
    } else if (cols == 4) {
      (*keypoints)[i] = colmap::FeatureKeypoint(row[0], row[1], row[2], row[3]);
    } else {
      (*keypoints)[i] = colmap::FeatureKeypoint(row[0], row[1], row[2], row[3],
                                                row[4], row[5]);
    }
  }
  return true;
}

bool DatabaseReader::ReadDescriptors(const colmap::image_t image_id,
                                     colmap::FeatureDescriptors* descriptors,
                                     std::string* error) const {
  std::lock_guard<std::mutex> lock(mutex_);
  StatementScope scope(read_descriptors_);
  const std::string what =
      "database " + path_ + ": descriptors of " + ImageLabel(image_id);
  BlobMatrix blob;
  if (!StepFeatureRow(read_descriptors_, image_id, what, &blob, error)) {
    return false;
  }
  // Open checks the whole table; this keeps any other type (whose floats
  // would pass for bytes) out of the matcher.
  if (descriptors_have_type_ &&
      sqlite3_column_int(read_descriptors_, 3) != kSiftDescriptorType) {
    *error = what + " are of type " +
             DescriptorTypeName(sqlite3_column_int(read_descriptors_, 3)) +
             "; rig_calibrator matches SIFT descriptors (type 0) only";
    return false;
  }
  if (blob.rows > 0 && blob.cols != 128) {
    *error = what + " have " + std::to_string(blob.cols) +
             " dimensions; rig_calibrator matches 128-dimensional SIFT";
    return false;
  }
  if (blob.rows < 0 || blob.rows > blob.num_bytes ||
      blob.num_bytes != blob.rows * blob.cols) {
    *error = what + " are malformed " + blob.ShapeText();
    return false;
  }
  descriptors->resize(blob.rows, 128);
  if (blob.rows > 0) {
    std::memcpy(descriptors->data(), blob.data, blob.num_bytes);
  }
  return true;
}

bool DatabaseReader::ReadInlierMatches(const colmap::image_t image_id1,
                                       const colmap::image_t image_id2,
                                       colmap::FeatureMatches* matches,
                                       std::string* error) const {
  matches->clear();
  std::lock_guard<std::mutex> lock(mutex_);
  StatementScope scope(read_inlier_matches_);
  sqlite3_bind_int64(
      read_inlier_matches_, 1,
      static_cast<sqlite3_int64>(ImagePairToPairId(image_id1, image_id2)));
  if (sqlite3_step(read_inlier_matches_) != SQLITE_ROW) return true;
  const BlobMatrix blob = BlobMatrix::OfRow(read_inlier_matches_);
  const int64_t rows = blob.rows;
  if (rows <= 0) return true;
  if (blob.cols != 2 || rows > blob.num_bytes ||
      blob.num_bytes != rows * 2 * static_cast<int64_t>(sizeof(uint32_t))) {
    *error = "database " + path_ + ": inlier matches of " +
             ImageLabel(image_id1) + " and " + ImageLabel(image_id2) +
             " are malformed";
    return false;
  }
  const uint32_t* data = static_cast<const uint32_t*>(blob.data);
  // COLMAP stores the columns in the order (smaller id, larger id).
  const bool swapped = image_id1 > image_id2;
  matches->resize(rows);
  for (int64_t i = 0; i < rows; ++i) {
    (*matches)[i].point2D_idx1 = data[2 * i + (swapped ? 1 : 0)];
    (*matches)[i].point2D_idx2 = data[2 * i + (swapped ? 0 : 1)];
  }
  return true;
}

int64_t DatabaseReader::NumVerifiedImagePairs() const {
  std::lock_guard<std::mutex> lock(mutex_);
  sqlite3_stmt* statement = nullptr;
  int64_t count = 0;
  if (sqlite3_prepare_v2(database_,
                         "SELECT COUNT(*) FROM two_view_geometries WHERE rows "
                         "> 0;",
                         -1, &statement, nullptr) == SQLITE_OK &&
      sqlite3_step(statement) == SQLITE_ROW) {
    count = sqlite3_column_int64(statement, 0);
  }
  sqlite3_finalize(statement);
  return count;
}

uint64_t DatabaseReader::ImagePairToPairId(const colmap::image_t image_id1,
                                           const colmap::image_t image_id2) {
  const uint64_t min_id = std::min(image_id1, image_id2);
  const uint64_t max_id = std::max(image_id1, image_id2);
  return kMaxNumImages * min_id + max_id;
}

}  // namespace rig_calibrator
