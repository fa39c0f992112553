// Read-only access to a COLMAP database of COLMAP 3.8, 3.12, 3.13, 4.0 or 4.1
// (the map images and the rig images, their cameras, keypoints, descriptors
// and verified matches; the rigs and frames of COLMAP >= 3.12).
//
// The input database is never modified. colmap::Database cannot be used for
// this: its constructor switches the file to WAL journaling, creates missing
// tables and rewrites `PRAGMA user_version`, i.e. it writes to the file, and it
// aborts the process (exit/CHECK) on schema errors. This reader opens the file
// with SQLITE_OPEN_READONLY and `immutable=1` (no locks, no -wal/-shm files,
// also for the WAL-mode files of COLMAP 4.x), checks the schema first and
// turns every problem into an error message.
//
// The schemas differ (see README, "COLMAP versions"): 3.10 moves the prior_*
// columns of `images` into `pose_priors`; 3.12 adds `rigs`, `rig_sensors`,
// `frames` and `frame_data`; 4.0 adds a `type` column to `descriptors`
// (0 = SIFT).
// Camera model ids above 10 (COLMAP >= 3.11) are read as DatabaseCamera but
// cannot become a colmap::Camera of COLMAP 3.8.
#pragma once

#include <colmap/base/camera.h>
#include <colmap/feature/types.h>
#include <colmap/util/types.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "src/geometry/rigid3d.h"

struct sqlite3;
struct sqlite3_stmt;

namespace rig_calibrator {

// One row of the `images` table.
struct DatabaseImage {
  colmap::image_t image_id = colmap::kInvalidImageId;
  std::string name;  // relative to the image path, with '/'
  colmap::camera_t camera_id = colmap::kInvalidCameraId;
};

// One row of the `cameras` table, whatever its model.
struct DatabaseCamera {
  colmap::camera_t camera_id = colmap::kInvalidCameraId;
  int model_id = -1;
  std::string model_name;  // COLMAP's name of the model, "UNKNOWN" if none
  size_t width = 0;
  size_t height = 0;
  std::vector<double> params;
  bool prior_focal_length = false;
  // The model is one of COLMAP 3.8's (ids 0-10), so ToColmapCamera works.
  bool known_to_colmap38 = false;
};

// The camera as a COLMAP 3.8 camera; fails naming the camera and its model if
// COLMAP 3.8 does not know the model.
bool ToColmapCamera(const DatabaseCamera& database_camera,
                    colmap::Camera* camera, std::string* error);

// A rig of COLMAP >= 3.12 (`rigs` and `rig_sensors`), camera sensors only.
struct DatabaseRig {
  uint32_t rig_id = 0;
  // kInvalidCameraId if the reference sensor is not a camera.
  colmap::camera_t ref_camera_id = colmap::kInvalidCameraId;
  struct Sensor {
    colmap::camera_t camera_id = colmap::kInvalidCameraId;
    std::optional<Rigid3d> sensor_from_rig;  // unknown when NULL
  };
  std::vector<Sensor> cameras;  // without the reference camera
};

// A frame of COLMAP >= 3.12 (`frames` and `frame_data`), its camera data.
struct DatabaseFrame {
  uint32_t frame_id = 0;
  uint32_t rig_id = 0;
  std::vector<colmap::image_t> image_ids;  // sorted
};

// All methods are thread-safe: the reads share one SQLite connection and are
// serialized by an internal mutex.
class DatabaseReader {
 public:
  DatabaseReader();
  ~DatabaseReader();
  DatabaseReader(const DatabaseReader&) = delete;
  DatabaseReader& operator=(const DatabaseReader&) = delete;

  // Opens `path` read-only and checks that it is a COLMAP database: an SQLite
  // file with the tables cameras, images, keypoints, descriptors, matches and
  // two_view_geometries (and, if one of rigs, rig_sensors, frames, frame_data
  // is there, all four), whose descriptors are all SIFT (a `type` column, if
  // any, is 0 everywhere; other types are rejected, naming them). Reads the
  // image list, rigs and frames. On failure returns false, sets *error and
  // leaves the reader closed.
  bool Open(const std::string& path, std::string* error);
  void Close();
  bool IsOpen() const { return database_ != nullptr; }

  const std::string& path() const { return path_; }
  // `PRAGMA user_version`: 3800 for COLMAP 3.8, 3900 for 3.12 and 3.13,
  // major * 1000000 + minor * 10000 + patch * 100 from 4.0 on, 0 for very old
  // databases.
  int user_version() const { return user_version_; }
  // The COLMAP version(s) whose schema this is, e.g. "COLMAP 3.8",
  // "COLMAP 3.12 or 3.13", "COLMAP 4.1.1", with the user_version.
  std::string SchemaDescription() const;

  // The rigs and frames of COLMAP >= 3.12 (empty for older databases).
  const std::vector<DatabaseRig>& Rigs() const { return rigs_; }
  const std::vector<DatabaseFrame>& Frames() const { return frames_; }

  const std::vector<DatabaseImage>& Images() const { return images_; }
  // nullptr if no image has this name.
  const DatabaseImage* FindImageWithName(const std::string& name) const;
  const DatabaseImage* FindImageWithId(colmap::image_t image_id) const;

  // Fails if there is no such camera or its parameters do not fit its model
  // (for models COLMAP 3.8 knows).
  bool ReadCamera(colmap::camera_t camera_id, DatabaseCamera* camera,
                  std::string* error) const;
  // ReadCamera and ToColmapCamera.
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
  bool CheckDescriptorTypes(std::string* error);
  bool ReadImages(std::string* error);
  bool ReadRigsAndFrames(std::string* error);
  // Prepares the cached statements of the readers.
  bool PrepareStatements(std::string* error);
  int CountRows(sqlite3_stmt* statement, colmap::image_t image_id) const;
  // "image <name> (id <id>)" for messages.
  std::string ImageLabel(colmap::image_t image_id) const;

  std::string path_;
  sqlite3* database_ = nullptr;
  int user_version_ = 0;
  bool has_rigs_ = false;               // COLMAP >= 3.12
  bool descriptors_have_type_ = false;  // COLMAP >= 4.0
  bool images_have_priors_ = false;     // COLMAP <= 3.9
  std::vector<DatabaseRig> rigs_;
  std::vector<DatabaseFrame> frames_;
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
