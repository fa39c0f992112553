// The scene of the model writer tests: a small map and a calibrated
// 3-camera rig whose model the writer builds, and the check that frames and
// image poses agree.
#pragma once

#include <colmap/base/reconstruction.h>
#include <gtest/gtest.h>

#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "colmap_ext/io/rigs_frames_io.h"
#include "src/geometry/rigid3d.h"
#include "src/rig/rig_dataset.h"

namespace rig_calibrator {
namespace testing {

inline constexpr int kNumMapPoints = 60;

inline colmap::Camera MakeCamera(const std::string& model,
                                 const std::vector<double>& params) {
  colmap::Camera camera;
  camera.SetModelIdFromName(model);
  camera.SetWidth(640);
  camera.SetHeight(480);
  camera.SetParams(params);
  return camera;
}

inline Eigen::Vector2d Project(const colmap::Camera& camera,
                               const Rigid3d& cam_from_world,
                               const Eigen::Vector3d& point) {
  const Eigen::Vector3d x = cam_from_world * point;
  return camera.WorldToImage(x.hnormalized());
}

inline Rigid3d SmallPose(std::mt19937* random, double angle, double offset) {
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
inline std::vector<Eigen::Vector3d> MakeMap(std::mt19937* random,
                                            Scene* scene) {
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
inline void MakeRig(const std::vector<Eigen::Vector3d>& points,
                    std::mt19937* random, Scene* scene) {
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

inline Scene MakeScene() {
  std::mt19937 random(5);
  Scene scene;
  const std::vector<Eigen::Vector3d> points = MakeMap(&random, &scene);
  MakeRig(points, &random, &scene);
  return scene;
}

inline size_t NumObservations(const colmap::Reconstruction& model) {
  size_t count = 0;
  for (const auto& [image_id, image] : model.Images()) {
    count += image.NumPoints3D();
  }
  return count;
}

// Every registered image of `model` is in exactly one frame, and its pose is
// sensor_from_rig * rig_from_world of that frame.
inline void ExpectFramesMatchImages(const colmap::Reconstruction& model,
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

}  // namespace testing
}  // namespace rig_calibrator
