#include "src/evaluation/evaluation.h"

#include <colmap/util/math.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace evaluation_test {

// cam_from_rig of a camera turned by `rotation` (applied in the camera
// frame) and moved by `center_offset` (in the rig frame).
Rigid3d Perturb(const Rigid3d& cam_from_rig, const Eigen::Matrix3d& rotation,
                const Eigen::Vector3d& center_offset) {
  const Eigen::Matrix3d new_rotation = rotation * cam_from_rig.RotationMatrix();
  const Eigen::Vector3d new_center = cam_from_rig.Center() + center_offset;
  return Rigid3d(new_rotation, -new_rotation * new_center);
}

// The estimate expressed in another rig frame: cam_from_rigest =
// cam_from_rig * rig_from_rigest, with centers scaled about the origin.
std::vector<Rigid3d> ChangeRigFrame(const std::vector<Rigid3d>& cam_from_rig,
                                    const Rigid3d& rig_from_rigest,
                                    double scale) {
  std::vector<Rigid3d> result;
  for (const Rigid3d& pose : cam_from_rig) {
    Rigid3d scaled = pose;
    scaled.translation *= scale;
    Rigid3d scaled_rig_from_rigest = rig_from_rigest;
    scaled_rig_from_rigest.translation *= scale;
    result.push_back(scaled * scaled_rig_from_rigest);
  }
  return result;
}

colmap::Camera PinholeCamera(double f, double cx, double cy) {
  colmap::Camera camera;
  camera.SetModelIdFromName("PINHOLE");
  camera.SetWidth(640);
  camera.SetHeight(480);
  camera.SetParams({f, f, cx, cy});
  return camera;
}

void ScaleFocal(double factor, colmap::Camera* camera) {
  for (const size_t idx : camera->FocalLengthIdxs()) {
    camera->Params()[idx] *= factor;
  }
}

TEST(Evaluation, TruthAgainstItselfIsZero) {
  for (const RigPreset preset : AllRigPresets()) {
    SCOPED_TRACE(RigPresetName(preset));
    const RigGroundTruth truth = MakeRigPreset(preset);
    for (const bool align_scale : {false, true}) {
      const CalibrationError error =
          CompareCalibrations(truth.cameras, truth.cam_from_rig, truth.cameras,
                              truth.cam_from_rig, align_scale);
      ASSERT_TRUE(error.ok()) << error.error;
      ASSERT_EQ(error.cameras.size(), truth.cameras.size());
      EXPECT_NEAR(error.scale, 1.0, 1e-12);
      for (const CameraError& camera : error.cameras) {
        EXPECT_LT(camera.rotation_deg, 1e-9);
        EXPECT_LT(camera.center_error, 1e-12);
        EXPECT_EQ(camera.focal_error_percent, 0.0);
        EXPECT_EQ(camera.principal_point_error_px, 0.0);
        EXPECT_LT(camera.max_projection_diff_px, 1e-9);
        // The whole image is within every preset's field of view.
        EXPECT_EQ(camera.num_projection_samples, 20 * 15);
        EXPECT_EQ(camera.num_projection_skipped, 0);
      }
    }
  }
}

TEST(Evaluation, UnprojectPixelIsExactIncludingFisheyeCorners) {
  for (const RigPreset preset : AllRigPresets()) {
    for (const colmap::Camera& camera : MakeRigPreset(preset).cameras) {
      for (const Eigen::Vector2d& pixel :
           {Eigen::Vector2d(0, 0), Eigen::Vector2d(camera.Width(), 0),
            Eigen::Vector2d(0.5 * camera.Width(), 0.5 * camera.Height()),
            Eigen::Vector2d(camera.Width(), camera.Height())}) {
        Eigen::Vector2d normalized;
        ASSERT_TRUE(UnprojectPixel(camera, pixel, &normalized))
            << camera.ModelName() << " " << pixel.transpose();
        EXPECT_LT((camera.WorldToImage(normalized) - pixel).norm(), 1e-10);
      }
    }
  }
}

// Perturbing one non-reference camera, with the rigs aligned on the
// reference camera, gives exactly the perturbation back.
TEST(Evaluation, KnownPerturbationIsMeasuredBack) {
  const RigGroundTruth truth = MakeRigPreset(RigPreset::kRing5);
  std::vector<colmap::Camera> cameras = truth.cameras;
  std::vector<Rigid3d> cam_from_rig = truth.cam_from_rig;
  const int k = 2;
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -1.0, 0.5).normalized();
  cam_from_rig[k] =
      Perturb(cam_from_rig[k],
              Eigen::AngleAxisd(colmap::DegToRad(0.1), axis).toRotationMatrix(),
              0.003 * Eigen::Vector3d(0.6, 0.0, 0.8));
  ScaleFocal(1.01, &cameras[k]);
  cameras[k].SetPrincipalPointX(cameras[k].PrincipalPointX() + 2);

  CompareOptions options;
  options.alignment = RigAlignment::kReferenceCamera;
  const CalibrationError error = CompareCalibrations(
      truth.cameras, truth.cam_from_rig, cameras, cam_from_rig, options);
  ASSERT_TRUE(error.ok());
  for (int i = 0; i < 5; ++i) {
    SCOPED_TRACE(i);
    const CameraError& camera = error.cameras[i];
    if (i == k) {
      EXPECT_NEAR(camera.rotation_deg, 0.1, 1e-9);
      EXPECT_NEAR(camera.center_error, 0.003, 1e-12);
      EXPECT_NEAR(camera.focal_error_percent, 1.0, 1e-9);
      EXPECT_NEAR(camera.principal_point_error_px, 2.0, 1e-12);
      EXPECT_GT(camera.mean_projection_diff_px, 1.0);
    } else {
      EXPECT_LT(camera.rotation_deg, 1e-9);
      EXPECT_LT(camera.center_error, 1e-12);
      EXPECT_EQ(camera.focal_error_percent, 0.0);
      EXPECT_EQ(camera.principal_point_error_px, 0.0);
      EXPECT_LT(camera.max_projection_diff_px, 1e-9);
    }
  }
  EXPECT_NEAR(error.MaxRotationDeg(), 0.1, 1e-9);
  EXPECT_NEAR(error.MaxCenterError(), 0.003, 1e-12);
}

// With all-camera alignment, a rotation theta of one of N cameras about axis
// a moves the chordal mean by phi = atan2(sin theta, N - 1 + cos theta) about
// a: (N - 1) I + R(theta) has the polar factor R(phi).
TEST(Evaluation, AllCameraAlignmentIsTheChordalMean) {
  const RigGroundTruth truth = MakeRigPreset(RigPreset::kRing5);
  std::vector<Rigid3d> cam_from_rig = truth.cam_from_rig;
  const int k = 3;
  const double theta = colmap::DegToRad(0.1);
  const Eigen::Vector3d axis = Eigen::Vector3d(1.0, 0.2, -0.4).normalized();
  cam_from_rig[k] = Perturb(cam_from_rig[k],
                            Eigen::AngleAxisd(theta, axis).toRotationMatrix(),
                            Eigen::Vector3d::Zero());
  const CalibrationError error = CompareCalibrations(
      truth.cameras, truth.cam_from_rig, truth.cameras, cam_from_rig, false);
  ASSERT_TRUE(error.ok());
  const double phi = std::atan2(std::sin(theta), 4 + std::cos(theta));
  // The alignment rotation in the rig frame is R(phi) about the perturbation
  // axis seen from the rig: R_k^T a.
  const Eigen::Vector3d rig_axis =
      truth.cam_from_rig[k].RotationMatrix().transpose() * axis;
  const Eigen::Matrix3d alignment =
      Eigen::AngleAxisd(phi, rig_axis).toRotationMatrix();
  Eigen::Vector3d mean_center = Eigen::Vector3d::Zero();
  for (const Rigid3d& pose : truth.cam_from_rig) {
    mean_center += pose.Center() / 5;
  }
  for (int i = 0; i < 5; ++i) {
    SCOPED_TRACE(i);
    EXPECT_NEAR(error.cameras[i].rotation_deg,
                colmap::RadToDeg(i == k ? theta - phi : phi), 1e-9);
    const Eigen::Vector3d offset = truth.cam_from_rig[i].Center() - mean_center;
    EXPECT_NEAR(error.cameras[i].center_error,
                (alignment * offset - offset).norm(), 1e-12);
  }
}

// A moved camera center shifts the centroid by offset / N.
TEST(Evaluation, AllCameraAlignmentMatchesCentroids) {
  const RigGroundTruth truth = MakeRigPreset(RigPreset::kCarSurround4);
  std::vector<Rigid3d> cam_from_rig = truth.cam_from_rig;
  cam_from_rig[1] = Perturb(cam_from_rig[1], Eigen::Matrix3d::Identity(),
                            Eigen::Vector3d(0.0, 0.004, 0.0));
  const CalibrationError error = CompareCalibrations(
      truth.cameras, truth.cam_from_rig, truth.cameras, cam_from_rig, false);
  ASSERT_TRUE(error.ok());
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(error.cameras[i].center_error, i == 1 ? 0.003 : 0.001, 1e-12);
    EXPECT_LT(error.cameras[i].rotation_deg, 1e-9);
  }
}

// Every preset's rig expressed in another rig frame, scaled by `scale`:
// both alignments remove the change (with scale alignment when scale != 1);
// without scale alignment a scaled rig stays off.
void ExpectRigFrameChangeRemoved(const Rigid3d& rig_from_rigest, double scale) {
  const bool align_scale = scale != 1.0;
  for (const RigPreset preset : AllRigPresets()) {
    SCOPED_TRACE(RigPresetName(preset));
    const RigGroundTruth truth = MakeRigPreset(preset);
    const std::vector<Rigid3d> moved =
        ChangeRigFrame(truth.cam_from_rig, rig_from_rigest, scale);
    // The change is not a no-op.
    EXPECT_GT(RotationDifferenceDeg(moved[0].rotation,
                                    truth.cam_from_rig[0].rotation),
              20);
    for (const RigAlignment alignment :
         {RigAlignment::kAllCameras, RigAlignment::kReferenceCamera}) {
      CompareOptions options;
      options.alignment = alignment;
      options.align_scale = align_scale;
      const CalibrationError error = CompareCalibrations(
          truth.cameras, truth.cam_from_rig, truth.cameras, moved, options);
      ASSERT_TRUE(error.ok());
      EXPECT_NEAR(error.scale, 1 / scale, 1e-12);
      EXPECT_LT(error.MaxRotationDeg(), 1e-9);
      EXPECT_LT(error.MaxCenterError(), 1e-12);
      if (align_scale) {
        options.align_scale = false;
        const CalibrationError unscaled = CompareCalibrations(
            truth.cameras, truth.cam_from_rig, truth.cameras, moved, options);
        EXPECT_EQ(unscaled.scale, 1.0);
        EXPECT_GT(unscaled.MaxCenterError(), 0.03);
      }
    }
  }
}

TEST(Evaluation, WholeRigTransformIsRemoved) {
  ExpectRigFrameChangeRemoved(
      Rigid3d(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())
                  .toRotationMatrix(),
              Eigen::Vector3d(0.5, -1.2, 2.0)),
      1.0);
}

TEST(Evaluation, GlobalScaleIsRemovedWithScaleAlignment) {
  ExpectRigFrameChangeRemoved(
      Rigid3d(Eigen::AngleAxisd(-0.4, Eigen::Vector3d(0, 1, 1).normalized())
                  .toRotationMatrix(),
              Eigen::Vector3d(-0.3, 0.1, 0.9)),
      1.7);
}

// Scaling f by 1.01 moves every pixel radially away from the principal
// point: the difference is 0.01 * r at distance r from it, for any model.
TEST(Evaluation, ProjectionDifferenceOfAFocalChangeIsProportionalToRadius) {
  std::vector<colmap::Camera> references = {PinholeCamera(400, 330, 230)};
  for (const RigPreset preset : AllRigPresets()) {
    for (const colmap::Camera& camera : MakeRigPreset(preset).cameras) {
      references.push_back(camera);
    }
  }
  for (const colmap::Camera& reference : references) {
    SCOPED_TRACE(reference.ModelName());
    colmap::Camera estimate = reference;
    ScaleFocal(1.01, &estimate);
    CameraError error;
    CompareProjections(reference, estimate, 20, 15, &error);
    ASSERT_EQ(error.num_projection_samples, 300);
    double sum = 0, max_radius = 0;
    for (int row = 0; row < 15; ++row) {
      for (int col = 0; col < 20; ++col) {
        const double radius = std::hypot(
            (col + 0.5) * reference.Width() / 20 - reference.PrincipalPointX(),
            (row + 0.5) * reference.Height() / 15 -
                reference.PrincipalPointY());
        sum += radius;
        max_radius = std::max(max_radius, radius);
      }
    }
    EXPECT_NEAR(error.mean_projection_diff_px, 0.01 * sum / 300, 1e-8);
    EXPECT_NEAR(error.max_projection_diff_px, 0.01 * max_radius, 1e-8);
  }
}

// Distortion coefficients of different models are not compared, only
// their projections: a distortion-free OPENCV equals a PINHOLE.
TEST(Evaluation, DifferentModelsAreComparedByTheirProjections) {
  const colmap::Camera pinhole = PinholeCamera(400, 320, 240);
  colmap::Camera opencv;
  opencv.SetModelIdFromName("OPENCV");
  opencv.SetWidth(640);
  opencv.SetHeight(480);
  opencv.SetParams({400, 400, 320, 240, 0, 0, 0, 0});
  CameraError error;
  CompareProjections(pinhole, opencv, 20, 15, &error);
  EXPECT_LT(error.max_projection_diff_px, 1e-12);

  // A little barrel distortion: zero at the center, growing outwards.
  opencv.Params()[4] = -0.01;
  CompareProjections(pinhole, opencv, 20, 15, &error);
  EXPECT_GT(error.max_projection_diff_px, 0.5);
  EXPECT_LT(error.max_projection_diff_px, 20);
}

// Rays beyond the fold of a strongly distorted estimate are skipped.
TEST(Evaluation, RaysOutsideTheFieldOfViewAreSkipped) {
  const colmap::Camera pinhole = PinholeCamera(400, 320, 240);
  colmap::Camera folded;
  folded.SetModelIdFromName("RADIAL");
  folded.SetWidth(640);
  folded.SetHeight(480);
  // r (1 - 0.6 r^2) folds at r = 1 / sqrt(1.8) = 0.745, inside the image
  // (the corner is at r = 1).
  folded.SetParams({400, 320, 240, -0.6, 0});
  CameraError error;
  CompareProjections(pinhole, folded, 20, 15, &error);
  EXPECT_GT(error.num_projection_skipped, 0);
  EXPECT_GT(error.num_projection_samples, 150);
  EXPECT_EQ(error.num_projection_samples + error.num_projection_skipped, 300);

  // The reference's own fold limits its rays the same way.
  CompareProjections(folded, pinhole, 20, 15, &error);
  EXPECT_EQ(error.num_projection_samples + error.num_projection_skipped, 300);
  EXPECT_GT(error.num_projection_skipped, 0);
}

TEST(Evaluation, BadInputIsReported) {
  const RigGroundTruth truth = MakeRigPreset(RigPreset::kStereoPair);
  std::vector<Rigid3d> too_few = {truth.cam_from_rig[0]};
  CalibrationError error = CompareCalibrations(
      truth.cameras, truth.cam_from_rig, truth.cameras, too_few, false);
  EXPECT_FALSE(error.ok());
  EXPECT_TRUE(error.cameras.empty());

  std::vector<colmap::Camera> broken = truth.cameras;
  broken[1].Params().pop_back();
  error = CompareCalibrations(truth.cameras, truth.cam_from_rig, broken,
                              truth.cam_from_rig, false);
  EXPECT_FALSE(error.ok());
  EXPECT_NE(error.error.find("estimated camera 1"), std::string::npos);

  broken = truth.cameras;
  broken[0] = colmap::Camera();
  error = CompareCalibrations(broken, truth.cam_from_rig, truth.cameras,
                              truth.cam_from_rig, false);
  EXPECT_FALSE(error.ok());

  CompareOptions options;
  options.alignment = RigAlignment::kReferenceCamera;
  options.reference_camera = 2;
  error = CompareCalibrations(truth.cameras, truth.cam_from_rig, truth.cameras,
                              truth.cam_from_rig, options);
  EXPECT_FALSE(error.ok());
  EXPECT_NE(FormatCalibrationErrorTable(error, {}).find("out of range"),
            std::string::npos);
  EXPECT_TRUE(CalibrationErrorToJson(error, {}).contains("error"));
}

TEST(Evaluation, TableAndJsonReportEveryCamera) {
  const RigGroundTruth truth = MakeRigPreset(RigPreset::kRing5);
  std::vector<colmap::Camera> cameras = truth.cameras;
  ScaleFocal(1.02, &cameras[4]);
  const CalibrationError error = CompareCalibrations(
      truth.cameras, truth.cam_from_rig, cameras, truth.cam_from_rig, false);
  ASSERT_TRUE(error.ok());
  EXPECT_NEAR(error.MaxFocalErrorPercent(), 2.0, 1e-9);

  const std::string table =
      FormatCalibrationErrorTable(error, {"front", "left"});
  EXPECT_NE(table.find("front"), std::string::npos);
  EXPECT_NE(table.find("left"), std::string::npos);
  EXPECT_NE(table.find("cam4"), std::string::npos);
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 1 + 5 + 2);
  // The cam4 row read back: rotation, center, focal (%) columns.
  std::istringstream cam4_row(table.substr(table.find("cam4")));
  std::string name;
  double rotation_deg = -1, center = -1, focal_percent = -1;
  cam4_row >> name >> rotation_deg >> center >> focal_percent;
  EXPECT_EQ(name, "cam4");
  EXPECT_NEAR(rotation_deg, 0, 1e-4);
  EXPECT_NEAR(focal_percent, error.cameras[4].focal_error_percent, 1e-3);

  const nlohmann::json json = CalibrationErrorToJson(error, truth.camera_names);
  ASSERT_EQ(json["cameras"].size(), 5);
  EXPECT_EQ(json["cameras"][4]["name"], "cam4");
  EXPECT_NEAR(json["cameras"][4]["focal_error_percent"].get<double>(), 2.0,
              1e-9);
  EXPECT_EQ(json["cameras"][0]["focal_error_percent"].get<double>(), 0.0);
  EXPECT_NEAR(json["max"]["focal_error_percent"].get<double>(), 2.0, 1e-9);
  EXPECT_EQ(json["scale"].get<double>(), 1.0);
}

}  // namespace evaluation_test
}  // namespace rig_calibrator
