// WriteRigOutput in BIN and TXT: every file written, read back by COLMAP's
// and this project's readers, and the exchange formats agreeing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>

#include "colmap_ext/io/camchain_io.h"
#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/io/model_writer.h"
#include "colmap_ext/io/rig_config_io.h"
#include "tests/colmap_ext/io/model_writer_scene.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace model_writer_output_test {

namespace fs = std::filesystem;

using testing::ExpectFramesMatchImages;
using testing::kNumMapPoints;
using testing::MakeCamera;
using testing::MakeScene;
using testing::NumObservations;
using testing::Project;
using testing::Scene;
using testing::SmallPose;

// The files of the output folder, and nothing left next to it.
void ExpectOutputFiles(const testing::ScopedTempDir& dir,
                       const std::string& output,
                       const std::string& extension) {
  std::set<std::string> files;
  for (const auto& entry : fs::directory_iterator(output)) {
    files.insert(entry.path().filename().string());
  }
  EXPECT_EQ(files, (std::set<std::string>{
                       "cameras" + extension, "images" + extension,
                       "points3D" + extension, "rigs" + extension,
                       "frames" + extension, kRigConfigFile,
                       kRigBundleAdjusterConfigFile, kCamchainFile,
                       kSummaryFile, kTimingsFile, kCorrespondencesFile}));
  // No temporary folder is left next to the output.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()),
                          fs::directory_iterator()),
            1);
}

// The model of the output: map and rig images, map points, all observations
// and the calibrated intrinsics.
void ExpectModel(const colmap::Reconstruction& model, const Scene& scene) {
  EXPECT_EQ(model.NumCameras(), 4u);
  EXPECT_EQ(model.NumImages(), 2u + scene.num_registered);
  EXPECT_EQ(model.NumRegImages(), 2u + scene.num_registered);
  EXPECT_EQ(model.NumPoints3D(), static_cast<size_t>(kNumMapPoints));
  EXPECT_EQ(NumObservations(model),
            2u * kNumMapPoints + scene.num_observations);
  EXPECT_EQ(model.Camera(3).ModelName(), "OPENCV");
  EXPECT_EQ(model.Camera(3).Params(), scene.calibration.cameras[1].Params());
}

// rigs/frames: the map's trivial rig and the calibrated one, trivial map
// frames and rig frames with ids after every image id.
void ExpectRigsAndFrames(const colmap::Reconstruction& model,
                         const ColmapRigsAndFrames& rigs_frames) {
  ASSERT_EQ(rigs_frames.rigs.size(), 2u);
  EXPECT_EQ(rigs_frames.rigs[0].rig_id, 1u);
  EXPECT_EQ(rigs_frames.rigs[1].rig_id, 5u);
  EXPECT_EQ(rigs_frames.rigs[1].ref_sensor.id, 2u);
  ASSERT_EQ(rigs_frames.rigs[1].sensors.size(), 2u);
  // Two trivial map frames (ids = image ids) and three rig frames, with ids
  // after every image id (the largest is 11).
  ASSERT_EQ(rigs_frames.frames.size(), 5u);
  EXPECT_EQ(rigs_frames.frames[0].frame_id, 1u);
  EXPECT_EQ(rigs_frames.frames[1].frame_id, 2u);
  for (int f = 2; f < 5; ++f) {
    EXPECT_EQ(rigs_frames.frames[f].frame_id, 12u + (f - 2));
  }
  ExpectFramesMatchImages(model, rigs_frames);
}

// The exact text of COLMAP >= 3.12: trivial rig and frame lines, single
// spaces, no trailing space.
void ExpectRigsAndFramesText(const std::string& output) {
  const std::string rigs = testing::ReadBytes(output + "/rigs.txt");
  EXPECT_NE(rigs.find("# Number of rigs: 2\n1 1 CAMERA 1\n5 3 CAMERA 2 "
                      "CAMERA 3 1 "),
            std::string::npos)
      << rigs;
  const std::string frames = testing::ReadBytes(output + "/frames.txt");
  std::istringstream lines(frames);
  std::string line;
  int num_data_lines = 0;
  while (std::getline(lines, line)) {
    if (line[0] == '#') continue;
    ++num_data_lines;
    EXPECT_EQ(line.find("  "), std::string::npos) << line;
    EXPECT_NE(line.back(), ' ') << line;
  }
  EXPECT_EQ(num_data_lines, 5);
  EXPECT_NE(frames.find("\n1 1 "), std::string::npos);
  EXPECT_NE(frames.find(" 1 CAMERA 1 1\n"), std::string::npos);
  EXPECT_NE(frames.find(" 2 CAMERA 2 6 CAMERA 3 7\n"), std::string::npos)
      << frames;  // frameset 1 without its unused cam2 image (id 8)
}

// The exchange formats describe the same rig as rigs.*.
void ExpectExchangeFormatsAgree(const std::string& output,
                                const ColmapRigsAndFrames& rigs_frames) {
  ASSERT_EQ(rigs_frames.rigs.size(), 2u);
  ASSERT_EQ(rigs_frames.rigs[1].sensors.size(), 2u);
  std::string error;
  std::vector<RigDescription> rig_config;
  ASSERT_TRUE(
      ReadRigConfigJson(output + "/" + kRigConfigFile, &rig_config, &error))
      << error;
  RigDescription camchain;
  ASSERT_TRUE(ReadCamchainYaml(output + "/" + kCamchainFile, &camchain, &error))
      << error;
  ASSERT_EQ(rig_config.size(), 1u);
  ASSERT_EQ(camchain.cameras.size(), 3u);
  const ColmapRig& rig = rigs_frames.rigs[1];
  for (int c = 1; c < 3; ++c) {
    const Rigid3d& sensor_from_rig = *rig.sensors[c - 1].sensor_from_rig;
    EXPECT_LT((rig_config[0].cameras[c].cam_from_rig->ToMatrix() -
               sensor_from_rig.ToMatrix())
                  .norm(),
              1e-12);
    EXPECT_LT((camchain.cameras[c].cam_from_rig->ToMatrix() -
               sensor_from_rig.ToMatrix())
                  .norm(),
              1e-12);
  }
}

void ExpectSummary(const std::string& output) {
  std::ifstream summary_file(output + "/" + kSummaryFile);
  const nlohmann::json json = nlohmann::json::parse(summary_file);
  EXPECT_EQ(json["method"], "1dr");
  EXPECT_EQ(json["num_framesets"], 4);
  EXPECT_EQ(json["num_framesets_used"], 3);
  ASSERT_EQ(json["cameras"].size(), 3u);
  EXPECT_EQ(json["cameras"][2]["num_images"], 4);
  EXPECT_EQ(json["cameras"][2]["num_used"], 2);
  EXPECT_EQ(json["cameras"][2]["num_inliers"], 32);
  EXPECT_DOUBLE_EQ(json["cameras"][2]["rms_px"].get<double>(), 2.5);
  EXPECT_EQ(json["cameras"][1]["model"], "OPENCV");
  EXPECT_EQ(json["cameras"][0]["cam_from_rig"]["rotation_wxyz"][0], 1.0);
  EXPECT_EQ(json["diagnostics"][0], "a diagnostic of the caller");
  EXPECT_EQ(json["seed"], 17);
  // The timings, which change from run to run, are in a file of their own.
  EXPECT_FALSE(json.contains("timings_s"));
  std::ifstream timings_file(output + "/" + kTimingsFile);
  const nlohmann::json timings = nlohmann::json::parse(timings_file);
  EXPECT_EQ(timings["timings_s"]["localize"], 1.5);
  EXPECT_EQ(timings["cpu_s"]["localize"], 2.5);
  EXPECT_EQ(timings["iterations"]["localize"], 7);
}

class ModelWriterOutput : public ::testing::TestWithParam<std::string> {};

TEST_P(ModelWriterOutput, WritesEverythingAndReadsBack) {
  const std::string output_type = GetParam();
  const bool binary = output_type == "BIN";
  const Scene scene = MakeScene();
  testing::ScopedTempDir dir;
  const std::string output = dir.File("out");
  CalibrationSummary summary =
      SummarizeCalibration(scene.dataset, scene.calibration, {});
  summary.method = "1dr";
  summary.diagnostics.push_back("a diagnostic of the caller");
  summary.timings.push_back({"localize", 1.5, 2.5, 7});
  summary.seed = 17;
  RigOutputOptions options;
  options.output_type = output_type;
  std::vector<std::string> notes;
  std::string error;
  ASSERT_TRUE(WriteRigOutput(output, scene.map, scene.dataset,
                             scene.calibration, {}, summary, options, &notes,
                             &error))
      << error;

  ExpectOutputFiles(dir, output, binary ? ".bin" : ".txt");
  colmap::Reconstruction model;
  model.Read(output);
  ExpectModel(model, scene);
  ColmapRigsAndFrames rigs_frames;
  ASSERT_TRUE(ReadRigsAndFrames(output, &rigs_frames, &error)) << error;
  ExpectRigsAndFrames(model, rigs_frames);
  if (!binary) ExpectRigsAndFramesText(output);
  ExpectExchangeFormatsAgree(output, rigs_frames);
  ExpectSummary(output);
  std::vector<ImageCorrespondences> correspondences;
  ASSERT_TRUE(ReadCorrespondenceFile(output + "/" + kCorrespondencesFile,
                                     &correspondences, &error))
      << error;
  // Every image with every correspondence, bit for bit (a re-run from the
  // file must see the same input).
  ASSERT_EQ(correspondences.size(), scene.dataset.images.size());
  for (size_t i = 0; i < correspondences.size(); ++i) {
    const RigImage& image = scene.dataset.images[i];
    EXPECT_EQ(correspondences[i].image_name, image.name);
    const colmap::Camera& camera =
        scene.dataset.cameras[image.camera_index].camera;
    EXPECT_EQ(correspondences[i].width, static_cast<int>(camera.Width()));
    EXPECT_EQ(correspondences[i].height, static_cast<int>(camera.Height()));
    ASSERT_EQ(correspondences[i].correspondences.size(),
              image.correspondences.size());
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      const Correspondence& read = correspondences[i].correspondences[k];
      EXPECT_EQ(read.point2D, image.correspondences[k].point2D);
      EXPECT_EQ(read.point3D, image.correspondences[k].point3D);
      EXPECT_EQ(read.point3D_id, image.correspondences[k].point3D_id);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(BinAndTxt, ModelWriterOutput,
                         ::testing::Values("BIN", "TXT"));

}  // namespace model_writer_output_test
}  // namespace rig_calibrator
