// A fixture builder for databases of COLMAP 3.12, 3.13, 4.0 and 4.1, written
// with SQLite following the schemas of those versions (the tables, columns
// and `PRAGMA user_version` listed in README, "COLMAP versions"), since the
// COLMAP 3.8 this project builds on cannot write them. Like COLMAP's
// feature_extractor it makes one trivial rig per camera and one trivial frame
// per image; GroupFrames does what COLMAP's rig_configurator does.
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"

namespace rig_calibrator {
namespace testing {

enum class ColmapSchema { k3_12, k3_13, k4_0, k4_1 };

// "3.12", "3.13", "4.0", "4.1".
std::string ColmapSchemaName(ColmapSchema schema);
// 3900 for 3.12 and 3.13 (hard-coded there), 4000400 (4.0.4), 4010100
// (4.1.1).
int ColmapSchemaUserVersion(ColmapSchema schema);

class ModernDatabase {
 public:
  // Creates the database at `path` (which must not exist), in WAL journaling
  // as COLMAP leaves it; or, with `create` false, opens the existing database
  // of that schema at `path` (a copy the test owns). Fails the test on an
  // SQLite error.
  ModernDatabase(const std::string& path, ColmapSchema schema,
                 bool create = true);
  ~ModernDatabase();
  ModernDatabase(const ModernDatabase&) = delete;
  ModernDatabase& operator=(const ModernDatabase&) = delete;

  // A camera (any model id, also > 10) and its trivial rig; returns its id.
  uint32_t AddCamera(int model_id, int width, int height,
                     const std::vector<double>& params,
                     bool prior_focal_length);
  // An image and its trivial frame (in the camera's trivial rig).
  uint32_t AddImage(const std::string& name, uint32_t camera_id);
  // Keypoints: rows x cols float32 (cols 2, 4 or 6), row-major.
  void AddKeypoints(uint32_t image_id, int cols,
                    const std::vector<float>& data);
  // SIFT descriptors (uint8, 128 per row); 4.x stores `type` 0.
  void AddSiftDescriptors(uint32_t image_id, const std::vector<uint8_t>& data);
  // Descriptors of another type (4.x only): rows x cols float32.
  void AddFloatDescriptors(uint32_t image_id, int type, int cols,
                           const std::vector<float>& data);
  // Raw matches and a verified geometry (config 2 = CALIBRATED, 9 =
  // CALIBRATED_RIG since 3.12) of the pair, inliers as (idx1, idx2) of
  // (image_id1, image_id2); stored as COLMAP does, smaller id first.
  void AddTwoViewGeometry(
      uint32_t image_id1, uint32_t image_id2,
      const std::vector<std::pair<uint32_t, uint32_t>>& inliers, int config);
  // COLMAP's rig_configurator: one rig of `camera_ids` (the first is the
  // reference; sensor_from_rig per other camera, unknown when empty)
  // replacing their trivial rigs, and one frame per group of image ids
  // replacing the images' trivial frames.
  void GroupFrames(const std::vector<uint32_t>& camera_ids,
                   const std::vector<std::optional<Rigid3d>>& sensor_from_rig,
                   const std::vector<std::vector<uint32_t>>& frames);

  // Runs SQL on the fixture (e.g. to break it on purpose).
  void Execute(const std::string& sql);
  // Checkpoints the WAL into the file and closes it (no -wal/-shm left).
  void Close();

 private:
  void Bind(sqlite3_stmt* statement, int index, const void* data,
            size_t num_bytes);

  ColmapSchema schema_;
  sqlite3* database_ = nullptr;
};

}  // namespace testing
}  // namespace rig_calibrator
