// `rig_calibrator calibrate` end to end, in process, on the real files of
// COLMAP 4.1.1 in tests/data/colmap_4_1_1 (its database and its binary and
// text maps of a rendered scene; README.md there says how they were made),
// compared with the renderer's ground truth by `rig_calibrator evaluate`.
// Also: framesets and known poses from the database's frames and rig after
// COLMAP's rig_configurator, and a map camera of a model COLMAP 3.8 does not
// know.
//
// Bounds. The map's camera centres are 5.2 mm (mean) and 14.7 mm (max) from
// the truth, and the rig is seen in 4 framesets only (20 images, ~4 400 2D-3D
// correspondences). Measured (rig_calibrator evaluate, the three tests here
// run 5 times; the localization's threads change the correspondences
// slightly from run to run): rotation <= 0.26 deg, center <= 12.1 mm, focal
// <= 0.33 %, principal point <= 3.3 px. The bounds leave about 2x of that:
// 0.5 deg, 30 mm (twice the map's largest centre error), 1 % and 6 px; a
// wrong reading (swapped cameras, a frame in the wrong frameset, keypoints
// of the wrong image) misses them by far.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "colmap_ext/commands/commands.h"
#include "colmap_ext/io/camera_records_io.h"
#include "colmap_ext/io/colmap_camera_models.h"
#include "colmap_ext/io/database_reader.h"
#include "colmap_ext/io/map_reader.h"
#include "colmap_ext/io/rig_config_io.h"
#include "colmap_ext/io/rigs_frames_io.h"
#include "tests/colmap_ext/colmap_testing.h"
#include "tests/colmap_ext/modern_database.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace colmap_4_1_1_calibration_test {

namespace fs = std::filesystem;

constexpr double kMaxRotationDeg = 0.5;
constexpr double kMaxCenterError = 0.03;  // meters: the map is metric
constexpr double kMaxFocalErrorPercent = 1.0;
constexpr double kMaxPrincipalPointErrorPx = 6.0;

std::string DataDir() {
  return testing::SourceDir() + "/tests/data/colmap_4_1_1";
}

class Colmap411CalibrationTest : public ::testing::Test {
 protected:
  // Runs calibrate; returns what it printed (and echoes it for the log).
  std::string Calibrate(const std::vector<std::string>& arguments,
                        int* exit_code) {
    ::testing::internal::CaptureStdout();
    *exit_code = testing::RunCommand(&RunCalibrate, arguments);
    const std::string output = ::testing::internal::GetCapturedStdout();
    std::cout << output << std::flush;
    return output;
  }

  // Evaluates `output` against the ground truth, checks the bounds and
  // prints the errors.
  void ExpectCloseToGroundTruth(const std::string& output) {
    const std::string errors = temp_.File("errors.json");
    ASSERT_EQ(
        testing::RunCommand(
            &RunEvaluate,
            {"--reference_path", DataDir() + "/ground_truth/rig_config.json",
             "--calibration_path", output, "--output_path", errors}),
        EXIT_SUCCESS);
    std::ifstream file(errors);
    const nlohmann::json cameras = nlohmann::json::parse(file)["cameras"];
    ASSERT_EQ(cameras.size(), 5u);
    for (const nlohmann::json& camera : cameras) {
      std::cout << "  " << camera["name"].get<std::string>() << ": rotation "
                << camera["rotation_deg"] << " deg, center "
                << camera["center_error"] << " m, focal "
                << camera["focal_error_percent"] << " %, principal point "
                << camera["principal_point_error_px"] << " px\n";
      EXPECT_LT(camera["rotation_deg"].get<double>(), kMaxRotationDeg);
      EXPECT_LT(camera["center_error"].get<double>(), kMaxCenterError);
      EXPECT_LT(camera["focal_error_percent"].get<double>(),
                kMaxFocalErrorPercent);
      EXPECT_LT(camera["principal_point_error_px"].get<double>(),
                kMaxPrincipalPointErrorPx);
    }
  }

  testing::ScopedTempDir temp_;
};

// The output's rigs and frames are what COLMAP 4.1.1 reads: the map's
// trivial rig and frames as in its own files, one rig of the 5 calibrated
// cameras, one frame of 5 images per frameset, and every registered image in
// one frame with a consistent pose (ReadMap checks both).
void ExpectColmap41RigsAndFrames(const std::string& output,
                                 const std::string& map) {
  colmap::Reconstruction model;
  MapReadInfo info;
  std::string error;
  ASSERT_TRUE(ReadMap(output, &model, &info, &error)) << error;
  EXPECT_EQ(model.NumRegImages(), 50u);
  EXPECT_EQ(info.num_rigs, 2);
  EXPECT_EQ(info.num_multi_camera_rigs, 1);
  EXPECT_EQ(info.num_frames, 34);

  ColmapRigsAndFrames written;
  ColmapRigsAndFrames input;
  ASSERT_TRUE(ReadRigsAndFrames(output, &written, &error)) << error;
  ASSERT_TRUE(ReadRigsAndFrames(map, &input, &error)) << error;
  ASSERT_EQ(written.rigs.size(), 2u);
  EXPECT_EQ(written.rigs[0].rig_id, input.rigs[0].rig_id);
  EXPECT_EQ(written.rigs[0].ref_sensor.id, input.rigs[0].ref_sensor.id);
  EXPECT_TRUE(written.rigs[0].sensors.empty());
  ASSERT_EQ(written.rigs[1].sensors.size(), 4u);
  for (const ColmapRigSensor& sensor : written.rigs[1].sensors) {
    EXPECT_TRUE(sensor.sensor_from_rig.has_value());
  }
  ASSERT_EQ(written.frames.size(), 34u);
  for (size_t f = 0; f < 30; ++f) {
    const ColmapFrame& a = written.frames[f];
    const ColmapFrame& b = input.frames[f];
    EXPECT_EQ(a.frame_id, b.frame_id);
    EXPECT_EQ(a.rig_id, b.rig_id);
    ASSERT_EQ(a.data.size(), 1u);
    EXPECT_EQ(a.data[0].data_id, b.data[0].data_id);
    // The final adjustment refines the map (refine_map, the default): a map
    // image's trivial frame is its adjusted pose in the output model, within
    // centimetres of the input map's.
    const colmap::Image& image =
        model.Image(static_cast<colmap::image_t>(a.data[0].data_id));
    const Rigid3d cam_from_world(
        Eigen::Quaterniond(image.Qvec()(0), image.Qvec()(1), image.Qvec()(2),
                           image.Qvec()(3)),
        image.Tvec());
    EXPECT_LT((a.rig_from_world.ToMatrix() - cam_from_world.ToMatrix()).norm(),
              1e-9);
    EXPECT_LT(
        (a.rig_from_world.ToMatrix() - b.rig_from_world.ToMatrix()).norm(),
        0.05);
  }
  for (size_t f = 30; f < 34; ++f) {
    EXPECT_EQ(written.frames[f].rig_id, written.rigs[1].rig_id);
    EXPECT_EQ(written.frames[f].data.size(), 5u);
  }
  if (fs::exists(map + "/rigs.bin")) {
    // The trivial rig byte for byte as COLMAP 4.1.1 wrote it (after the
    // count). The trivial frames' poses are the output model's image poses
    // (1e-9 above); the map is adjusted with the rig (refine_map), so they
    // are compared with the input map's frames to 0.05 (matrix norm) only.
    EXPECT_EQ(testing::ReadBytes(output + "/rigs.bin").substr(8, 16),
              testing::ReadBytes(map + "/rigs.bin").substr(8));
  }
}

class Colmap411MapTypeTest : public Colmap411CalibrationTest,
                             public ::testing::WithParamInterface<std::string> {
};

TEST_P(Colmap411MapTypeTest, CalibratesWithoutTouchingTheInputs) {
  const std::string map = DataDir() + "/map/" + GetParam();
  const std::map<std::string, std::string> inputs_before =
      testing::SnapshotFolder(DataDir());
  const std::string output = temp_.File("calibration");
  int exit_code = 0;
  const std::string printed = Calibrate(
      {"--database_path", DataDir() + "/calib.db", "--image_path",
       DataDir() + "/rig_images", "--input_path", map, "--output_path", output,
       "--output_type", GetParam() == "sparse_txt" ? "TXT" : "BIN"},
      &exit_code);
  ASSERT_EQ(exit_code, EXIT_SUCCESS);
  // The database and everything else byte for byte unchanged, no -wal or
  // -shm file next to the database.
  EXPECT_TRUE(testing::SnapshotFolder(DataDir()) == inputs_before);
  EXPECT_FALSE(fs::exists(DataDir() + "/calib.db-wal"));
  EXPECT_FALSE(fs::exists(DataDir() + "/calib.db-shm"));

  EXPECT_NE(printed.find("COLMAP 4.1.1 schema (user_version 4010100)"),
            std::string::npos);
  EXPECT_NE(printed.find("rigs and frames (COLMAP >= 3.12): 1 rig(s)"),
            std::string::npos);
  EXPECT_NE(printed.find("Rig layout: 5 cameras, 4 framesets (from identical "
                         "names after the camera prefix)"),
            std::string::npos);
  EXPECT_NE(printed.find("framesets with k cameras: 1: 0, 2: 0, 3: 0, 4: 0, "
                         "5: 4"),
            std::string::npos);
  EXPECT_NE(printed.find("20 of 20 images used, 4 of 4 framesets"),
            std::string::npos);
  ExpectCloseToGroundTruth(output);
  ExpectColmap41RigsAndFrames(output, map);
}

INSTANTIATE_TEST_SUITE_P(BinaryAndText, Colmap411MapTypeTest,
                         ::testing::Values("sparse/0", "sparse_txt"),
                         [](const auto& info) {
                           return info.param == "sparse/0" ? "BinaryMap"
                                                           : "TextMap";
                         });

// After COLMAP's rig_configurator (here its effect, written with SQL into a
// copy of the database): the frames group the rig images although their
// names after the camera prefix differ (cam1/c1_000000.jpg, ...), and the
// rig holds the ground truth's cam_from_rig, which the summary compares with.
// The map camera is a FISHEYE (COLMAP 4.0) in a copy of the map.
TEST_F(Colmap411CalibrationTest, FramesAndKnownPosesFromTheDatabase) {
  const std::string database = temp_.File("calib.db");
  fs::copy_file(DataDir() + "/calib.db", database);
  fs::permissions(database, fs::perms::owner_write, fs::perm_options::add);
  const std::string images = temp_.File("rig_images");
  std::vector<RigDescription> truth;
  std::string error;
  ASSERT_TRUE(ReadRigConfigJson(DataDir() + "/ground_truth/rig_config.json",
                                &truth, &error))
      << error;
  ASSERT_EQ(truth.size(), 1u);
  std::vector<uint32_t> camera_ids(5);
  std::vector<std::vector<uint32_t>> frames(4);
  {
    DatabaseReader reader;
    ASSERT_TRUE(reader.Open(database, &error)) << error;
    for (int c = 0; c < 5; ++c) {
      for (int f = 0; f < 4; ++f) {
        const std::string name =
            "cam" + std::to_string(c) + "/00000" + std::to_string(f) + ".jpg";
        const DatabaseImage* image = reader.FindImageWithName(name);
        ASSERT_NE(image, nullptr) << name;
        camera_ids[c] = image->camera_id;
        frames[f].push_back(image->image_id);
        const std::string renamed = c == 0 ? name
                                           : "cam" + std::to_string(c) + "/c" +
                                                 std::to_string(c) + "_00000" +
                                                 std::to_string(f) + ".jpg";
        fs::create_directories(fs::path(images + "/" + renamed).parent_path());
        fs::copy_file(DataDir() + "/rig_images/" + name,
                      images + "/" + renamed);
      }
    }
  }
  std::vector<std::optional<Rigid3d>> cam_from_rig;
  for (const RigDescriptionCamera& camera : truth[0].cameras) {
    cam_from_rig.push_back(camera.cam_from_rig);
  }
  cam_from_rig[0].reset();  // the reference sensor has no pose
  {
    testing::ModernDatabase writer(database, testing::ColmapSchema::k4_1,
                                   /*create=*/false);
    writer.Execute(
        "UPDATE images SET name = substr(name, 1, 5) || 'c' || substr(name, "
        "4, 1) || '_' || substr(name, 6) WHERE name LIKE 'cam%' AND name NOT "
        "LIKE 'cam0/%';");
    writer.GroupFrames(camera_ids, cam_from_rig, frames);
  }
  const std::string map = temp_.File("map");
  fs::copy(DataDir() + "/map/sparse/0", map);
  CameraRecord fisheye;
  fisheye.camera_id = 1;
  fisheye.model_id = ColmapCameraModelIdFromName("FISHEYE");
  fisheye.width = 640;
  fisheye.height = 480;
  fisheye.params = {400, 400, 320, 240};
  ASSERT_TRUE(WriteCameraRecords(map + "/cameras.bin", true, {fisheye}, &error))
      << error;

  const std::string output = temp_.File("calibration");
  int exit_code = 0;
  const std::string printed =
      Calibrate({"--database_path", database, "--image_path", images,
                 "--input_path", map, "--output_path", output},
                &exit_code);
  ASSERT_EQ(exit_code, EXIT_SUCCESS);
  EXPECT_NE(printed.find("Rig layout: 5 cameras, 4 framesets (from the "
                         "database's frames (COLMAP rig_configurator)"),
            std::string::npos);
  EXPECT_NE(printed.find("5: 4"), std::string::npos);
  EXPECT_NE(printed.find("1 FISHEYE (model id 15, COLMAP >= 4.0)"),
            std::string::npos);
  EXPECT_NE(printed.find("against the known rig of database " + database),
            std::string::npos);
  ExpectCloseToGroundTruth(output);

  // The comparison with the database's rig in the summary: the ground truth,
  // so within the same bounds.
  std::ifstream summary_file(output + "/calibration_summary.json");
  const nlohmann::json known = nlohmann::json::parse(summary_file)["known_rig"];
  ASSERT_TRUE(known.is_object());
  EXPECT_EQ(known["reference_camera"], "cam0");
  ASSERT_EQ(known["cameras"].size(), 4u);
  for (const nlohmann::json& camera : known["cameras"]) {
    EXPECT_LT(camera["rotation_error_deg"].get<double>(), kMaxRotationDeg);
    EXPECT_LT(camera["translation_error"].get<double>(), kMaxCenterError);
    EXPECT_GT(camera["known_translation_norm"].get<double>(), 0.1);
  }
  // The map camera is written back as it was.
  std::vector<CameraRecord> cameras;
  ASSERT_TRUE(
      ReadCameraRecords(output + "/cameras.bin", true, &cameras, &error))
      << error;
  ASSERT_EQ(cameras.size(), 6u);
  int num_fisheye = 0;
  for (const CameraRecord& camera : cameras) {
    if (camera.camera_id != 1) continue;
    EXPECT_EQ(camera.model_id, fisheye.model_id);
    EXPECT_EQ(camera.params, fisheye.params);
    ++num_fisheye;
  }
  EXPECT_EQ(num_fisheye, 1);
}

}  // namespace colmap_4_1_1_calibration_test
}  // namespace rig_calibrator
