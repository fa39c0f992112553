#include "colmap_ext/io/database_reader.h"

#include <colmap/base/database.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include "tests/colmap_ext/colmap_testing.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace database_reader_test {

namespace fs = std::filesystem;

using testing::ExecuteSql;

colmap::FeatureDescriptors RandomDescriptors(const int rows, const int seed) {
  colmap::FeatureDescriptors descriptors(rows, 128);
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < 128; ++j) {
      descriptors(i, j) = static_cast<uint8_t>((i * 131 + j * 17 + seed) % 97);
    }
  }
  return descriptors;
}

// A small COLMAP 3.8 database written by colmap::Database: two cameras,
// images "map/a.png" (1), "map/b.png" (2) and "cam0/0001.png" (3), features,
// and verified inlier matches between images 3 and 1.
struct TestDatabase {
  colmap::Camera camera1;
  colmap::Camera camera2;
  colmap::FeatureKeypoints keypoints[3];
  colmap::FeatureDescriptors descriptors[3];
  colmap::FeatureMatches matches_3_to_1;

  void Write(const std::string& path) {
    colmap::Database database(path);
    camera1.InitializeWithName("SIMPLE_RADIAL", 500, 640, 480);
    camera2.InitializeWithName("OPENCV_FISHEYE", 300, 800, 600);
    camera2.SetPriorFocalLength(true);
    camera1.SetCameraId(database.WriteCamera(camera1));
    camera2.SetCameraId(database.WriteCamera(camera2));
    const char* names[3] = {"map/a.png", "map/b.png", "cam0/0001.png"};
    for (int i = 0; i < 3; ++i) {
      colmap::Image image;
      image.SetName(names[i]);
      image.SetCameraId(i < 2 ? camera1.CameraId() : camera2.CameraId());
      const colmap::image_t image_id = database.WriteImage(image);
      for (int k = 0; k < 5 + i; ++k) {
        keypoints[i].emplace_back(10.5f * k + i, 3.25f * k, 1.5f + k, 0.1f * k);
      }
      descriptors[i] = RandomDescriptors(5 + i, i);
      database.WriteKeypoints(image_id, keypoints[i]);
      database.WriteDescriptors(image_id, descriptors[i]);
    }
    matches_3_to_1 = {{0, 4}, {2, 1}, {6, 0}};
    colmap::TwoViewGeometry geometry;
    geometry.config = colmap::TwoViewGeometry::UNCALIBRATED;
    geometry.inlier_matches = matches_3_to_1;
    database.WriteTwoViewGeometry(3, 1, geometry);
    colmap::TwoViewGeometry failed;
    failed.config = colmap::TwoViewGeometry::DEGENERATE;
    database.WriteTwoViewGeometry(3, 2, failed);
  }
};

class DatabaseReaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = temp_dir_.File("database.db");
    database_.Write(path_);
  }

  testing::ScopedTempDir temp_dir_;
  std::string path_;
  TestDatabase database_;
};

TEST_F(DatabaseReaderTest, ReadsImagesCamerasAndFeatures) {
  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(path_, &error)) << error;
  EXPECT_EQ(reader.user_version(), 3800);
  ASSERT_EQ(reader.Images().size(), 3u);
  const DatabaseImage* rig_image = reader.FindImageWithName("cam0/0001.png");
  ASSERT_NE(rig_image, nullptr);
  EXPECT_EQ(rig_image->image_id, 3u);
  EXPECT_EQ(rig_image->camera_id, database_.camera2.CameraId());
  EXPECT_EQ(reader.FindImageWithName("cam0/0002.png"), nullptr);
  EXPECT_EQ(reader.FindImageWithId(1)->name, "map/a.png");

  colmap::Camera camera;
  ASSERT_TRUE(reader.ReadCamera(database_.camera2.CameraId(), &camera, &error))
      << error;
  EXPECT_EQ(camera.ModelName(), "OPENCV_FISHEYE");
  EXPECT_EQ(camera.Width(), 800u);
  EXPECT_EQ(camera.Height(), 600u);
  EXPECT_EQ(camera.Params(), database_.camera2.Params());
  EXPECT_TRUE(camera.HasPriorFocalLength());
  EXPECT_FALSE(reader.ReadCamera(99, &camera, &error));
  EXPECT_NE(error.find("no camera with id 99"), std::string::npos) << error;

  for (colmap::image_t image_id = 1; image_id <= 3; ++image_id) {
    const int i = static_cast<int>(image_id) - 1;
    EXPECT_EQ(reader.NumKeypoints(image_id), 5 + i);
    EXPECT_EQ(reader.NumDescriptors(image_id), 5 + i);
    colmap::FeatureKeypoints keypoints;
    colmap::FeatureDescriptors descriptors;
    ASSERT_TRUE(reader.ReadKeypoints(image_id, &keypoints, &error)) << error;
    ASSERT_TRUE(reader.ReadDescriptors(image_id, &descriptors, &error))
        << error;
    ASSERT_EQ(keypoints.size(), database_.keypoints[i].size());
    for (size_t k = 0; k < keypoints.size(); ++k) {
      EXPECT_EQ(keypoints[k].x, database_.keypoints[i][k].x);
      EXPECT_EQ(keypoints[k].y, database_.keypoints[i][k].y);
      EXPECT_EQ(keypoints[k].a12, database_.keypoints[i][k].a12);
    }
    EXPECT_EQ(descriptors, database_.descriptors[i]);
  }
  EXPECT_EQ(reader.NumKeypoints(42), -1);
  colmap::FeatureKeypoints keypoints;
  EXPECT_FALSE(reader.ReadKeypoints(42, &keypoints, &error));
  EXPECT_NE(error.find("missing"), std::string::npos) << error;
}

TEST_F(DatabaseReaderTest, ReadsInlierMatchesInTheRequestedOrder) {
  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(path_, &error)) << error;
  EXPECT_EQ(reader.NumVerifiedImagePairs(), 1);
  colmap::FeatureMatches matches;
  ASSERT_TRUE(reader.ReadInlierMatches(3, 1, &matches, &error)) << error;
  ASSERT_EQ(matches.size(), database_.matches_3_to_1.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    EXPECT_EQ(matches[i].point2D_idx1,
              database_.matches_3_to_1[i].point2D_idx1);
    EXPECT_EQ(matches[i].point2D_idx2,
              database_.matches_3_to_1[i].point2D_idx2);
  }
  ASSERT_TRUE(reader.ReadInlierMatches(1, 3, &matches, &error)) << error;
  ASSERT_EQ(matches.size(), database_.matches_3_to_1.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    EXPECT_EQ(matches[i].point2D_idx1,
              database_.matches_3_to_1[i].point2D_idx2);
    EXPECT_EQ(matches[i].point2D_idx2,
              database_.matches_3_to_1[i].point2D_idx1);
  }
  ASSERT_TRUE(reader.ReadInlierMatches(3, 2, &matches, &error)) << error;
  EXPECT_TRUE(matches.empty());
  ASSERT_TRUE(reader.ReadInlierMatches(1, 2, &matches, &error)) << error;
  EXPECT_TRUE(matches.empty());
  EXPECT_EQ(DatabaseReader::ImagePairToPairId(3, 1),
            colmap::Database::ImagePairToPairId(3, 1));
}

TEST_F(DatabaseReaderTest, LeavesTheDatabaseAndItsFolderUntouched) {
  const std::string bytes_before = testing::ReadBytes(path_);
  const auto mtime_before = fs::last_write_time(path_);
  const std::set<std::string> files_before =
      testing::ListFolder(temp_dir_.path());
  {
    DatabaseReader reader;
    std::string error;
    ASSERT_TRUE(reader.Open(path_, &error)) << error;
    colmap::FeatureDescriptors descriptors;
    colmap::FeatureMatches matches;
    ASSERT_TRUE(reader.ReadDescriptors(3, &descriptors, &error));
    ASSERT_TRUE(reader.ReadInlierMatches(3, 1, &matches, &error));
  }
  EXPECT_EQ(testing::ReadBytes(path_), bytes_before);
  EXPECT_EQ(fs::last_write_time(path_), mtime_before);
  EXPECT_EQ(testing::ListFolder(temp_dir_.path()), files_before);
}

TEST_F(DatabaseReaderTest, ReadsDataStillInTheWriteAheadLog) {
  // While a COLMAP process holds the database open, committed rows can live
  // in the "-wal" file only.
  colmap::Database writer(path_);
  colmap::Image image;
  image.SetName("cam1/0001.png");
  image.SetCameraId(database_.camera1.CameraId());
  writer.WriteImage(image);
  ASSERT_GT(fs::file_size(path_ + "-wal"), 0u);

  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(path_, &error)) << error;
  EXPECT_NE(reader.FindImageWithName("cam1/0001.png"), nullptr);
}

TEST_F(DatabaseReaderTest, RejectsMissingAndNonDatabaseFiles) {
  DatabaseReader reader;
  std::string error;
  EXPECT_FALSE(reader.Open(temp_dir_.File("missing.db"), &error));
  EXPECT_NE(error.find("no such file"), std::string::npos) << error;

  EXPECT_FALSE(reader.Open(temp_dir_.path(), &error));
  EXPECT_NE(error.find("not a regular file"), std::string::npos) << error;

  const std::string text_path = temp_dir_.File("notes.txt");
  std::ofstream(text_path) << "# rig_calibrator 2D-3D correspondences\n";
  EXPECT_FALSE(reader.Open(text_path, &error));
  EXPECT_NE(error.find("not an SQLite file"), std::string::npos) << error;
  EXPECT_FALSE(reader.IsOpen());

  const std::string empty_path = temp_dir_.File("empty.db");
  std::ofstream(empty_path).close();
  EXPECT_FALSE(reader.Open(empty_path, &error));
  EXPECT_NE(error.find("not an SQLite file"), std::string::npos) << error;

  const std::string other_path = temp_dir_.File("other.db");
  ExecuteSql(other_path, "CREATE TABLE songs (title TEXT);");
  EXPECT_FALSE(reader.Open(other_path, &error));
  EXPECT_NE(error.find("not a COLMAP database"), std::string::npos) << error;
}

TEST_F(DatabaseReaderTest, RejectsIncompleteColmapDatabases) {
  ExecuteSql(path_, "DROP TABLE two_view_geometries;");
  DatabaseReader reader;
  std::string error;
  EXPECT_FALSE(reader.Open(path_, &error));
  EXPECT_NE(error.find("missing table(s) two_view_geometries"),
            std::string::npos)
      << error;
}

TEST_F(DatabaseReaderTest, DescribesTheColmap38Schema) {
  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(path_, &error)) << error;
  EXPECT_EQ(reader.SchemaDescription(),
            "COLMAP 3.8 or older schema (user_version 3800)");
  EXPECT_TRUE(reader.Rigs().empty());
  EXPECT_TRUE(reader.Frames().empty());
}

TEST_F(DatabaseReaderTest, DescribesTheColmap310Schema) {
  // COLMAP 3.10 and 3.11: pose priors moved out of the images table, no
  // rigs yet.
  const std::string path = temp_dir_.File("colmap310.db");
  ExecuteSql(path,
             "CREATE TABLE cameras (camera_id INTEGER PRIMARY KEY, model "
             "INTEGER, width INTEGER, height INTEGER, params BLOB, "
             "prior_focal_length INTEGER);"
             "CREATE TABLE images (image_id INTEGER PRIMARY KEY, name TEXT, "
             "camera_id INTEGER);"
             "CREATE TABLE pose_priors (image_id INTEGER PRIMARY KEY, position "
             "BLOB, coordinate_system INTEGER);"
             "CREATE TABLE keypoints (image_id INTEGER, rows INTEGER, cols "
             "INTEGER, data BLOB);"
             "CREATE TABLE descriptors (image_id INTEGER, rows INTEGER, cols "
             "INTEGER, data BLOB);"
             "CREATE TABLE matches (pair_id INTEGER, rows INTEGER, cols "
             "INTEGER, data BLOB);"
             "CREATE TABLE two_view_geometries (pair_id INTEGER, rows INTEGER, "
             "cols INTEGER, data BLOB, config INTEGER);"
             "INSERT INTO images VALUES (1, 'cam0/1.png', 1);");
  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(path, &error)) << error;
  EXPECT_EQ(reader.SchemaDescription(),
            "COLMAP 3.10 or 3.11 schema (user_version 0)");
  EXPECT_EQ(reader.Images().size(), 1u);
}

TEST_F(DatabaseReaderTest, RejectsPartialRigTables) {
  ExecuteSql(path_,
             "CREATE TABLE rigs (rig_id INTEGER PRIMARY KEY);"
             "CREATE TABLE frames (frame_id INTEGER PRIMARY KEY);");
  DatabaseReader reader;
  std::string error;
  EXPECT_FALSE(reader.Open(path_, &error));
  EXPECT_NE(error.find("has the table(s) rigs, frames but not rig_sensors, "
                       "frame_data"),
            std::string::npos)
      << error;
}

}  // namespace database_reader_test
}  // namespace rig_calibrator
