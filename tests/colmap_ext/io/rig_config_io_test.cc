#include "colmap_ext/io/rig_config_io.h"

#include <gtest/gtest.h>

#include <boost/property_tree/json_parser.hpp>
#include <boost/property_tree/ptree.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "tests/testing.h"

namespace rig_calibrator {
namespace rig_config_io_test {

colmap::Camera MakeCamera(const std::string& model,
                          const std::vector<double>& params,
                          colmap::camera_t camera_id) {
  colmap::Camera camera;
  camera.SetModelIdFromName(model);
  camera.SetWidth(640);
  camera.SetHeight(480);
  camera.SetParams(params);
  camera.SetCameraId(camera_id);
  return camera;
}

// A 3-camera rig with the reference in the middle; cam2 is not calibrated.
RigDescription MakeRig() {
  std::mt19937 random(11);
  std::normal_distribution<double> normal;
  RigDescription rig;
  rig.reference_camera = 1;
  rig.cameras.resize(3);
  for (int c = 0; c < 3; ++c) {
    rig.cameras[c].name = "cam" + std::to_string(c);
    rig.cameras[c].image_prefix = "rig/cam" + std::to_string(c) + "/";
    rig.cameras[c].camera = MakeCamera(
        "OPENCV_FISHEYE",
        {300.0 + c, 301, 320.5, 240.25, 0.01 * c, -1e-3, 1e-4, 1e-17}, 7 + c);
    rig.cameras[c].cam_from_rig =
        c == rig.reference_camera
            ? Rigid3d()
            : Rigid3d(Eigen::Quaterniond(normal(random), normal(random),
                                         normal(random), normal(random)),
                      Eigen::Vector3d(normal(random), normal(random),
                                      normal(random)));
  }
  rig.cameras[2].camera.reset();
  rig.cameras[2].cam_from_rig.reset();
  return rig;
}

TEST(RigConfigIo, RigConfigJsonRoundTrip) {
  const RigDescription rig = MakeRig();
  testing::ScopedTempDir dir;
  const std::string path = dir.File("rig_config.json");
  std::string error;
  ASSERT_TRUE(WriteRigConfigJson(path, rig, &error)) << error;

  // The fields of COLMAP's rig_configurator, with exact numbers.
  std::ifstream file(path);
  const nlohmann::json json = nlohmann::json::parse(file);
  ASSERT_EQ(json.size(), 1u);
  const nlohmann::json& cameras = json[0]["cameras"];
  ASSERT_EQ(cameras.size(), 3u);
  EXPECT_EQ(cameras[1]["image_prefix"], "rig/cam1/");
  EXPECT_EQ(cameras[1]["ref_sensor"], true);
  EXPECT_FALSE(cameras[1].contains("cam_from_rig_rotation"));
  EXPECT_FALSE(cameras[0].contains("ref_sensor"));
  EXPECT_EQ(cameras[0]["cam_from_rig_rotation"][0].get<double>(),
            rig.cameras[0].cam_from_rig->rotation.w());
  EXPECT_EQ(cameras[0]["cam_from_rig_translation"][2].get<double>(),
            rig.cameras[0].cam_from_rig->translation.z());
  EXPECT_EQ(cameras[0]["camera_model_name"], "OPENCV_FISHEYE");
  EXPECT_EQ(cameras[0]["camera_params"][7].get<double>(), 1e-17);
  EXPECT_FALSE(cameras[2].contains("cam_from_rig_rotation"));
  EXPECT_FALSE(cameras[2].contains("camera_model_name"));

  std::vector<RigDescription> read;
  ASSERT_TRUE(ReadRigConfigJson(path, &read, &error)) << error;
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].reference_camera, 1);
  ASSERT_EQ(read[0].cameras.size(), 3u);
  for (int c = 0; c < 2; ++c) {
    SCOPED_TRACE(c);
    const RigDescriptionCamera& a = rig.cameras[c];
    const RigDescriptionCamera& b = read[0].cameras[c];
    EXPECT_EQ(b.name, "rig/cam" + std::to_string(c));
    EXPECT_EQ(b.image_prefix, a.image_prefix);
    ASSERT_TRUE(b.camera && b.cam_from_rig);
    EXPECT_EQ(b.camera->ModelName(), "OPENCV_FISHEYE");
    EXPECT_EQ(b.camera->Params(), a.camera->Params());
    EXPECT_LT((b.cam_from_rig->ToMatrix() - a.cam_from_rig->ToMatrix()).norm(),
              1e-15);
  }
  EXPECT_FALSE(read[0].cameras[2].camera);
  EXPECT_FALSE(read[0].cameras[2].cam_from_rig);
}

TEST(RigConfigIo, ReadsColmapsDocumentedExampleAndRejectsBadFiles) {
  testing::ScopedTempDir dir;
  const std::string path = dir.File("rig.json");
  auto read = [&](const std::string& text, std::vector<RigDescription>* rigs,
                  std::string* error) {
    std::ofstream(path) << text;
    return ReadRigConfigJson(path, rigs, error);
  };
  std::vector<RigDescription> rigs;
  std::string error;
  ASSERT_TRUE(read(R"([{"cameras": [
      {"image_prefix": "rig1/camera1/", "ref_sensor": true},
      {"image_prefix": "rig1/camera2/",
       "cam_from_rig_rotation": [0.7071067811865475, 0.0, 0.7071067811865476, 0.0],
       "cam_from_rig_translation": [0, 0, 0]}]},
     {"cameras": [{"image_prefix": "rig2/a/", "ref_sensor": true},
                  {"image_prefix": "rig2/b/"}]}])",
                   &rigs, &error))
      << error;
  ASSERT_EQ(rigs.size(), 2u);
  EXPECT_EQ(rigs[0].reference_camera, 0);
  EXPECT_NEAR(rigs[0].cameras[1].cam_from_rig->rotation.y(), 0.70710678, 1e-8);
  EXPECT_FALSE(rigs[1].cameras[1].cam_from_rig);

  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"([{"cameras": [{"image_prefix": "a/"}]}])", "no camera with"},
      {R"([{"cameras": [{"image_prefix": "a/", "ref_sensor": true},
                       {"image_prefix": "b/", "ref_sensor": true}]}])",
       "more than one ref_sensor"},
      {R"([{"cameras": [{"image_prefix": "a/", "ref_sensor": true,
                         "cam_from_rig_rotation": [1, 0, 0, 0],
                         "cam_from_rig_translation": [0, 0, 0]}]}])",
       "must not have a pose"},
      {R"([{"cameras": [{"image_prefix": "a/", "ref_sensor": true},
                       {"image_prefix": "b/",
                        "cam_from_rig_rotation": [1, 0, 0, 0]}]}])",
       "must be given together"},
      {R"([{"cameras": [{"image_prefix": "a/", "ref_sensor": true,
                         "camera_model_name": "PINHOLE",
                         "camera_params": [1, 2, 3]}]}])",
       "PINHOLE takes 4 camera_params (fx, fy, cx, cy), not 3"},
      {R"([{"cameras": [{"image_prefix": "a/", "ref_sensor": true,
                         "camera_model_name": "KB4",
                         "camera_params": [1, 2, 3]}]}])",
       "unknown camera_model_name"},
      {R"([{"cameras": [{"ref_sensor": true}]}])", "has no image_prefix"},
      {R"([{"cameras": [)", "not valid JSON"},
  };
  for (const auto& [text, message] : bad) {
    EXPECT_FALSE(read(text, &rigs, &error)) << text;
    EXPECT_NE(error.find(message), std::string::npos) << error;
  }
}

TEST(RigConfigIo, RigBundleAdjusterConfigIsWhatColmap38Reads) {
  const RigDescription rig = MakeRig();
  testing::ScopedTempDir dir;
  const std::string path = dir.File("rig_ba.json");
  std::string error;
  ASSERT_TRUE(WriteRigBundleAdjusterConfig(path, rig, &error)) << error;

  // Parsed as COLMAP 3.8's ReadCameraRigConfig does (boost property tree).
  boost::property_tree::ptree tree;
  boost::property_tree::read_json(path, tree);
  ASSERT_EQ(tree.size(), 1u);
  const boost::property_tree::ptree& rig_node = tree.begin()->second;
  EXPECT_EQ(rig_node.get<int>("ref_camera_id"), 8);
  std::vector<int> camera_ids;
  for (const auto& camera : rig_node.get_child("cameras")) {
    const int camera_id = camera.second.get<int>("camera_id");
    camera_ids.push_back(camera_id);
    const RigDescriptionCamera& expected = rig.cameras[camera_id - 7];
    EXPECT_EQ(camera.second.get<std::string>("image_prefix"),
              expected.image_prefix);
    std::vector<double> qvec;
    for (const auto& value : camera.second.get_child("rel_qvec")) {
      qvec.push_back(value.second.get_value<double>());
    }
    std::vector<double> tvec;
    for (const auto& value : camera.second.get_child("rel_tvec")) {
      tvec.push_back(value.second.get_value<double>());
    }
    ASSERT_EQ(qvec.size(), 4u);
    ASSERT_EQ(tvec.size(), 3u);
    EXPECT_NEAR(qvec[0], expected.cam_from_rig->rotation.w(), 1e-15);
    EXPECT_NEAR(qvec[3], expected.cam_from_rig->rotation.z(), 1e-15);
    EXPECT_NEAR(tvec[1], expected.cam_from_rig->translation.y(), 1e-15);
  }
  // The uncalibrated camera is left out.
  EXPECT_EQ(camera_ids, (std::vector<int>{7, 8}));

  RigDescription no_reference = rig;
  no_reference.reference_camera = 2;
  EXPECT_FALSE(WriteRigBundleAdjusterConfig(path, no_reference, &error));
}

TEST(RigConfigIo, PredictsColmap38SnapshotGrouping) {
  RigDescription rig = MakeRig();
  colmap::Reconstruction model;
  colmap::Camera map_camera = MakeCamera("PINHOLE", {500, 500, 320, 240}, 1);
  model.AddCamera(map_camera);
  for (const colmap::camera_t camera_id : {7, 8, 9}) {
    model.AddCamera(MakeCamera("PINHOLE", {500, 500, 320, 240}, camera_id));
  }
  colmap::image_t next_id = 1;
  auto add = [&](const std::string& name, colmap::camera_t camera_id) {
    colmap::Image image;
    image.SetImageId(next_id++);
    image.SetName(name);
    image.SetCameraId(camera_id);
    model.AddImage(image);
    model.RegisterImage(image.ImageId());
  };
  add("rig/cam0/1.png", 7);
  add("rig/cam1/1.png", 8);
  add("rig/cam1/2.png", 8);
  add("rig/cam0/3.png", 7);  // no reference image: not a snapshot
  add("map/a.png", 1);
  RigBundleAdjusterGrouping grouping =
      PredictRigBundleAdjusterGrouping(rig, model);
  EXPECT_EQ(grouping.num_snapshots, 2);
  EXPECT_EQ(grouping.num_multi_image_snapshots, 1);
  EXPECT_TRUE(grouping.problems.empty());

  // A map image whose name contains a rig prefix lands in a snapshot: COLMAP
  // 3.8 would abort on it.
  add("old/rig/cam1/2.png", 1);
  grouping = PredictRigBundleAdjusterGrouping(rig, model);
  ASSERT_EQ(grouping.problems.size(), 1u);
  EXPECT_NE(grouping.problems[0].find("old/rig/cam1/2.png (camera 1, not a "
                                      "rig camera)"),
            std::string::npos)
      << grouping.problems[0];
}

}  // namespace rig_config_io_test
}  // namespace rig_calibrator
