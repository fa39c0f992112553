// `rig_calibrator calibrate` on bad input, with real COLMAP 3.8 files: a
// database written by colmap::Database and a map written by
// colmap::Reconstruction. Every case must fail with a message naming the file
// or option, exit non-zero, leave no output folder (nor a temporary one)
// behind and leave every input file byte for byte unchanged.
#include <colmap/base/database.h>
#include <colmap/base/reconstruction.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "colmap_ext/commands/commands.h"
#include "tests/colmap_ext/colmap_testing.h"
#include "tests/colmap_ext/modern_database.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace calibrate_command_test {

namespace fs = std::filesystem;

constexpr int kNumFeatures = 40;
constexpr int kNumMapPoints = 30;

void WriteBytes(const std::string& path, const std::string& bytes) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

using testing::ExecuteSql;

// Features of one image: keypoints on a grid, descriptors from `random`.
void WriteFeatures(colmap::Database* database, const colmap::image_t image_id,
                   std::mt19937* random) {
  colmap::FeatureKeypoints keypoints;
  colmap::FeatureDescriptors descriptors(kNumFeatures, 128);
  std::uniform_int_distribution<int> byte(0, 60);
  for (int k = 0; k < kNumFeatures; ++k) {
    keypoints.emplace_back(15.5f * (k % 8) + 20, 40.5f * (k / 8) + 20);
    for (int j = 0; j < 128; ++j) descriptors(k, j) = byte(*random);
  }
  database->WriteKeypoints(image_id, keypoints);
  database->WriteDescriptors(image_id, descriptors);
}

// The inputs of a calibration, in <temp>/inputs:
//   database.db      COLMAP 3.8: map images map/0..2.png (SIMPLE_RADIAL),
//                    rig images cam0/, cam1/ 0001, 0002.png (one camera per
//                    folder) and 0001.png, 0002.png outside any folder,
//                    features for all; the rig features match nothing in the
//                    map
//   sparse/          the map: 3 registered images, kNumMapPoints points seen
//                    by all three
//   rig_images/      cam0/000{1,2}.png, cam1/000{1,2}.png (never decoded)
// and the output folder <temp>/out.
class CalibrateCommandBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    inputs_ = temp_.File("inputs");
    output_ = temp_.File("out");
    database_ = inputs_ + "/database.db";
    map_ = inputs_ + "/sparse";
    rig_images_ = inputs_ + "/rig_images";
    fs::create_directories(map_);
    WriteDatabase(database_, /*with_rig_images=*/true);
    WriteMap(map_, /*with_points=*/true);
    for (const std::string name :
         {"cam0/0001.png", "cam0/0002.png", "cam1/0001.png", "cam1/0002.png"}) {
      WriteBytes(rig_images_ + "/" + name, "not decoded");
    }
  }

  static void WriteDatabase(const std::string& path,
                            const bool with_rig_images) {
    std::mt19937 random(11);
    colmap::Database database(path);
    colmap::Camera map_camera;
    map_camera.InitializeWithName("SIMPLE_RADIAL", 500, 640, 480);
    map_camera.SetCameraId(database.WriteCamera(map_camera));
    for (int i = 0; i < 3; ++i) {
      colmap::Image image;
      image.SetName("map/" + std::to_string(i) + ".png");
      image.SetCameraId(map_camera.CameraId());
      WriteFeatures(&database, database.WriteImage(image), &random);
    }
    if (!with_rig_images) return;
    for (const std::string folder : {"cam0", "cam1", "flat"}) {
      colmap::Camera camera;
      camera.InitializeWithName("OPENCV", 400, 640, 480);
      camera.SetCameraId(database.WriteCamera(camera));
      for (const std::string file : {"0001.png", "0002.png"}) {
        colmap::Image image;
        image.SetName(folder == "flat" ? file : folder + "/" + file);
        image.SetCameraId(camera.CameraId());
        WriteFeatures(&database, database.WriteImage(image), &random);
      }
    }
  }

  // The map images have the database's names and keypoint counts; point p
  // is keypoint p of every map image.
  static void WriteMap(const std::string& folder, const bool with_points) {
    colmap::Reconstruction map;
    colmap::Camera camera;
    camera.InitializeWithName("SIMPLE_RADIAL", 500, 640, 480);
    camera.SetCameraId(1);
    map.AddCamera(camera);
    for (colmap::image_t image_id = 1; image_id <= 3; ++image_id) {
      colmap::Image image;
      image.SetImageId(image_id);
      image.SetName("map/" + std::to_string(image_id - 1) + ".png");
      image.SetCameraId(1);
      image.SetQvec(Eigen::Vector4d(1, 0, 0, 0));
      image.SetTvec(Eigen::Vector3d(image_id, 0, 0));
      image.SetPoints2D(std::vector<Eigen::Vector2d>(
          kNumFeatures, Eigen::Vector2d(320.5, 240.5)));
      map.AddImage(image);
      map.RegisterImage(image_id);
    }
    for (int p = 0; with_points && p < kNumMapPoints; ++p) {
      colmap::Track track;
      for (colmap::image_t image_id = 1; image_id <= 3; ++image_id) {
        track.AddElement(image_id, p);
      }
      map.AddPoint3D(Eigen::Vector3d(p % 5, p / 5, 5), track);
    }
    fs::create_directories(folder);
    map.WriteBinary(folder);
  }

  std::vector<std::string> Arguments() const {
    return {"--database_path", database_, "--image_path",  rig_images_,
            "--input_path",    map_,      "--output_path", output_};
  }

  // `arguments` with option `name` set to `value` (added if missing).
  static std::vector<std::string> With(std::vector<std::string> arguments,
                                       const std::string& name,
                                       const std::string& value) {
    for (size_t i = 0; i + 1 < arguments.size(); ++i) {
      if (arguments[i] == name) {
        arguments[i + 1] = value;
        return arguments;
      }
    }
    arguments.push_back(name);
    arguments.push_back(value);
    return arguments;
  }

  // Runs the command; expects failure, every `expected` text in the
  // messages, no output and unchanged inputs.
  void ExpectFails(const std::vector<std::string>& arguments,
                   const std::vector<std::string>& expected) {
    const std::map<std::string, std::string> inputs_before =
        testing::SnapshotFolder(inputs_);
    const std::map<std::string, std::string> temp_before =
        testing::SnapshotFolder(temp_.path());
    ::testing::internal::CaptureStderr();
    ::testing::internal::CaptureStdout();
    const int exit_code = testing::RunCommand(&RunCalibrate, arguments);
    const std::string output = ::testing::internal::GetCapturedStdout();
    const std::string messages = ::testing::internal::GetCapturedStderr();
    ASSERT_NE(messages.find("ERROR: "), std::string::npos) << messages;
    // What the user sees, for the test log.
    std::cout << messages.substr(messages.rfind("ERROR: ")) << std::flush;
    EXPECT_EQ(exit_code, EXIT_FAILURE) << messages;
    for (const std::string& text : expected) {
      EXPECT_NE(messages.find(text), std::string::npos)
          << "expected '" << text << "' in:\n"
          << messages;
    }
    EXPECT_FALSE(fs::exists(output_));
    // No temporary output folder and no database side file (-wal, -shm,
    // -journal) left behind, and the inputs are byte for byte the same.
    EXPECT_EQ(testing::SnapshotFolder(temp_.path()), temp_before);
    EXPECT_TRUE(testing::SnapshotFolder(inputs_) == inputs_before);
  }

  testing::ScopedTempDir temp_;
  std::string inputs_;
  std::string output_;
  std::string database_;
  std::string map_;
  std::string rig_images_;
};

TEST_F(CalibrateCommandBadInput, MissingOptionsAndPaths) {
  ExpectFails({"--database_path", database_, "--image_path", rig_images_,
               "--input_path", map_},
              {"--output_path is required"});
  ExpectFails({"--database_path", database_, "--output_path", output_},
              {"--database_path", "--image_path", "--input_path",
               "--correspondences_path"});
  const std::string missing = inputs_ + "/missing";
  ExpectFails(With(Arguments(), "--database_path", missing),
              {"database " + missing + ": no such file"});
  ExpectFails(With(Arguments(), "--image_path", missing),
              {"--image_path " + missing + " does not exist"});
  ExpectFails(
      With(Arguments(), "--input_path", missing),
      {"the map folder " + missing + " does not exist", "--input_path"});
  ExpectFails({"--correspondences_path", missing, "--output_path", output_},
              {missing});
}

TEST_F(CalibrateCommandBadInput, MapOptionsAndExportDatabase) {
  // The export never overwrites: neither the input database nor another file.
  ExpectFails(With(Arguments(), "--RigCalibrator.export_database", database_),
              {"--RigCalibrator.export_database " + database_ + " exists"});
  ExpectFails({"--correspondences_path", database_, "--output_path", output_,
               "--RigCalibrator.export_database", inputs_ + "/new.db"},
              {"--RigCalibrator.export_database needs the map's database"});
  ExpectFails(With(With(Arguments(), "--RigCalibrator.refine_map", "0"),
                   "--RigCalibrator.refine_map_intrinsics", "1"),
              {"--RigCalibrator.refine_map_intrinsics 1 needs "
               "--RigCalibrator.refine_map 1"});
}

TEST_F(CalibrateCommandBadInput, PathsOfTheWrongKind) {
  // A folder as the database, a file as the image folder, a file as the map.
  ExpectFails(With(Arguments(), "--database_path", rig_images_),
              {"database " + rig_images_ + ": not a regular file"});
  ExpectFails(With(Arguments(), "--image_path", database_),
              {"--image_path " + database_ +
               " does not exist or is not a "
               "folder"});
  ExpectFails(
      With(Arguments(), "--input_path", database_),
      {"the map folder " + database_ + " does not exist or is not a folder"});
  // A folder without a model.
  ExpectFails(With(Arguments(), "--input_path", rig_images_),
              {"the map folder " + rig_images_ + " has no cameras.txt"});
}

TEST_F(CalibrateCommandBadInput, DatabaseWithoutTheRigImages) {
  const std::string map_only = inputs_ + "/map_only.db";
  WriteDatabase(map_only, /*with_rig_images=*/false);
  ExpectFails(With(Arguments(), "--database_path", map_only),
              {"4 of the 4 images under " + rig_images_ +
                   " are not in the database " + map_only,
               "feature_extractor"});
}

TEST_F(CalibrateCommandBadInput, RigImagesWithoutFeatures) {
  // Image rows without keypoints: feature extraction was interrupted.
  ExecuteSql(database_,
             "DELETE FROM keypoints WHERE image_id IN (SELECT image_id FROM "
             "images WHERE name LIKE 'cam1/%');");
  ExpectFails(Arguments(), {database_, "cam1/0001.png"});
}

TEST_F(CalibrateCommandBadInput, ImagesMissingFromDisk) {
  const std::string empty = inputs_ + "/empty";
  fs::create_directories(empty + "/cam0");
  fs::create_directories(empty + "/cam1");
  WriteBytes(empty + "/cam0/notes.txt", "not an image");
  ExpectFails(
      With(Arguments(), "--image_path", empty),
      {"no images (png, jpg, pgm, ppm, bmp, tif) under --image_path " + empty});
}

TEST_F(CalibrateCommandBadInput, ModelWithoutPoints) {
  const std::string no_points = inputs_ + "/no_points";
  WriteMap(no_points, /*with_points=*/false);
  ExpectFails(With(Arguments(), "--input_path", no_points),
              {"the map in " + no_points + " has no 3D points"});
}

TEST_F(CalibrateCommandBadInput, NoCameraFolders) {
  const std::string flat = inputs_ + "/flat";
  WriteBytes(flat + "/0001.png", "not decoded");
  WriteBytes(flat + "/0002.png", "not decoded");
  ExpectFails(
      With(Arguments(), "--image_path", flat),
      {"the rig images under --image_path " + flat + ": no camera folders"});
}

TEST_F(CalibrateCommandBadInput, OneCameraOnly) {
  const std::string one = inputs_ + "/one_camera";
  WriteBytes(one + "/cam0/0001.png", "not decoded");
  WriteBytes(one + "/cam0/0002.png", "not decoded");
  ExpectFails(With(Arguments(), "--image_path", one),
              {"the rig images under --image_path " + one +
               ": a rig needs at least two cameras: found only cam0/"});
}

TEST_F(CalibrateCommandBadInput, NoImageLocalized) {
  // Valid inputs all the way through localization, but the rig features
  // match nothing in the map.
  ExpectFails(Arguments(), {"no image could be localized in the map"});
}

TEST_F(CalibrateCommandBadInput, UnknownCameraModels) {
  ExpectFails(With(Arguments(), "--RigCalibrator.camera_model", "NOT_A_MODEL"),
              {"unknown or unsupported camera model 'NOT_A_MODEL' for camera "
               "cam0"});
  // FOV is a COLMAP model the upgrade does not support.
  ExpectFails(
      With(Arguments(), "--RigCalibrator.camera_model", "cam0:OPENCV,cam1:FOV"),
      {"unknown or unsupported camera model 'FOV' for camera cam1"});
  ExpectFails(
      With(Arguments(), "--RigCalibrator.camera_model", "cam0:OPENCV,cam7:FOV"),
      {"--RigCalibrator.camera_model names camera 'cam7'"});
  ExpectFails(With(Arguments(), "--RigCalibrator.camera_model", "cam0:OPENCV"),
              {"--RigCalibrator.camera_model gives no model for camera cam1"});
}

TEST_F(CalibrateCommandBadInput, NonColmapFilesAsDatabase) {
  const std::string text = inputs_ + "/notes.db";
  WriteBytes(text, "# rig_calibrator 2D-3D correspondences\n");
  ExpectFails(With(Arguments(), "--database_path", text),
              {"database " + text + ": not an SQLite file"});
  const std::string model_file = map_ + "/images.bin";
  ExpectFails(With(Arguments(), "--database_path", model_file),
              {"database " + model_file + ": not an SQLite file"});
  const std::string other = inputs_ + "/songs.db";
  ExecuteSql(other, "CREATE TABLE songs (title TEXT);");
  ExpectFails(With(Arguments(), "--database_path", other),
              {"database " + other +
               ": an SQLite file but not a COLMAP "
               "database"});
}

// A COLMAP 4.1 database (written following its schema) of the map and rig
// images, with descriptors of `descriptor_type` and the camera of cam0 of
// model `cam0_model_id` (a known focal length).
void WriteColmap41Database(const std::string& path, const int descriptor_type,
                           const int cam0_model_id,
                           const std::vector<double>& cam0_params) {
  testing::ModernDatabase database(path, testing::ColmapSchema::k4_1);
  const uint32_t map_camera =
      database.AddCamera(2, 640, 480, {500, 320, 240, 0}, false);
  const uint32_t cam0 =
      database.AddCamera(cam0_model_id, 640, 480, cam0_params, true);
  const uint32_t cam1 =
      database.AddCamera(4, 640, 480, {480, 480, 320, 240, 0, 0, 0, 0}, false);
  for (const std::string name :
       {"map/0.png", "map/1.png", "map/2.png", "cam0/0001.png", "cam0/0002.png",
        "cam1/0001.png", "cam1/0002.png"}) {
    const uint32_t camera = name[0] == 'm'   ? map_camera
                            : name[3] == '0' ? cam0
                                             : cam1;
    const uint32_t image_id = database.AddImage(name, camera);
    database.AddKeypoints(image_id, 6, std::vector<float>(6 * 4, 1.0f));
    if (descriptor_type == 0) {
      database.AddSiftDescriptors(image_id, std::vector<uint8_t>(4 * 128, 3));
    } else {
      database.AddFloatDescriptors(image_id, descriptor_type, 128,
                                   std::vector<float>(4 * 128, 0.5f));
    }
  }
}

TEST_F(CalibrateCommandBadInput, DatabaseOfNonSiftDescriptors) {
  const std::string aliked = inputs_ + "/aliked.db";
  WriteColmap41Database(aliked, 2, 4, {400, 400, 320, 240, 0, 0, 0, 0});
  ExpectFails(With(Arguments(), "--database_path", aliked),
              {"database " + aliked + ": the descriptors are not all SIFT: " +
                   "ALIKED_N32 (2) for 7 image(s)",
               "SIFT descriptors (type 0) only"});
}

TEST_F(CalibrateCommandBadInput, RigCameraOfAModelThisBuildCannotUse) {
  // FISHEYE (COLMAP 4.0): fine for its image size, but not as the known
  // intrinsics of method known.
  const std::string fisheye = inputs_ + "/fisheye.db";
  WriteColmap41Database(fisheye, 0, 15, {400, 400, 320, 240});
  ExpectFails(With(With(Arguments(), "--database_path", fisheye),
                   "--RigCalibrator.method", "known"),
              {"method known needs the intrinsics of camera cam0 from "
               "database " +
                   fisheye +
                   ", but its camera 2 has the model FISHEYE (model id 15, "
                   "COLMAP >= 4.0), which COLMAP 3.8 (this build) does not "
                   "know",
               "--RigCalibrator.intrinsics_path"});
}

TEST_F(CalibrateCommandBadInput, NonColmapFilesAsModel) {
  // Binary files that are not a model: text, a database, a truncated file.
  const std::string text_model = inputs_ + "/text_as_binary";
  for (const std::string name : {"cameras", "images", "points3D"}) {
    WriteBytes(text_model + "/" + name + ".bin",
               "this is not a COLMAP model at all");
  }
  ExpectFails(With(Arguments(), "--input_path", text_model),
              {text_model + "/cameras.bin is not a COLMAP binary model file"});

  const std::string database_model = inputs_ + "/database_as_model";
  fs::create_directories(database_model);
  for (const std::string name : {"cameras", "images", "points3D"}) {
    fs::copy_file(database_, database_model + "/" + name + ".bin");
  }
  ExpectFails(
      With(Arguments(), "--input_path", database_model),
      {database_model + "/cameras.bin is not a COLMAP binary model file"});

  // An image name cut off by the end of the file (COLMAP 3.8 would loop
  // forever looking for its terminating zero).
  const std::string truncated = inputs_ + "/truncated";
  fs::copy(map_, truncated);
  const std::string images = testing::ReadBytes(map_ + "/images.bin");
  WriteBytes(truncated + "/images.bin", images.substr(0, 8 + 64 + 6));
  ExpectFails(With(Arguments(), "--input_path", truncated),
              {truncated + "/images.bin is not a COLMAP binary model file",
               "it ends inside an image name"});

  // A camera model id COLMAP 3.8 does not know (newer COLMAP has more
  // models): COLMAP 3.8's reader would abort.
  const std::string new_model = inputs_ + "/new_camera_model";
  fs::copy(map_, new_model);
  std::string cameras = testing::ReadBytes(map_ + "/cameras.bin");
  const int32_t unknown_model_id = 42;
  cameras.replace(8 + 4, 4, reinterpret_cast<const char*>(&unknown_model_id),
                  4);
  WriteBytes(new_model + "/cameras.bin", cameras);
  ExpectFails(With(Arguments(), "--input_path", new_model),
              {new_model + "/cameras.bin", "model id 42"});

  // Text files: junk, and a camera model COLMAP 3.8 does not know.
  const std::string junk_text = inputs_ + "/junk_text";
  for (const std::string name : {"cameras", "images", "points3D"}) {
    WriteBytes(junk_text + "/" + name + ".txt", "1 2 3\nnot a model\n");
  }
  ExpectFails(With(Arguments(), "--input_path", junk_text),
              {junk_text + "/cameras.txt line 1"});
  const std::string text_model_dir = inputs_ + "/text_model";
  colmap::Reconstruction map;
  map.ReadBinary(map_);
  fs::create_directories(text_model_dir);
  map.WriteText(text_model_dir);
  WriteBytes(text_model_dir + "/cameras.txt",
             "1 RAD_TAN_THIN_PRISM_FISHEYE 640 480 500 500 320 240\n");
  ExpectFails(
      With(Arguments(), "--input_path", text_model_dir),
      {text_model_dir + "/cameras.txt line 1", "RAD_TAN_THIN_PRISM_FISHEYE"});
  WriteBytes(text_model_dir + "/cameras.txt",
             "1 SIMPLE_RADIAL 640 480 500 320 240\n");
  ExpectFails(With(Arguments(), "--input_path", text_model_dir),
              {text_model_dir + "/cameras.txt line 1",
               "SIMPLE_RADIAL has 4 parameters, the line gives 3"});
  // An image whose pose is not finite (map_consistency.h; tracks and
  // observations that do not confirm each other are repaired instead,
  // map_consistency_command_test.cc).
  WriteBytes(text_model_dir + "/cameras.txt",
             "1 SIMPLE_RADIAL 640 480 500 320 240 0\n");
  std::string images_txt = testing::ReadBytes(text_model_dir + "/images.txt");
  const size_t record = images_txt.find("\n1 ") + 1;
  const size_t qw = images_txt.find(' ', record) + 1;
  images_txt.replace(qw, images_txt.find(' ', qw) - qw, "nan");
  WriteBytes(text_model_dir + "/images.txt", images_txt);
  ExpectFails(With(Arguments(), "--input_path", text_model_dir),
              {text_model_dir + "/images.txt: image map/0.png (id 1) has a "
                                "pose that is not finite"});
}

}  // namespace calibrate_command_test
}  // namespace rig_calibrator
