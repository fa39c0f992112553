// The model writer: the model it builds, uncalibrated cameras, timestamp
// framesets, all-or-nothing output, mismatched calibrations and refined map
// points.
#include "colmap_ext/io/model_writer.h"

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
#include "colmap_ext/io/rig_config_io.h"
#include "tests/colmap_ext/io/model_writer_scene.h"
#include "tests/testing.h"

namespace rig_calibrator {
namespace model_writer_test {

namespace fs = std::filesystem;

using testing::ExpectFramesMatchImages;
using testing::kNumMapPoints;
using testing::MakeCamera;
using testing::MakeScene;
using testing::NumObservations;
using testing::Project;
using testing::Scene;
using testing::SmallPose;

TEST(ModelWriter, BuildsTheModel) {
  const Scene scene = MakeScene();
  RigModel rig_model;
  std::string error;
  ASSERT_TRUE(BuildRigModel(scene.map, scene.dataset, scene.calibration,
                            &rig_model, &error))
      << error;
  const colmap::Reconstruction& model = rig_model.model;
  EXPECT_EQ(model.NumCameras(), 4u);
  EXPECT_EQ(rig_model.rig.camera_ids, (std::vector<colmap::camera_t>{2, 3, 4}));
  EXPECT_EQ(model.NumRegImages(), 2u + scene.num_registered);
  EXPECT_EQ(NumObservations(model),
            2u * kNumMapPoints + scene.num_observations);
  EXPECT_EQ(rig_model.rig.frames.size(), 3u);
  for (size_t i = 0; i < scene.dataset.images.size(); ++i) {
    const RigImage& rig_image = scene.dataset.images[i];
    const colmap::image_t image_id = rig_model.image_ids[i];
    if (!scene.calibration.images[i].used) {
      EXPECT_EQ(image_id, colmap::kInvalidImageId);
      continue;
    }
    EXPECT_EQ(image_id, 3 + i);
    const colmap::Image& image = model.Image(image_id);
    EXPECT_EQ(image.Name(), rig_image.name);
    EXPECT_EQ(image.NumPoints2D(), rig_image.correspondences.size());
    // The pose is the calibration's, whatever frame the rig is written in.
    const Rigid3d expected = scene.calibration.CamFromWorld(
        rig_image.camera_index, rig_image.frameset_index);
    const Rigid3d actual = Rigid3d::FromQvecTvec(image.Qvec(), image.Tvec());
    EXPECT_LT((expected.ToMatrix() - actual.ToMatrix()).norm(), 1e-12);
    // Inlier correspondences observe their map point; the image's points
    // reproject onto their observations with the calibrated camera.
    for (colmap::point2D_t k = 0; k < image.NumPoints2D(); ++k) {
      if (!image.Point2D(k).HasPoint3D()) continue;
      EXPECT_TRUE(scene.calibration.images[i].inlier_mask[k]);
      const colmap::Point3D& point =
          model.Point3D(image.Point2D(k).Point3DId());
      EXPECT_LT((Project(model.Camera(image.CameraId()), actual, point.XYZ()) -
                 image.Point2D(k).XY())
                    .norm(),
                1e-6);
    }
  }
  // The rig is expressed in the reference camera's frame.
  EXPECT_LT(
      (rig_model.rig.cam_from_rig[0]->ToMatrix() - Rigid3d().ToMatrix()).norm(),
      1e-15);
}

TEST(ModelWriter, UncalibratedCameraHasNoPoseAndNoImages) {
  Scene scene = MakeScene();
  scene.calibration.camera_calibrated[2] = false;
  testing::ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::vector<std::string> notes;
  std::string error;
  ASSERT_TRUE(
      WriteRigOutput(output, scene.map, scene.dataset, scene.calibration, {},
                     SummarizeCalibration(scene.dataset, scene.calibration, {}),
                     RigOutputOptions(), &notes, &error))
      << error;
  colmap::Reconstruction model;
  model.Read(output);
  EXPECT_EQ(model.NumCameras(), 4u);  // the camera is there, with its images
  EXPECT_EQ(model.NumRegImages(), 2u + 6u);  // cam0 and cam1 in 3 framesets
  ColmapRigsAndFrames rigs_frames;
  ASSERT_TRUE(ReadRigsAndFrames(output, &rigs_frames, &error)) << error;
  ASSERT_EQ(rigs_frames.rigs[1].sensors.size(), 2u);
  EXPECT_TRUE(rigs_frames.rigs[1].sensors[0].sensor_from_rig);
  EXPECT_FALSE(rigs_frames.rigs[1].sensors[1].sensor_from_rig);
  ExpectFramesMatchImages(model, rigs_frames);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("cam2 is not calibrated"), std::string::npos);
}

TEST(ModelWriter, TimestampFramesetsAreNotedForColmapsRigTools) {
  Scene scene = MakeScene();
  scene.dataset.images[0].name = "cam0/0_late.png";
  testing::ScopedTempDir dir;
  std::vector<std::string> notes;
  std::string error;
  ASSERT_TRUE(WriteRigOutput(dir.File("out"), scene.map, scene.dataset,
                             scene.calibration, {}, CalibrationSummary(),
                             RigOutputOptions(), &notes, &error))
      << error;
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(notes[0].find("will see 2 snapshots with two images or more, "
                          "where this calibration has 3"),
            std::string::npos)
      << notes[0];
  EXPECT_NE(notes[1].find("rig_config.json: 1 framesets pair images with "
                          "different names"),
            std::string::npos)
      << notes[1];
}

TEST(ModelWriter, OutputIsAllOrNothing) {
  const Scene scene = MakeScene();
  testing::ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::string error;
  auto write = [&](const RigDataset& dataset, const RigOutputOptions& options) {
    return WriteRigOutput(output, scene.map, dataset, scene.calibration, {},
                          CalibrationSummary(), options, nullptr, &error);
  };

  // A failure midway (the correspondence file, written last, refuses a name
  // with a line break) leaves neither the output nor a temporary folder.
  RigDataset bad_names = scene.dataset;
  bad_names.images[0].name = "cam0/bad\nname.png";
  EXPECT_FALSE(write(bad_names, RigOutputOptions()));
  EXPECT_NE(error.find("line break"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(output));
  EXPECT_TRUE(fs::is_empty(dir.path()));

  // An existing non-empty output folder is kept unless overwrite is set.
  fs::create_directory(output);
  std::ofstream(output + "/keep.txt") << "x";
  EXPECT_FALSE(write(scene.dataset, RigOutputOptions()));
  EXPECT_NE(error.find("exists and is not empty"), std::string::npos) << error;
  EXPECT_TRUE(fs::exists(output + "/keep.txt"));
  EXPECT_FALSE(write(bad_names, [] {
    RigOutputOptions options;
    options.overwrite = true;
    return options;
  }()));
  EXPECT_TRUE(fs::exists(output + "/keep.txt"));
  RigOutputOptions overwrite;
  overwrite.overwrite = true;
  ASSERT_TRUE(write(scene.dataset, overwrite)) << error;
  EXPECT_FALSE(fs::exists(output + "/keep.txt"));
  EXPECT_TRUE(fs::exists(output + "/images.bin"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()),
                          fs::directory_iterator()),
            1);

  // An empty output folder is fine; outputs overlapping inputs are not.
  fs::remove_all(output);
  fs::create_directory(output);
  EXPECT_TRUE(write(scene.dataset, RigOutputOptions())) << error;
  RigOutputOptions inside_input;
  inside_input.overwrite = true;
  inside_input.input_paths = {dir.path()};
  EXPECT_FALSE(write(scene.dataset, inside_input));
  EXPECT_NE(error.find("overlaps the input path"), std::string::npos);
  inside_input.input_paths = {output + "/../out/sparse"};
  EXPECT_FALSE(write(scene.dataset, inside_input));
  RigOutputOptions bad_type;
  bad_type.output_type = "PLY";
  EXPECT_FALSE(write(scene.dataset, bad_type));
}

TEST(ModelWriter, RejectsMismatchedCalibration) {
  Scene scene = MakeScene();
  RigModel rig_model;
  std::string error;
  RigCalibration short_calibration = scene.calibration;
  short_calibration.rig_from_world.pop_back();
  EXPECT_FALSE(BuildRigModel(scene.map, scene.dataset, short_calibration,
                             &rig_model, &error));
  EXPECT_NE(error.find("does not match the dataset"), std::string::npos);
  RigCalibration bad_mask = scene.calibration;
  bad_mask.images[0].inlier_mask.pop_back();
  EXPECT_FALSE(
      BuildRigModel(scene.map, scene.dataset, bad_mask, &rig_model, &error));
  RigCalibration bad_camera = scene.calibration;
  bad_camera.cameras[1].Params().pop_back();
  EXPECT_FALSE(
      BuildRigModel(scene.map, scene.dataset, bad_camera, &rig_model, &error));
  EXPECT_NE(error.find("cam1 has invalid intrinsics"), std::string::npos);
  RigDataset map_name = scene.dataset;
  map_name.images[0].name = "map/1.png";
  EXPECT_FALSE(BuildRigModel(scene.map, map_name, scene.calibration, &rig_model,
                             &error));
  EXPECT_NE(error.find("has the name of a map image"), std::string::npos);
}

TEST(ModelWriter, MovesRefinedMapPoints) {
  Scene scene = MakeScene();
  const colmap::point3D_t point3D_id = *scene.map.Point3DIds().begin();
  const Eigen::Vector3d moved =
      scene.map.Point3D(point3D_id).XYZ() + Eigen::Vector3d(0.01, 0, 0);
  scene.calibration.refined_points3D[point3D_id] = moved;
  RigModel rig_model;
  std::string error;
  ASSERT_TRUE(BuildRigModel(scene.map, scene.dataset, scene.calibration,
                            &rig_model, &error))
      << error;
  EXPECT_EQ(rig_model.model.Point3D(point3D_id).XYZ(), moved);

  // A refined point that the map does not have is an inconsistency...
  RigCalibration unknown_point = scene.calibration;
  unknown_point.refined_points3D[1000000] = moved;
  EXPECT_FALSE(BuildRigModel(scene.map, scene.dataset, unknown_point,
                             &rig_model, &error));
  EXPECT_NE(error.find("refined point 1000000 is not a map point"),
            std::string::npos);
  // ... except in a run from a correspondence file, which has no map points.
  colmap::Reconstruction no_points;
  for (const auto& [camera_id, camera] : scene.map.Cameras()) {
    no_points.AddCamera(camera);
  }
  ASSERT_TRUE(BuildRigModel(no_points, scene.dataset, unknown_point, &rig_model,
                            &error))
      << error;
  EXPECT_EQ(rig_model.model.NumPoints3D(), 0u);
}

}  // namespace model_writer_test
}  // namespace rig_calibrator
