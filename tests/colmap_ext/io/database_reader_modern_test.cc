// The database reader on databases of COLMAP 3.12, 3.13, 4.0 (fixtures
// written with SQLite following those schemas) and on the real COLMAP 4.1.1
// database of tests/data/colmap_4_1_1.
#include <gtest/gtest.h>

#include <filesystem>

#include "colmap_ext/io/database_reader.h"
#include "tests/colmap_ext/modern_database.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace database_reader_modern_test {

namespace fs = std::filesystem;
using testing::ColmapSchema;
using testing::ModernDatabase;

constexpr int kPinhole = 1;
constexpr int kOpencv = 4;
constexpr int kFisheye = 15;  // COLMAP >= 4.0

std::vector<float> Keypoints(const int rows, const int cols, const int seed) {
  std::vector<float> data;
  for (int i = 0; i < rows * cols; ++i) data.push_back(0.25f * i + seed);
  return data;
}

std::vector<uint8_t> Descriptors(const int rows, const int seed) {
  std::vector<uint8_t> data;
  for (int i = 0; i < rows * 128; ++i) {
    data.push_back(static_cast<uint8_t>((i * 7 + seed) % 251));
  }
  return data;
}

// Two map images of a PINHOLE camera, rig images of an OPENCV camera (cam0)
// and a FISHEYE camera (cam1, a model COLMAP 3.8 does not know), keypoints
// of 2, 4 and 6 columns, SIFT descriptors, verified matches (config 9,
// CALIBRATED_RIG, between two rig images).
class ModernDatabaseTest : public ::testing::TestWithParam<ColmapSchema> {
 protected:
  void SetUp() override {
    path_ = temp_dir_.File("database.db");
    ModernDatabase database(path_, GetParam());
    map_camera_ =
        database.AddCamera(kPinhole, 640, 480, {400, 400, 320, 240}, true);
    cam0_ = database.AddCamera(kOpencv, 768, 576,
                               {420, 421, 384, 288, -0.1, 0.01, 0, 0}, false);
    cam1_ = database.AddCamera(kFisheye, 640, 480, {300, 301, 320, 240}, true);
    const char* names[] = {"map/a.png", "map/b.png", "cam0/0001.png",
                           "cam1/0001.png", "cam0/0002.png"};
    const uint32_t cameras[] = {map_camera_, map_camera_, cam0_, cam1_, cam0_};
    const int cols[] = {2, 4, 6, 6, 2};
    for (int i = 0; i < 5; ++i) {
      const uint32_t image_id = database.AddImage(names[i], cameras[i]);
      database.AddKeypoints(image_id, cols[i], Keypoints(3 + i, cols[i], i));
      database.AddSiftDescriptors(image_id, Descriptors(3 + i, i));
    }
    database.AddTwoViewGeometry(4, 3, {{0, 1}, {2, 0}}, 9);
    database.Close();
  }

  testing::ScopedTempDir temp_dir_;
  std::string path_;
  uint32_t map_camera_ = 0;
  uint32_t cam0_ = 0;
  uint32_t cam1_ = 0;
};

TEST_P(ModernDatabaseTest, ReadsEveryTableTheCalibrationUses) {
  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(path_, &error)) << error;
  EXPECT_EQ(reader.user_version(), ColmapSchemaUserVersion(GetParam()));
  const std::string expected_version =
      GetParam() == ColmapSchema::k4_0   ? "COLMAP 4.0.4"
      : GetParam() == ColmapSchema::k4_1 ? "COLMAP 4.1.1"
                                         : "COLMAP 3.12 or 3.13";
  EXPECT_EQ(reader.SchemaDescription().rfind(expected_version, 0), 0u)
      << reader.SchemaDescription();

  ASSERT_EQ(reader.Images().size(), 5u);
  EXPECT_EQ(reader.FindImageWithName("cam1/0001.png")->camera_id, cam1_);

  colmap::Camera camera;
  ASSERT_TRUE(reader.ReadCamera(cam0_, &camera, &error)) << error;
  EXPECT_EQ(camera.ModelName(), "OPENCV");
  EXPECT_EQ(camera.Width(), 768u);
  EXPECT_EQ(camera.Params(),
            std::vector<double>({420, 421, 384, 288, -0.1, 0.01, 0, 0}));
  EXPECT_FALSE(camera.HasPriorFocalLength());

  // A camera model of COLMAP 4.0: readable (size, parameters), but not as a
  // COLMAP 3.8 camera.
  DatabaseCamera fisheye;
  ASSERT_TRUE(reader.ReadCamera(cam1_, &fisheye, &error)) << error;
  EXPECT_EQ(fisheye.model_name, "FISHEYE");
  EXPECT_FALSE(fisheye.known_to_colmap38);
  EXPECT_EQ(fisheye.width, 640u);
  EXPECT_EQ(fisheye.params, std::vector<double>({300, 301, 320, 240}));
  EXPECT_FALSE(reader.ReadCamera(cam1_, &camera, &error));
  EXPECT_NE(error.find("camera 3 has the model FISHEYE (model id 15, COLMAP "
                       ">= 4.0), which COLMAP 3.8 (this build) does not know"),
            std::string::npos)
      << error;

  const int cols[] = {2, 4, 6, 6, 2};
  for (colmap::image_t image_id = 1; image_id <= 5; ++image_id) {
    const int i = static_cast<int>(image_id) - 1;
    colmap::FeatureKeypoints keypoints;
    colmap::FeatureDescriptors descriptors;
    ASSERT_TRUE(reader.ReadKeypoints(image_id, &keypoints, &error)) << error;
    ASSERT_TRUE(reader.ReadDescriptors(image_id, &descriptors, &error))
        << error;
    const std::vector<float> expected = Keypoints(3 + i, cols[i], i);
    ASSERT_EQ(keypoints.size(), static_cast<size_t>(3 + i));
    EXPECT_EQ(keypoints.back().x, expected[(2 + i) * cols[i]]);
    EXPECT_EQ(keypoints.back().y, expected[(2 + i) * cols[i] + 1]);
    if (cols[i] == 6) {
      EXPECT_EQ(keypoints.back().a22, expected[(2 + i) * cols[i] + 5]);
    }
    const std::vector<uint8_t> expected_descriptors = Descriptors(3 + i, i);
    ASSERT_EQ(descriptors.rows(), 3 + i);
    EXPECT_EQ(descriptors(2, 5), expected_descriptors[2 * 128 + 5]);
  }

  colmap::FeatureMatches matches;
  ASSERT_TRUE(reader.ReadInlierMatches(4, 3, &matches, &error)) << error;
  ASSERT_EQ(matches.size(), 2u);
  EXPECT_EQ(matches[1].point2D_idx1, 2u);
  EXPECT_EQ(matches[1].point2D_idx2, 0u);
  EXPECT_EQ(reader.NumVerifiedImagePairs(), 1);

  // feature_extractor's trivial rigs and frames.
  ASSERT_EQ(reader.Rigs().size(), 3u);
  EXPECT_EQ(reader.Rigs()[2].ref_camera_id, cam1_);
  EXPECT_TRUE(reader.Rigs()[2].cameras.empty());
  ASSERT_EQ(reader.Frames().size(), 5u);
  EXPECT_EQ(reader.Frames()[3].image_ids, std::vector<colmap::image_t>({4}));
}

TEST_P(ModernDatabaseTest, ReadsTheFramesAndPosesOfRigConfigurator) {
  const Rigid3d cam1_from_rig(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d(0, 1, 0))),
      Eigen::Vector3d(0.1, 0, -0.02));
  {
    // ModernDatabase's constructor creates the file: add to it with SQL.
    ModernDatabase database(temp_dir_.File("grouped.db"), GetParam());
    const uint32_t a = database.AddCamera(kOpencv, 100, 100,
                                          {1, 1, 50, 50, 0, 0, 0, 0}, false);
    const uint32_t b = database.AddCamera(kOpencv, 100, 100,
                                          {1, 1, 50, 50, 0, 0, 0, 0}, false);
    const uint32_t c = database.AddCamera(kOpencv, 100, 100,
                                          {1, 1, 50, 50, 0, 0, 0, 0}, false);
    for (const char* name : {"cam0/1.png", "cam1/1.png", "cam2/1.png",
                             "cam0/2.png", "cam1/2.png"}) {
      database.AddImage(name, name[3] == '0' ? a : name[3] == '1' ? b : c);
    }
    database.GroupFrames({a, b, c}, {std::nullopt, cam1_from_rig, std::nullopt},
                         {{1, 2, 3}, {4, 5}});
  }
  DatabaseReader reader;
  std::string error;
  ASSERT_TRUE(reader.Open(temp_dir_.File("grouped.db"), &error)) << error;
  ASSERT_EQ(reader.Rigs().size(), 1u);
  const DatabaseRig& rig = reader.Rigs()[0];
  EXPECT_EQ(rig.ref_camera_id, 1u);
  ASSERT_EQ(rig.cameras.size(), 2u);
  EXPECT_EQ(rig.cameras[0].camera_id, 2u);
  ASSERT_TRUE(rig.cameras[0].sensor_from_rig.has_value());
  EXPECT_LT((rig.cameras[0].sensor_from_rig->RotationMatrix() -
             cam1_from_rig.RotationMatrix())
                .norm(),
            1e-12);
  EXPECT_EQ(rig.cameras[0].sensor_from_rig->translation,
            cam1_from_rig.translation);
  EXPECT_FALSE(rig.cameras[1].sensor_from_rig.has_value());
  ASSERT_EQ(reader.Frames().size(), 2u);
  EXPECT_EQ(reader.Frames()[0].image_ids,
            std::vector<colmap::image_t>({1, 2, 3}));
  EXPECT_EQ(reader.Frames()[1].image_ids, std::vector<colmap::image_t>({4, 5}));
  EXPECT_EQ(reader.Frames()[1].rig_id, rig.rig_id);
}

TEST_P(ModernDatabaseTest, LeavesTheWalDatabaseUntouched) {
  const std::string bytes_before = testing::ReadBytes(path_);
  const std::set<std::string> files_before =
      testing::ListFolder(temp_dir_.path());
  // The file says WAL (bytes 18 and 19 of the header are 2), which makes a
  // plain read-only connection create -wal and -shm files.
  ASSERT_EQ(bytes_before[18], 2);
  {
    DatabaseReader reader;
    std::string error;
    ASSERT_TRUE(reader.Open(path_, &error)) << error;
    colmap::FeatureDescriptors descriptors;
    ASSERT_TRUE(reader.ReadDescriptors(3, &descriptors, &error)) << error;
  }
  EXPECT_EQ(testing::ReadBytes(path_), bytes_before);
  EXPECT_EQ(testing::ListFolder(temp_dir_.path()), files_before);
}

INSTANTIATE_TEST_SUITE_P(
    Schemas, ModernDatabaseTest,
    ::testing::Values(ColmapSchema::k3_12, ColmapSchema::k3_13,
                      ColmapSchema::k4_0, ColmapSchema::k4_1),
    [](const auto& info) {
      std::string name = testing::ColmapSchemaName(info.param);
      name[1] = '_';
      return "Colmap" + name;
    });

TEST(ModernDatabaseErrorsTest, RejectsNonSiftDescriptorsNamingTheType) {
  testing::ScopedTempDir temp_dir;
  const std::string path = temp_dir.File("aliked.db");
  {
    ModernDatabase database(path, ColmapSchema::k4_1);
    const uint32_t camera =
        database.AddCamera(kPinhole, 640, 480, {400, 400, 320, 240}, false);
    for (const char* name : {"map/a.png", "map/b.png"}) {
      const uint32_t image_id = database.AddImage(name, camera);
      database.AddKeypoints(image_id, 2, Keypoints(4, 2, 0));
      database.AddFloatDescriptors(image_id, 1, 128,
                                   std::vector<float>(4 * 128, 0.1f));
    }
  }
  DatabaseReader reader;
  std::string error;
  EXPECT_FALSE(reader.Open(path, &error));
  EXPECT_NE(error.find("database " + path +
                       ": the descriptors are not all SIFT: ALIKED_N16ROT (1) "
                       "for 2 image(s), e.g. image id 1"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("SIFT"), std::string::npos) << error;
  EXPECT_FALSE(reader.IsOpen());
}

// The real database written by COLMAP 4.1.1 (tests/data/colmap_4_1_1).
TEST(Colmap411DatabaseTest, ReadsTheRealFileWithoutTouchingIt) {
  const std::string folder = testing::SourceDir() + "/tests/data/colmap_4_1_1";
  const std::string path = folder + "/calib.db";
  const std::string bytes_before = testing::ReadBytes(path);
  ASSERT_FALSE(bytes_before.empty()) << path;
  const std::set<std::string> files_before = testing::ListFolder(folder);
  {
    DatabaseReader reader;
    std::string error;
    ASSERT_TRUE(reader.Open(path, &error)) << error;
    EXPECT_EQ(reader.user_version(), 4010100);
    EXPECT_EQ(reader.SchemaDescription(),
              "COLMAP 4.1.1 schema (user_version 4010100)");
    EXPECT_EQ(reader.Images().size(), 50u);
    // feature_extractor's 6 trivial rigs and 50 trivial frames.
    EXPECT_EQ(reader.Rigs().size(), 6u);
    ASSERT_EQ(reader.Frames().size(), 50u);
    for (const DatabaseFrame& frame : reader.Frames()) {
      EXPECT_EQ(frame.image_ids.size(), 1u);
    }
    const DatabaseImage* image = reader.FindImageWithName("cam3/000002.jpg");
    ASSERT_NE(image, nullptr);
    colmap::Camera camera;
    ASSERT_TRUE(reader.ReadCamera(image->camera_id, &camera, &error)) << error;
    EXPECT_EQ(camera.ModelName(), "OPENCV");
    EXPECT_EQ(camera.Params(),
              std::vector<double>({768, 768, 320, 240, 0, 0, 0, 0}));
    colmap::FeatureKeypoints keypoints;
    colmap::FeatureDescriptors descriptors;
    ASSERT_TRUE(reader.ReadKeypoints(image->image_id, &keypoints, &error))
        << error;
    ASSERT_TRUE(reader.ReadDescriptors(image->image_id, &descriptors, &error))
        << error;
    EXPECT_GT(keypoints.size(), 500u);
    EXPECT_EQ(descriptors.rows(), static_cast<int>(keypoints.size()));
    EXPECT_EQ(reader.NumVerifiedImagePairs(), 89);
  }
  EXPECT_EQ(testing::ReadBytes(path), bytes_before);
  EXPECT_EQ(testing::ListFolder(folder), files_before);
}

}  // namespace database_reader_modern_test
}  // namespace rig_calibrator
