#include "tests/fuzz/fuzz_templates.h"

#include <colmap/base/database.h>

namespace rig_calibrator {
namespace fuzz {

colmap::Reconstruction TemplateModel() {
  colmap::Reconstruction model;
  for (colmap::camera_t camera_id : {1, 2}) {
    colmap::Camera camera;
    camera.InitializeWithName(camera_id == 1 ? "SIMPLE_RADIAL" : "OPENCV", 500,
                              640, 480);
    camera.SetCameraId(camera_id);
    model.AddCamera(camera);
  }
  for (colmap::image_t image_id : {1, 2}) {
    colmap::Image image;
    image.SetImageId(image_id);
    image.SetCameraId(image_id);
    image.SetName(image_id == 1 ? "cam0/0001.png" : "cam1/0001.png");
    image.SetQvec(Eigen::Vector4d(1, 0, 0, 0));
    image.SetTvec(Eigen::Vector3d(0.1 * image_id, 0, 0));
    image.SetPoints2D({Eigen::Vector2d(100.5, 200.25),
                       Eigen::Vector2d(320, 240), Eigen::Vector2d(10, 20)});
    model.AddImage(image);
    model.RegisterImage(image_id);
  }
  for (colmap::point2D_t point2D_idx : {0, 1}) {
    colmap::Track track;
    track.AddElement(1, point2D_idx);
    track.AddElement(2, point2D_idx);
    model.AddPoint3D(Eigen::Vector3d(0.5 * point2D_idx, 0.25, 4), track);
  }
  return model;
}

ColmapRigsAndFrames TemplateRigsAndFrames() {
  ColmapRigsAndFrames rigs_frames;
  ColmapRig rig;
  rig.rig_id = 1;
  rig.ref_sensor.id = 1;
  ColmapRigSensor sensor;
  sensor.sensor.id = 2;
  sensor.sensor_from_rig =
      Rigid3d(Eigen::Quaterniond(1, 0, 0, 0), Eigen::Vector3d(0.1, 0, 0));
  rig.sensors.push_back(sensor);
  rigs_frames.rigs.push_back(rig);
  for (uint32_t frame_id : {1, 2}) {
    ColmapFrame frame;
    frame.frame_id = frame_id;
    frame.rig_id = 1;
    frame.rig_from_world = Rigid3d(Eigen::Quaterniond(1, 0, 0, 0),
                                   Eigen::Vector3d(0, 0, frame_id));
    for (uint32_t camera_id : {1, 2}) {
      ColmapFrameData data;
      data.sensor.id = camera_id;
      data.data_id = 2 * (frame_id - 1) + camera_id;
      frame.data.push_back(data);
    }
    rigs_frames.frames.push_back(frame);
  }
  return rigs_frames;
}

RigDescription TemplateRig() {
  RigDescription rig;
  for (int c = 0; c < 2; ++c) {
    RigDescriptionCamera camera;
    camera.name = "cam" + std::to_string(c);
    camera.image_prefix = camera.name + "/";
    colmap::Camera intrinsics;
    intrinsics.InitializeWithName(c == 0 ? "OPENCV" : "OPENCV_FISHEYE", 500,
                                  640, 480);
    intrinsics.SetCameraId(c + 1);
    camera.camera = intrinsics;
    camera.cam_from_rig =
        Rigid3d(Eigen::Quaterniond(1, 0, 0, 0), Eigen::Vector3d(0.1 * c, 0, 0));
    rig.cameras.push_back(camera);
  }
  return rig;
}

std::vector<ImageCorrespondences> TemplateCorrespondences() {
  std::vector<ImageCorrespondences> images(2);
  for (int i = 0; i < 2; ++i) {
    images[i].image_name = "cam" + std::to_string(i) + "/0001 a.png";
    images[i].width = 640;
    images[i].height = 480;
    for (int k = 0; k < 2; ++k) {
      Correspondence correspondence;
      correspondence.point2D = Eigen::Vector2d(100.5 + k, 200.25);
      correspondence.point3D = Eigen::Vector3d(0.5, -0.25 * k, 4);
      correspondence.point3D_id = k == 0 ? 7 : -1;
      images[i].correspondences.push_back(correspondence);
    }
  }
  return images;
}

void WriteTemplateDatabase(const std::string& path) {
  colmap::Database database(path);
  const char* names[3] = {"map/a.png", "cam0/0001.png", "cam1/0001.png"};
  for (int i = 0; i < 3; ++i) {
    colmap::Camera camera;
    camera.InitializeWithName(i == 0 ? "SIMPLE_RADIAL" : "OPENCV_FISHEYE", 300,
                              64, 48);
    const colmap::camera_t camera_id = database.WriteCamera(camera);
    colmap::Image image;
    image.SetName(names[i]);
    image.SetCameraId(camera_id);
    const colmap::image_t image_id = database.WriteImage(image);
    colmap::FeatureKeypoints keypoints;
    for (int k = 0; k < 3; ++k) {
      keypoints.emplace_back(10.5f * k + i, 3.25f * k, 1.5f + k, 0.1f * k);
    }
    database.WriteKeypoints(image_id, keypoints);
    colmap::FeatureDescriptors descriptors(3, 128);
    for (int k = 0; k < descriptors.size(); ++k) {
      descriptors.data()[k] = static_cast<uint8_t>(k * 7 + i);
    }
    database.WriteDescriptors(image_id, descriptors);
  }
  colmap::TwoViewGeometry geometry;
  geometry.config = colmap::TwoViewGeometry::UNCALIBRATED;
  geometry.inlier_matches = {{0, 2}, {1, 1}};
  database.WriteTwoViewGeometry(1, 2, geometry);
}

}  // namespace fuzz
}  // namespace rig_calibrator
