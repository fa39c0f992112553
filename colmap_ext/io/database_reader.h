// Read-only access to a COLMAP 3.8 database (the map images and the rig
// images, their cameras, keypoints, descriptors and verified matches).
//
// The input database is never modified. colmap::Database cannot be used for
// this: its constructor switches the file to WAL journaling, creates missing
// tables and rewrites `PRAGMA user_version`, i.e. it writes to the file, and it
// aborts the process (exit/CHECK) on schema errors. This reader opens the file
// with SQLITE_OPEN_READONLY, checks the schema first and turns every problem
// into an error message.
#pragma once

#include <colmap/base/camera.h>
#include <colmap/feature/types.h>
#include <colmap/util/types.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace rig_calibrator {

// One row of the `images` table.
struct DatabaseImage {
  colmap::image_t image_id = colmap::kInvalidImageId;
  std::string name;  // relative to the image path, with '/'
  colmap::camera_t camera_id = colmap::kInvalidCameraId;
};

// All methods are thread-safe: the reads share one SQLite connection and are
// serialized by an internal mutex.
class DatabaseReader {
 public:
  DatabaseReader();
  ~DatabaseReader();
  DatabaseReader(const DatabaseReader&) = delete;
  DatabaseReader& operator=(const DatabaseReader&) = delete;

  // Opens `path` read-only and checks that it is a COLMAP 3.8 database:
  // an SQLite file with the tables cameras, images, keypoints, descriptors,
  // matches and two_view_geometries. Databases of newer COLMAP versions
  // (tables rigs, frames or pose_priors; images without prior_* columns) are
  // rejected with a message that says so. Reads the image list. On failure
  // returns false, sets *error and leaves the reader closed.
  bool Open(const std::string& path, std::string* error);
  void Close();
  bool IsOpen() const { return database_ != nullptr; }

  const std::string& path() const { return path_; }
  // `PRAGMA user_version`: 3800 for COLMAP 3.8, 0 for very old databases.
  int user_version() const { return user_version_; }

  const std::vector<DatabaseImage>& Images() const { return images_; }
  // nullptr if no image has this name.
  const DatabaseImage* FindImageWithName(const std::string& name) const;
  const DatabaseImage* FindImageWithId(colmap::image_t image_id) const;

  bool ReadCamera(colmap::camera_t camera_id, colmap::Camera* camera,
                  std::string* error) const;

  // Number of keypoint/descriptor rows stored for the image; -1 if the image
  // has no row in the table (its features were never extracted).
  int NumKeypoints(colmap::image_t image_id) const;
  int NumDescriptors(colmap::image_t image_id) const;

  // Fail (false, *error) if the image has no row in the table or the blob is
  // malformed; descriptors must be 128-dimensional uint8 (SIFT).
  bool ReadKeypoints(colmap::image_t image_id,
                     colmap::FeatureKeypoints* keypoints,
                     std::string* error) const;
  bool ReadDescriptors(colmap::image_t image_id,
                       colmap::FeatureDescriptors* descriptors,
                       std::string* error) const;

  // Inlier matches of the geometrically verified pair (image_id1, image_id2)
  // from `two_view_geometries`, ordered so that point2D_idx1 indexes
  // image_id1's keypoints whatever order COLMAP stored them in. Empty (and
  // true) if the pair was never matched or was not verified.
  bool ReadInlierMatches(colmap::image_t image_id1, colmap::image_t image_id2,
                         colmap::FeatureMatches* matches,
                         std::string* error) const;
  // Number of rows in `two_view_geometries` with at least one inlier.
  int64_t NumVerifiedImagePairs() const;

  // COLMAP's pair id, 2147483647 * min(id1, id2) + max(id1, id2).
  static uint64_t ImagePairToPairId(colmap::image_t image_id1,
                                    colmap::image_t image_id2);

 private:
  bool CheckSchema(std::string* error);
  bool ReadImages(std::string* error);
  // Prepares the cached statements of the readers.
  bool PrepareStatements(std::string* error);
  int CountRows(sqlite3_stmt* statement, colmap::image_t image_id) const;
  // "image <name> (id <id>)" for messages.
  std::string ImageLabel(colmap::image_t image_id) const;

  std::string path_;
  sqlite3* database_ = nullptr;
  int user_version_ = 0;
  std::vector<DatabaseImage> images_;
  std::unordered_map<std::string, size_t> image_index_by_name_;
  std::unordered_map<colmap::image_t, size_t> image_index_by_id_;

  sqlite3_stmt* read_camera_ = nullptr;
  sqlite3_stmt* count_keypoints_ = nullptr;
  sqlite3_stmt* count_descriptors_ = nullptr;
  sqlite3_stmt* read_keypoints_ = nullptr;
  sqlite3_stmt* read_descriptors_ = nullptr;
  sqlite3_stmt* read_inlier_matches_ = nullptr;
  mutable std::mutex mutex_;
};

}  // namespace rig_calibrator
