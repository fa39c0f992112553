// The database export (database_export.h) on a real COLMAP 3.8 database of
// the model writer's scene: the rig-to-map matches it writes, its refusals,
// and COLMAP 3.8's point_triangulator continuing from the calibrated model
// with the exported database.
#include "colmap_ext/io/database_export.h"

#include <colmap/base/database.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/io/model_writer.h"
#include "tests/colmap_ext/io/model_writer_scene.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace database_export_test {

using testing::MakeScene;
using testing::ReadBytes;
using testing::Scene;
using testing::ScopedTempDir;

// COLMAP 3.8's command-line tool: $COLMAP, else the set-up's cache.
std::string ColmapBinary() {
  if (const char* colmap = std::getenv("COLMAP")) return colmap;
  const char* cache = std::getenv("RIG_CALIBRATOR_CACHE");
  const char* home = std::getenv("HOME");
  const std::string root = cache != nullptr ? cache
                           : home != nullptr
                               ? std::string(home) + "/.cache/rig_calibrator"
                               : "";
  return root + "/colmap-3.8/bin/colmap";
}

// The scene's database: the map images (ids 1, 2, their points2D as
// keypoints, all matched to each other) and the rig images, whose keypoints
// are their correspondences' 2D points in reverse order (so that keypoint and
// correspondence indices differ), one database camera per rig camera.
void WriteSceneDatabase(const Scene& scene, const std::string& path) {
  colmap::Database database(path);
  colmap::Camera map_camera = scene.map.Camera(1);
  database.WriteCamera(map_camera, /*use_camera_id=*/true);
  for (const colmap::image_t image_id : {1, 2}) {
    const colmap::Image& image = scene.map.Image(image_id);
    colmap::Image db_image;
    db_image.SetImageId(image_id);
    db_image.SetName(image.Name());
    db_image.SetCameraId(1);
    database.WriteImage(db_image, /*use_image_id=*/true);
    colmap::FeatureKeypoints keypoints;
    for (const colmap::Point2D& point2D : image.Points2D()) {
      keypoints.emplace_back(point2D.X(), point2D.Y());
    }
    database.WriteKeypoints(image_id, keypoints);
  }
  colmap::FeatureMatches map_matches;
  for (colmap::point2D_t k = 0; k < scene.map.Image(1).NumPoints2D(); ++k) {
    map_matches.emplace_back(k, k);
  }
  database.WriteMatches(1, 2, map_matches);
  colmap::TwoViewGeometry geometry;
  geometry.config = colmap::TwoViewGeometry::CALIBRATED;
  geometry.inlier_matches = map_matches;
  database.WriteTwoViewGeometry(1, 2, geometry);
  std::vector<colmap::camera_t> rig_camera_ids;
  for (const RigCamera& camera : scene.dataset.cameras) {
    rig_camera_ids.push_back(database.WriteCamera(camera.camera));
  }
  for (const RigImage& image : scene.dataset.images) {
    colmap::Image db_image;
    db_image.SetName(image.name);
    db_image.SetCameraId(rig_camera_ids[image.camera_index]);
    const colmap::image_t image_id = database.WriteImage(db_image);
    colmap::FeatureKeypoints keypoints;
    for (auto it = image.correspondences.rbegin();
         it != image.correspondences.rend(); ++it) {
      keypoints.emplace_back(it->point2D.x(), it->point2D.y());
    }
    database.WriteKeypoints(image_id, keypoints);
  }
}

TEST(DatabaseExportTest, WritesTheRigToMapMatchesOfTheInlierCorrespondences) {
  const Scene scene = MakeScene();
  ScopedTempDir folder;
  const std::string input = folder.File("input.db");
  WriteSceneDatabase(scene, input);
  const std::string input_bytes = ReadBytes(input);
  DatabaseExportSummary summary;
  std::string error;
  ASSERT_TRUE(ExportDatabaseWithRigMatches(input, folder.File("export.db"),
                                           scene.map, scene.dataset,
                                           scene.calibration, &summary, &error))
      << error;
  EXPECT_EQ(ReadBytes(input), input_bytes) << "the input was modified";
  EXPECT_FALSE(std::filesystem::exists(folder.File("export.db-wal")));

  // Every used rig image: its 16 inliers with a map point id, each matched
  // to that point's keypoint in both map images.
  EXPECT_EQ(summary.num_rig_images, scene.num_registered);
  EXPECT_EQ(summary.num_image_pairs, 2 * scene.num_registered);
  EXPECT_EQ(summary.num_matches, 2 * scene.num_observations);
  EXPECT_EQ(summary.num_unmatched_rows, 0);
  EXPECT_EQ(summary.num_cameras_updated, 3);

  DatabaseReader reader;
  ASSERT_TRUE(reader.Open(folder.File("export.db"), &error)) << error;
  for (size_t i = 0; i < scene.dataset.images.size(); ++i) {
    const RigImage& image = scene.dataset.images[i];
    const DatabaseImage* rig_image = reader.FindImageWithName(image.name);
    ASSERT_NE(rig_image, nullptr);
    for (const colmap::image_t map_id : {1, 2}) {
      colmap::FeatureMatches matches;
      ASSERT_TRUE(reader.ReadInlierMatches(rig_image->image_id, map_id,
                                           &matches, &error))
          << error;
      if (!scene.calibration.images[i].used) {
        EXPECT_TRUE(matches.empty()) << image.name;
        continue;
      }
      EXPECT_EQ(matches.size(), 16u) << image.name;
      const int num_rows = static_cast<int>(image.correspondences.size());
      for (const colmap::FeatureMatch& match : matches) {
        // Keypoint k is at correspondence num_rows - 1 - k's 2D point (the
        // scene repeats some 2D points); the map's point p + 1 is keypoint p
        // of both map images.
        const Eigen::Vector2d& keypoint =
            image.correspondences[num_rows - 1 - match.point2D_idx1].point2D;
        bool found = false;
        for (size_t k = 0; k < image.correspondences.size(); ++k) {
          found = found || (scene.calibration.images[i].inlier_mask[k] &&
                            image.correspondences[k].point3D_id ==
                                static_cast<int64_t>(match.point2D_idx2) + 1 &&
                            image.correspondences[k].point2D == keypoint);
        }
        EXPECT_TRUE(found) << image.name << " keypoint " << match.point2D_idx1;
      }
    }
  }
  colmap::Camera camera;
  const DatabaseImage* cam1_image =
      reader.FindImageWithName(scene.dataset.images[1].name);
  ASSERT_TRUE(reader.ReadCamera(cam1_image->camera_id, &camera, &error));
  EXPECT_EQ(camera.ModelName(), "OPENCV");
  EXPECT_EQ(camera.Params(), scene.calibration.cameras[1].Params());
}

TEST(DatabaseExportTest, RefusesAnExistingFileAndTheInput) {
  const Scene scene = MakeScene();
  ScopedTempDir folder;
  const std::string input = folder.File("input.db");
  WriteSceneDatabase(scene, input);
  DatabaseExportSummary summary;
  std::string error;
  EXPECT_FALSE(ExportDatabaseWithRigMatches(input, input, scene.map,
                                            scene.dataset, scene.calibration,
                                            &summary, &error));
  EXPECT_NE(error.find("exists"), std::string::npos) << error;
  const std::string other = folder.File("other.db");
  { std::ofstream(other) << "x"; }
  EXPECT_FALSE(ExportDatabaseWithRigMatches(input, other, scene.map,
                                            scene.dataset, scene.calibration,
                                            &summary, &error));
  EXPECT_EQ(ReadBytes(other), "x");
  EXPECT_FALSE(ExportDatabaseWithRigMatches(
      folder.File("missing.db"), folder.File("new.db"), scene.map,
      scene.dataset, scene.calibration, &summary, &error));
  EXPECT_FALSE(std::filesystem::exists(folder.File("new.db")));
}

TEST(DatabaseExportTest, Colmap38PointTriangulatorTriangulatesFromRigMatches) {
  const std::string colmap = ColmapBinary();
  if (!std::filesystem::exists(colmap)) {
    GTEST_SKIP() << "no COLMAP 3.8 binary at " << colmap
                 << " (scripts/setup_deps.sh builds it)";
  }
  const Scene scene = MakeScene();
  ScopedTempDir folder;
  WriteSceneDatabase(scene, folder.File("input.db"));
  DatabaseExportSummary summary;
  std::string error;
  ASSERT_TRUE(ExportDatabaseWithRigMatches(
      folder.File("input.db"), folder.File("export.db"), scene.map,
      scene.dataset, scene.calibration, &summary, &error))
      << error;
  CalibrationSummary calibration_summary;
  ASSERT_TRUE(WriteRigOutput(
      folder.File("calibration"), scene.map, scene.dataset, scene.calibration,
      {}, calibration_summary, RigOutputOptions(), nullptr, &error))
      << error;
  std::filesystem::create_directory(folder.File("triangulated"));
  // The README's recipe: the points are re-triangulated from the database's
  // matches, the poses and intrinsics are the calibration's.
  const std::string command =
      colmap + " point_triangulator --database_path " +
      folder.File("export.db") + " --image_path " + folder.path() +
      " --input_path " + folder.File("calibration") + " --output_path " +
      folder.File("triangulated") + " --clear_points 1 > " +
      folder.File("triangulator.log") + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0)
      << ReadBytes(folder.File("triangulator.log"));
  colmap::Reconstruction triangulated;
  triangulated.ReadBinary(folder.File("triangulated"));
  int num_rig_images_observing = 0;
  size_t num_rig_observations = 0;
  for (const auto& [image_id, image] : triangulated.Images()) {
    if (image.Name().rfind("map/", 0) == 0) continue;
    num_rig_images_observing += image.NumPoints3D() > 0 ? 1 : 0;
    num_rig_observations += image.NumPoints3D();
  }
  std::printf(
      "point_triangulator: %zu points, %zu rig observations in %d of %d "
      "rig images, mean reprojection error %.3g px\n",
      triangulated.NumPoints3D(), num_rig_observations,
      num_rig_images_observing, scene.num_registered,
      triangulated.ComputeMeanReprojectionError());
  EXPECT_EQ(triangulated.NumRegImages(), 2u + scene.num_registered);
  EXPECT_EQ(num_rig_images_observing, scene.num_registered);
  EXPECT_GE(num_rig_observations,
            static_cast<size_t>(scene.num_observations) * 9 / 10);
  EXPECT_LT(triangulated.ComputeMeanReprojectionError(), 1e-3);
}

}  // namespace database_export_test
}  // namespace rig_calibrator
