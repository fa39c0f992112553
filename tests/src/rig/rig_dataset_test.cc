// ValidateCalibration: a calibration shaped like its dataset, with finite
// poses and inlier masks of the right length; every other shape fails with a
// message naming what is wrong. ValidateDataset: frameset times empty or one
// finite, strictly increasing time per frameset.
#include "src/rig/rig_dataset.h"

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <tuple>
#include <vector>

namespace rig_calibrator {
namespace rig_dataset_test {

// Two cameras, two framesets, three images (frameset "f1" misses cam1), and
// the calibration that matches it.
class ValidateCalibrationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const std::string name : {"cam0", "cam1"}) {
      RigCamera camera;
      camera.name = name;
      camera.camera.InitializeWithName("PINHOLE", 500, 640, 480);
      dataset_.cameras.push_back(camera);
      calibration_.cameras.push_back(camera.camera);
      calibration_.cam_from_rig.emplace_back();
      calibration_.camera_calibrated.push_back(true);
    }
    dataset_.frameset_names = {"f0", "f1"};
    calibration_.rig_from_world = {Rigid3d(), std::nullopt};
    for (const auto& [name, camera, frameset] :
         std::vector<std::tuple<std::string, int, int>>{
             {"cam0/f0.png", 0, 0},
             {"cam1/f0.png", 1, 0},
             {"cam0/f1.png", 0, 1}}) {
      RigImage image;
      image.name = name;
      image.camera_index = camera;
      image.frameset_index = frameset;
      image.correspondences.resize(3);
      dataset_.images.push_back(image);
      ImageResult result;
      result.inlier_mask = {1, 0, 1};
      calibration_.images.push_back(result);
    }
    calibration_.images[2].inlier_mask.clear();  // empty: no mask yet
  }

  // Expects the modified calibration to fail with `expected` in the error.
  void ExpectFails(const std::function<void(RigCalibration*)>& modify,
                   const std::string& expected) {
    RigCalibration calibration = calibration_;
    modify(&calibration);
    std::string error;
    EXPECT_FALSE(ValidateCalibration(dataset_, calibration, &error));
    EXPECT_NE(error.find(expected), std::string::npos)
        << "expected '" << expected << "' in: " << error;
  }

  RigDataset dataset_;
  RigCalibration calibration_;
};

TEST_F(ValidateCalibrationTest, AcceptsAMatchingCalibration) {
  std::string error;
  EXPECT_TRUE(ValidateCalibration(dataset_, calibration_, &error)) << error;
}

TEST_F(ValidateCalibrationTest, RejectsAnInvalidDataset) {
  dataset_.images[1].frameset_index = 2;
  std::string error;
  EXPECT_FALSE(ValidateCalibration(dataset_, calibration_, &error));
  EXPECT_NE(error.find("cam1/f0.png"), std::string::npos) << error;
}

TEST_F(ValidateCalibrationTest, RejectsEveryMissingOrExtraEntry) {
  const std::string mismatch = "the calibration does not match the dataset";
  ExpectFails([](RigCalibration* c) { c->cameras.pop_back(); }, mismatch);
  ExpectFails([](RigCalibration* c) { c->cam_from_rig.emplace_back(); },
              mismatch);
  ExpectFails([](RigCalibration* c) { c->camera_calibrated.pop_back(); },
              mismatch);
  ExpectFails([](RigCalibration* c) { c->rig_from_world.pop_back(); },
              mismatch);
  ExpectFails([](RigCalibration* c) { c->images.emplace_back(); }, mismatch);
}

TEST_F(ValidateCalibrationTest, RejectsNonFinitePoses) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  ExpectFails(
      [&](RigCalibration* c) { c->cam_from_rig[1].translation.x() = inf; },
      "the camera cam1 has a non-finite cam_from_rig");
  ExpectFails([&](RigCalibration* c) { c->cam_from_rig[0].rotation.w() = nan; },
              "the camera cam0 has a non-finite cam_from_rig");
  ExpectFails(
      [&](RigCalibration* c) { c->rig_from_world[0]->translation.z() = nan; },
      "the frameset f0 has a non-finite rig_from_world");
  ExpectFails(
      [&](RigCalibration* c) {
        c->rig_from_world[1] = Rigid3d();
        c->rig_from_world[1]->rotation.x() = inf;
      },
      "the frameset f1 has a non-finite rig_from_world");
}

TEST_F(ValidateCalibrationTest, RejectsInlierMasksOfTheWrongLength) {
  ExpectFails([](RigCalibration* c) { c->images[1].inlier_mask.push_back(1); },
              "the image cam1/f0.png has 4 inlier flags for 3 correspondences");
  ExpectFails([](RigCalibration* c) { c->images[2].inlier_mask = {1}; },
              "the image cam0/f1.png has 1 inlier flags for 3");
}

// Frameset times are optional; when given, one finite time per frameset,
// strictly increasing; the error names the count or the frameset.
TEST_F(ValidateCalibrationTest, FramesetTimesAreEmptyOrOnePerFramesetIncreasing) {
  std::string error;
  EXPECT_TRUE(ValidateDataset(dataset_, &error)) << error;
  dataset_.frameset_times_s = {0.0, 0.2};
  EXPECT_TRUE(ValidateDataset(dataset_, &error)) << error;
  const auto expect_fails = [&](const std::vector<double>& times,
                                const std::string& expected) {
    RigDataset dataset = dataset_;
    dataset.frameset_times_s = times;
    std::string message;
    EXPECT_FALSE(ValidateDataset(dataset, &message));
    EXPECT_NE(message.find(expected), std::string::npos)
        << "expected '" << expected << "' in: " << message;
  };
  expect_fails({0.0}, "the dataset has 1 frameset times for 2 framesets");
  expect_fails({0.0, 0.2, 0.4}, "3 frameset times for 2 framesets");
  expect_fails({0.2, 0.2}, "the time of frameset f1 is not finite or not after");
  expect_fails({0.2, 0.1}, "the time of frameset f1");
  expect_fails({std::numeric_limits<double>::quiet_NaN(), 0.2},
               "the time of frameset f0 is not finite");
  expect_fails({0.0, std::numeric_limits<double>::infinity()},
               "the time of frameset f1");
}

}  // namespace rig_dataset_test
}  // namespace rig_calibrator
