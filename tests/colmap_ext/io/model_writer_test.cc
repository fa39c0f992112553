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
#include "tests/testing.h"

namespace rig_calibrator {
namespace {

namespace fs = std::filesystem;

constexpr int kNumMapPoints = 60;

colmap::Camera MakeCamera(const std::string& model,
                          const std::vector<double>& params) {
  colmap::Camera camera;
  camera.SetModelIdFromName(model);
  camera.SetWidth(640);
  camera.SetHeight(480);
  camera.SetParams(params);
  return camera;
}

Eigen::Vector2d Project(const colmap::Camera& camera,
                        const Rigid3d& cam_from_world,
                        const Eigen::Vector3d& point) {
  const Eigen::Vector3d x = cam_from_world * point;
  return camera.WorldToImage(x.hnormalized());
}

Rigid3d SmallPose(std::mt19937* random, double angle, double offset) {
  std::uniform_real_distribution<double> uniform(-1, 1);
  const Eigen::Vector3d axis =
      Eigen::Vector3d(uniform(*random), uniform(*random), uniform(*random))
          .normalized();
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis)),
                 offset * Eigen::Vector3d(uniform(*random), uniform(*random),
                                          uniform(*random)));
}

// A map of one camera, two registered images and points seen by both; a
// 3-camera rig (reference cam0, whose solved cam_from_rig is deliberately not
// the identity) over 4 framesets: frameset 3 has no rig pose, the cam2 image
// of frameset 1 is not used.
struct Scene {
  colmap::Reconstruction map;
  RigDataset dataset;
  RigCalibration calibration;
  int num_registered = 0;    // rig images expected in the model
  int num_observations = 0;  // rig observations expected in the model
};

// The map of Scene; returns its points (ids 1, 2, ...).
std::vector<Eigen::Vector3d> MakeMap(std::mt19937* random, Scene* scene) {
  colmap::Camera map_camera = MakeCamera("PINHOLE", {500, 500, 320, 240});
  map_camera.SetCameraId(1);
  scene->map.AddCamera(map_camera);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < kNumMapPoints; ++k) {
    points.emplace_back(4 * uniform(*random), 3 * uniform(*random),
                        10 + 3 * uniform(*random));
  }
  for (colmap::image_t image_id : {1, 2}) {
    const Rigid3d pose = SmallPose(random, 0.05, 0.5);
    colmap::Image image;
    image.SetImageId(image_id);
    image.SetName("map/" + std::to_string(image_id) + ".png");
    image.SetCameraId(1);
    image.SetQvec(pose.Qvec());
    image.SetTvec(pose.translation);
    std::vector<Eigen::Vector2d> points2D;
    for (const Eigen::Vector3d& point : points) {
      points2D.push_back(Project(map_camera, pose, point));
    }
    image.SetPoints2D(points2D);
    scene->map.AddImage(image);
    scene->map.RegisterImage(image_id);
  }
  for (int k = 0; k < kNumMapPoints; ++k) {
    colmap::Track track;
    track.AddElement(1, k);
    track.AddElement(2, k);
    scene->map.AddPoint3D(points[k], track);
  }
  return points;
}

// The rig, dataset and calibration of Scene.
void MakeRig(const std::vector<Eigen::Vector3d>& points, std::mt19937* random,
             Scene* scene) {
  RigDataset& dataset = scene->dataset;
  RigCalibration& calibration = scene->calibration;
  const std::vector<colmap::Camera> cameras = {
      MakeCamera("OPENCV_FISHEYE",
                 {300, 301, 320.5, 240.5, 0.02, -0.003, 1e-4, 0}),
      MakeCamera("OPENCV", {500, 502, 321, 239, -0.1, 0.01, 1e-4, -1e-4}),
      MakeCamera("SIMPLE_RADIAL", {450, 320, 240, -0.05})};
  for (int c = 0; c < 3; ++c) {
    RigCamera camera;
    camera.name = "cam" + std::to_string(c);
    camera.camera = MakeCamera("SIMPLE_RADIAL", {400, 320, 240, 0});
    dataset.cameras.push_back(camera);
    calibration.cameras.push_back(cameras[c]);
    calibration.cam_from_rig.push_back(SmallPose(random, 0.2, 0.3));
    calibration.camera_calibrated.push_back(true);
  }
  dataset.reference_camera = 0;
  for (int f = 0; f < 4; ++f) {
    dataset.frameset_names.push_back(std::to_string(f) + ".png");
    calibration.rig_from_world.push_back(f == 3 ? std::optional<Rigid3d>()
                                                : SmallPose(random, 0.1, 1.0));
  }
  for (int f = 0; f < 4; ++f) {
    for (int c = 0; c < 3; ++c) {
      RigImage image;
      image.name = "cam" + std::to_string(c) + "/" + dataset.frameset_names[f];
      image.camera_index = c;
      image.frameset_index = f;
      ImageResult result;
      result.localized = true;
      result.used = f != 3 && !(f == 1 && c == 2);
      const Rigid3d cam_from_world =
          f == 3 ? Rigid3d() : calibration.CamFromWorld(c, f);
      for (int k = 0; k < 20; ++k) {
        const int point = (7 * f + 3 * c + k) % kNumMapPoints;
        Correspondence correspondence;
        correspondence.point3D = points[point];
        correspondence.point2D =
            Project(cameras[c], cam_from_world, points[point]);
        correspondence.point3D_id = point + 1;
        image.correspondences.push_back(correspondence);
        result.inlier_mask.push_back(k % 5 != 0);
      }
      // Not a map point id, and a second observation of a point: neither is
      // added to the model.
      Correspondence unknown = image.correspondences[1];
      unknown.point3D_id = 9999;
      image.correspondences.push_back(unknown);
      result.inlier_mask.push_back(true);
      image.correspondences.push_back(image.correspondences[2]);
      result.inlier_mask.push_back(true);
      result.num_inliers = 16;
      result.rms_px = 0.5 + c;
      result.radial_rms_px = 0.25;
      if (result.used) {
        ++scene->num_registered;
        scene->num_observations += 16;
      }
      dataset.images.push_back(image);
      calibration.images.push_back(result);
    }
  }
}

Scene MakeScene() {
  std::mt19937 random(5);
  Scene scene;
  const std::vector<Eigen::Vector3d> points = MakeMap(&random, &scene);
  MakeRig(points, &random, &scene);
  return scene;
}

size_t NumObservations(const colmap::Reconstruction& model) {
  size_t count = 0;
  for (const auto& [image_id, image] : model.Images()) {
    count += image.NumPoints3D();
  }
  return count;
}

// Every registered image of `model` is in exactly one frame, and its pose is
// sensor_from_rig * rig_from_world of that frame.
void ExpectFramesMatchImages(const colmap::Reconstruction& model,
                             const ColmapRigsAndFrames& rigs_frames) {
  std::map<uint32_t, const ColmapRig*> rigs;
  for (const ColmapRig& rig : rigs_frames.rigs) {
    EXPECT_TRUE(rigs.emplace(rig.rig_id, &rig).second) << "duplicate rig id";
  }
  std::set<uint32_t> frame_ids;
  std::map<uint64_t, int> image_frames;
  for (const ColmapFrame& frame : rigs_frames.frames) {
    EXPECT_TRUE(frame_ids.insert(frame.frame_id).second) << "duplicate frame";
    ASSERT_EQ(rigs.count(frame.rig_id), 1u);
    const ColmapRig& rig = *rigs[frame.rig_id];
    for (const ColmapFrameData& data : frame.data) {
      ++image_frames[data.data_id];
      EXPECT_EQ(data.sensor.type, kSensorCamera);
      std::optional<Rigid3d> sensor_from_rig;
      if (data.sensor.id == rig.ref_sensor.id) {
        sensor_from_rig = Rigid3d();
      }
      for (const ColmapRigSensor& sensor : rig.sensors) {
        if (sensor.sensor.id == data.sensor.id) {
          sensor_from_rig = sensor.sensor_from_rig;
        }
      }
      ASSERT_TRUE(sensor_from_rig)
          << "camera " << data.sensor.id << " is not a posed sensor of its rig";
      const colmap::Image& image = model.Image(data.data_id);
      EXPECT_EQ(image.CameraId(), data.sensor.id);
      const Rigid3d expected = *sensor_from_rig * frame.rig_from_world;
      const Rigid3d actual = Rigid3d::FromQvecTvec(image.Qvec(), image.Tvec());
      EXPECT_LT((expected.ToMatrix() - actual.ToMatrix()).norm(), 1e-9)
          << image.Name();
    }
  }
  for (const colmap::image_t image_id : model.RegImageIds()) {
    EXPECT_EQ(image_frames[image_id], 1) << model.Image(image_id).Name();
  }
  EXPECT_EQ(image_frames.size(), model.NumRegImages());
}

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

// The files of the output folder, and nothing left next to it.
void ExpectOutputFiles(const testing::ScopedTempDir& dir,
                       const std::string& output,
                       const std::string& extension) {
  std::set<std::string> files;
  for (const auto& entry : fs::directory_iterator(output)) {
    files.insert(entry.path().filename().string());
  }
  EXPECT_EQ(files,
            (std::set<std::string>{"cameras" + extension, "images" + extension,
                                   "points3D" + extension, "rigs" + extension,
                                   "frames" + extension, kRigConfigFile,
                                   kRigBundleAdjusterConfigFile, kCamchainFile,
                                   kSummaryFile, kCorrespondencesFile}));
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
  EXPECT_EQ(json["timings_s"]["localize"], 1.5);
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
  summary.timings_s.emplace_back("localize", 1.5);
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

}  // namespace
}  // namespace rig_calibrator
