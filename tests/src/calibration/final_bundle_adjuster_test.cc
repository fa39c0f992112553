#include "src/calibration/final_bundle_adjuster.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

namespace rig_calibrator {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

struct SceneOptions {
  int model_id = colmap::OpenCVCameraModel::kModelId;
  int num_cameras = 4;
  int num_framesets = 20;
  int num_points_per_image = 100;
  double noise_px = 0;
  double outlier_ratio = 0;
  // true: images observe one world point cloud (shared point ids); false:
  // every observation has its own point (id -1), spread over the image.
  bool shared_points = false;
  unsigned seed = 1;
};

// A synthetic rig looking around (camera i turned by i * 360 / num_cameras
// degrees about the rig's y axis), walked through a scene with points 2-10 m
// away; some images are missing.
struct SyntheticRig {
  RigDataset dataset;
  RigCalibration truth;
  // Per image, per correspondence: replaced by a random pixel.
  std::vector<std::vector<char>> is_gross_outlier;
};

Eigen::Quaterniond RotationAboutAxis(double angle_rad,
                                     const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis.normalized()));
}

colmap::Camera MakeCamera(int model_id, int index) {
  colmap::Camera camera;
  camera.SetModelId(model_id);
  if (model_id == colmap::OpenCVFisheyeCameraModel::kModelId) {
    // f * 75 deg * (1 + distortion) reaches the image border: 150 deg FOV.
    camera.SetWidth(640);
    camera.SetHeight(640);
    camera.SetParams({250.0 + 5 * index, 251.0 + 5 * index, 320.0 + 3 * index,
                      320.0 - 2 * index, 0.05, -0.01, 0.002, -0.0005});
  } else {
    // k2 keeps r (1 + k1 r^2 + k2 r^4) monotonic over the whole image.
    camera.SetWidth(640);
    camera.SetHeight(480);
    camera.SetParams({500.0 + 10 * index, 501.0 + 10 * index, 320.0 + 3 * index,
                      240.0 - 2 * index, -0.3, 0.08, 1e-4, -2e-4});
  }
  return camera;
}

// Half of the field of view kept for observations.
double MaxViewAngleRad(int model_id) {
  return (model_id == colmap::OpenCVFisheyeCameraModel::kModelId ? 75.0
                                                                 : 50.0) *
         kDegToRad;
}

bool InImage(const colmap::Camera& camera, const Eigen::Vector2d& x) {
  return x.x() >= 0 && x.y() >= 0 && x.x() <= camera.Width() &&
         x.y() <= camera.Height();
}

SyntheticRig MakeSyntheticRig(const SceneOptions& options) {
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> uniform(0, 1);
  std::normal_distribution<double> gaussian(0, 1);
  const auto random_unit = [&]() {
    return Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng))
        .normalized();
  };

  SyntheticRig rig;
  RigDataset& dataset = rig.dataset;
  RigCalibration& truth = rig.truth;
  for (int i = 0; i < options.num_cameras; ++i) {
    RigCamera camera;
    camera.name = "cam" + std::to_string(i);
    camera.camera = MakeCamera(options.model_id, i);
    dataset.cameras.push_back(camera);
    truth.cameras.push_back(camera.camera);
    truth.camera_calibrated.push_back(true);
    // Camera i looks along yaw_i with a small tilt, 15 cm from the rig
    // center; camera 0 defines the rig frame.
    const double yaw = 2 * M_PI * i / options.num_cameras;
    const Eigen::Quaterniond rig_from_cam =
        RotationAboutAxis(yaw, Eigen::Vector3d::UnitY()) *
        RotationAboutAxis(i == 0 ? 0 : 3 * kDegToRad * i,
                          Eigen::Vector3d::UnitX());
    const Eigen::Vector3d center_in_rig =
        i == 0 ? Eigen::Vector3d::Zero()
               : Eigen::Vector3d(0.15 * std::sin(yaw), 0.02 * i,
                                 0.15 * (std::cos(yaw) - 1));
    truth.cam_from_rig.push_back(
        Rigid3d(rig_from_cam, center_in_rig).Inverse());
  }

  std::vector<Eigen::Vector3d> cloud;
  if (options.shared_points) {
    for (int p = 0; p < 3000; ++p) {
      cloud.push_back(random_unit() * (4 + 6 * uniform(rng)));
    }
  }

  for (int j = 0; j < options.num_framesets; ++j) {
    dataset.frameset_names.push_back("frame" + std::to_string(j));
    const double a = 2 * M_PI * j / options.num_framesets;
    const Eigen::Vector3d rig_center(std::cos(a), 0.2 * std::sin(3 * a),
                                     std::sin(a));
    const Eigen::Quaterniond world_from_rig =
        RotationAboutAxis(0.7 * a, Eigen::Vector3d::UnitY()) *
        RotationAboutAxis(5 * kDegToRad * uniform(rng), random_unit());
    truth.rig_from_world.push_back(
        Rigid3d(world_from_rig, rig_center).Inverse());
    for (int i = 0; i < options.num_cameras; ++i) {
      if ((j * options.num_cameras + i) % 7 == 3) {
        continue;  // a missing image
      }
      RigImage image;
      image.name = dataset.cameras[i].name + "/" + dataset.frameset_names[j];
      image.camera_index = i;
      image.frameset_index = j;
      const colmap::Camera& camera = truth.cameras[i];
      const Rigid3d cam_from_world = truth.CamFromWorld(i, j);
      const Rigid3d world_from_cam = cam_from_world.Inverse();
      const auto observe = [&](const Eigen::Vector3d& point_in_cam,
                               Eigen::Vector2d* x) {
        if (std::atan2(point_in_cam.head<2>().norm(), point_in_cam.z()) >
            MaxViewAngleRad(options.model_id)) {
          return false;
        }
        *x = camera.WorldToImage(point_in_cam.hnormalized());
        return InImage(camera, *x);
      };
      if (options.shared_points) {
        std::vector<int> order(cloud.size());
        for (size_t p = 0; p < order.size(); ++p) order[p] = p;
        std::shuffle(order.begin(), order.end(), rng);
        for (int p : order) {
          Correspondence correspondence;
          if (observe(cam_from_world * cloud[p], &correspondence.point2D)) {
            correspondence.point3D = cloud[p];
            correspondence.point3D_id = p;
            image.correspondences.push_back(correspondence);
          }
          if (static_cast<int>(image.correspondences.size()) ==
              options.num_points_per_image) {
            break;
          }
        }
      } else {
        while (static_cast<int>(image.correspondences.size()) <
               options.num_points_per_image) {
          const Eigen::Vector2d pixel(uniform(rng) * camera.Width(),
                                      uniform(rng) * camera.Height());
          const Eigen::Vector3d point_in_cam =
              camera.ImageToWorld(pixel).homogeneous().normalized() *
              (2 + 8 * uniform(rng));
          Correspondence correspondence;
          if (point_in_cam.z() > 0 &&
              observe(point_in_cam, &correspondence.point2D)) {
            correspondence.point3D = world_from_cam * point_in_cam;
            image.correspondences.push_back(correspondence);
          }
        }
      }
      std::vector<char> is_outlier(image.correspondences.size(), 0);
      for (size_t k = 0; k < image.correspondences.size(); ++k) {
        Eigen::Vector2d& x = image.correspondences[k].point2D;
        x += options.noise_px * Eigen::Vector2d(gaussian(rng), gaussian(rng));
        if (uniform(rng) < options.outlier_ratio) {
          x = Eigen::Vector2d(uniform(rng) * camera.Width(),
                              uniform(rng) * camera.Height());
          is_outlier[k] = 1;
        }
      }
      ImageResult result;
      result.localized = true;
      result.inlier_mask.assign(image.correspondences.size(), 1);
      truth.images.push_back(result);
      rig.is_gross_outlier.push_back(is_outlier);
      dataset.images.push_back(image);
    }
  }
  return rig;
}

Rigid3d Perturb(const Rigid3d& pose, double angle_deg, double distance,
                std::mt19937* rng) {
  std::normal_distribution<double> gaussian(0, 1);
  const Eigen::Vector3d axis(gaussian(*rng), gaussian(*rng), gaussian(*rng));
  const Eigen::Vector3d direction(gaussian(*rng), gaussian(*rng),
                                  gaussian(*rng));
  return Rigid3d(RotationAboutAxis(angle_deg * kDegToRad, axis) * pose.rotation,
                 pose.translation + distance * direction.normalized());
}

// The start of the adjustment: rotations off by 1 deg, translations by 2 cm,
// focal lengths by 2 %, principal points by 10 px, k1 by 0.02.
RigCalibration PerturbedStart(const SyntheticRig& rig, unsigned seed) {
  std::mt19937 rng(seed);
  RigCalibration start = rig.truth;
  for (size_t i = 0; i < start.cameras.size(); ++i) {
    if (static_cast<int>(i) != rig.dataset.reference_camera) {
      start.cam_from_rig[i] = Perturb(start.cam_from_rig[i], 1, 0.02, &rng);
    }
    std::vector<double>& params = start.cameras[i].Params();
    const double sign = i % 2 == 0 ? 1 : -1;
    params[0] *= 1 + 0.02 * sign;
    params[1] *= 1 + 0.02 * sign;
    params[2] += 10 * sign;
    params[3] -= 10;
    params[4] += 0.02 * sign;
  }
  for (std::optional<Rigid3d>& pose : start.rig_from_world) {
    pose = Perturb(*pose, 1, 0.02, &rng);
  }
  return start;
}

double RotationErrorDeg(const Eigen::Quaterniond& a,
                        const Eigen::Quaterniond& b) {
  // 2 asin |vec(a^-1 b)| keeps full precision for tiny angles (acos does not).
  const Eigen::Quaterniond difference = (a.conjugate() * b).normalized();
  return 2 * std::asin(std::min(1.0, difference.vec().norm())) / kDegToRad;
}

// Largest errors of an estimate against the truth.
struct CalibrationErrors {
  double rotation_deg = 0;  // cam_from_rig and rig_from_world
  double center = 0;        // camera centers in the rig, rig centers
  double focal_relative = 0;
  double principal_point_px = 0;
  double k1 = 0;
};

CalibrationErrors Compare(const RigCalibration& estimate,
                          const RigCalibration& truth) {
  CalibrationErrors errors;
  const auto add_pose = [&](const Rigid3d& a, const Rigid3d& b) {
    errors.rotation_deg =
        std::max(errors.rotation_deg, RotationErrorDeg(a.rotation, b.rotation));
    errors.center = std::max(errors.center, (a.Center() - b.Center()).norm());
  };
  for (size_t i = 0; i < truth.cameras.size(); ++i) {
    add_pose(estimate.cam_from_rig[i], truth.cam_from_rig[i]);
    const std::vector<double>& p = estimate.cameras[i].Params();
    const std::vector<double>& q = truth.cameras[i].Params();
    for (int k : {0, 1}) {
      errors.focal_relative =
          std::max(errors.focal_relative, std::abs(p[k] / q[k] - 1));
    }
    for (int k : {2, 3}) {
      errors.principal_point_px =
          std::max(errors.principal_point_px, std::abs(p[k] - q[k]));
    }
    errors.k1 = std::max(errors.k1, std::abs(p[4] - q[4]));
  }
  for (size_t j = 0; j < truth.rig_from_world.size(); ++j) {
    add_pose(*estimate.rig_from_world[j], *truth.rig_from_world[j]);
  }
  return errors;
}

void PrintErrors(const char* label, const CalibrationErrors& e,
                 const FinalBundleAdjustmentSummary& summary) {
  std::printf(
      "%s: rotation %.3g deg, center %.3g, focal %.3g, pp %.3g px, k1 %.3g; "
      "rms %.3g -> %.3g px, %d observations, %d outliers, %d iterations, "
      "%.3f s\n",
      label, e.rotation_deg, e.center, e.focal_relative, e.principal_point_px,
      e.k1, summary.initial_rms_px, summary.final_rms_px, summary.num_residuals,
      summary.num_outliers, summary.num_iterations, summary.seconds);
}

// The residual of CreateRigReprojectionError, fully auto-differentiated: the
// reference for its analytic Jacobians.
template <typename CameraModel>
struct AutoDiffRigReprojectionError {
  template <typename T>
  bool operator()(const T* rig_from_world, const T* cam_from_rig,
                  const T* camera_params, const T* point3D,
                  T* residuals) const {
    T point_in_rig[3], point_in_cam[3];
    ceres::UnitQuaternionRotatePoint(rig_from_world, point3D, point_in_rig);
    for (int k = 0; k < 3; ++k) {
      point_in_rig[k] += rig_from_world[4 + k];
    }
    ceres::UnitQuaternionRotatePoint(cam_from_rig, point_in_rig, point_in_cam);
    for (int k = 0; k < 3; ++k) {
      point_in_cam[k] += cam_from_rig[4 + k];
    }
    CameraModel::WorldToImage(camera_params, point_in_cam[0] / point_in_cam[2],
                              point_in_cam[1] / point_in_cam[2], &residuals[0],
                              &residuals[1]);
    residuals[0] -= observed.x();
    residuals[1] -= observed.y();
    return true;
  }
  Eigen::Vector2d observed;
};

template <typename CameraModel>
void ExpectJacobiansMatchAutoDiff() {
  SCOPED_TRACE(CameraModel::model_name);
  constexpr int kNumParams = static_cast<int>(CameraModel::kNumParams);
  const Rigid3d rig_from_world(RotationAboutAxis(0.7, Eigen::Vector3d(1, 2, 3)),
                               Eigen::Vector3d(0.3, -1, 2));
  const Rigid3d cam_from_rig(RotationAboutAxis(2.0, Eigen::Vector3d(-1, 1, 0)),
                             Eigen::Vector3d(0.1, 0.05, -0.2));
  const Rigid3d cam_from_world = cam_from_rig * rig_from_world;
  Eigen::Vector3d point3D =
      cam_from_world.Inverse() * Eigen::Vector3d(1.2, -0.8, 3);
  colmap::Camera camera;
  camera.InitializeWithId(CameraModel::kModelId, 500, 640, 480);
  for (size_t k : camera.ExtraParamsIdxs()) {
    camera.Params(k) = 0.02 * (k % 2 == 0 ? 1 : -1) * (1 + k);
  }
  const auto pose_block = [](const Rigid3d& pose) {
    return std::array<double, 7>{pose.rotation.w(),    pose.rotation.x(),
                                 pose.rotation.y(),    pose.rotation.z(),
                                 pose.translation.x(), pose.translation.y(),
                                 pose.translation.z()};
  };
  const std::array<double, 7> rig_block = pose_block(rig_from_world);
  const std::array<double, 7> cam_block = pose_block(cam_from_rig);
  const Eigen::Vector2d observed(100, 200);
  const double* parameters[] = {rig_block.data(), cam_block.data(),
                                camera.ParamsData(), point3D.data()};

  Eigen::Vector2d expected_residual;
  Eigen::Matrix<double, 2, 7, Eigen::RowMajor> expected_rig, expected_cam;
  Eigen::Matrix<double, 2, kNumParams, Eigen::RowMajor> expected_params;
  Eigen::Matrix<double, 2, 3, Eigen::RowMajor> expected_point;
  double* expected_jacobians[] = {expected_rig.data(), expected_cam.data(),
                                  expected_params.data(),
                                  expected_point.data()};
  ceres::AutoDiffCostFunction<AutoDiffRigReprojectionError<CameraModel>, 2, 7,
                              7, kNumParams, 3>
      reference(new AutoDiffRigReprojectionError<CameraModel>{observed});
  ASSERT_TRUE(reference.Evaluate(parameters, expected_residual.data(),
                                 expected_jacobians));
  EXPECT_NEAR((expected_residual -
               (camera.WorldToImage((cam_from_world * point3D).hnormalized()) -
                observed))
                  .norm(),
              0, 1e-9);

  // Pose Jacobians are compared on the manifold (what Ceres uses).
  const ceres::QuaternionManifold quaternion_manifold;
  const auto on_manifold =
      [&](const std::array<double, 7>& block,
          const Eigen::Matrix<double, 2, 7, Eigen::RowMajor>& jacobian) {
        Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus_jacobian;
        quaternion_manifold.PlusJacobian(block.data(), plus_jacobian.data());
        Eigen::Matrix<double, 2, 6> tangent;
        tangent << jacobian.leftCols<4>() * plus_jacobian,
            jacobian.rightCols<3>();
        return tangent;
      };
  for (const bool variable_point : {false, true}) {
    SCOPED_TRACE(variable_point ? "variable point" : "fixed point");
    const std::unique_ptr<ceres::CostFunction> cost(CreateRigReprojectionError(
        CameraModel::kModelId, observed, variable_point ? nullptr : &point3D));
    ASSERT_NE(cost, nullptr);
    ASSERT_EQ(cost->parameter_block_sizes().size(), variable_point ? 4 : 3);
    Eigen::Vector2d residual;
    Eigen::Matrix<double, 2, 7, Eigen::RowMajor> rig_jacobian, cam_jacobian;
    Eigen::Matrix<double, 2, kNumParams, Eigen::RowMajor> params_jacobian;
    Eigen::Matrix<double, 2, 3, Eigen::RowMajor> point_jacobian;
    double* jacobians[] = {rig_jacobian.data(), cam_jacobian.data(),
                           params_jacobian.data(), point_jacobian.data()};
    ASSERT_TRUE(cost->Evaluate(parameters, residual.data(), jacobians));
    const double scale = 1e-10 * expected_rig.norm();
    EXPECT_LT((residual - expected_residual).norm(), 1e-10);
    EXPECT_LT((on_manifold(rig_block, rig_jacobian) -
               on_manifold(rig_block, expected_rig))
                  .norm(),
              scale);
    EXPECT_LT((on_manifold(cam_block, cam_jacobian) -
               on_manifold(cam_block, expected_cam))
                  .norm(),
              scale);
    EXPECT_LT((params_jacobian - expected_params).norm(),
              1e-10 * expected_params.norm());
    if (variable_point) {
      EXPECT_LT((point_jacobian - expected_point).norm(), scale);
    }
    // Without the intrinsics' Jacobian (constant block) the rest is the same.
    jacobians[2] = nullptr;
    ASSERT_TRUE(cost->Evaluate(parameters, residual.data(), jacobians));
    EXPECT_LT((on_manifold(rig_block, rig_jacobian) -
               on_manifold(rig_block, expected_rig))
                  .norm(),
              scale);
  }
  // Behind the camera: a failed evaluation, not a NaN.
  const Eigen::Vector3d behind =
      cam_from_world.Inverse() * Eigen::Vector3d(0.2, 0.1, -3);
  const std::unique_ptr<ceres::CostFunction> cost(
      CreateRigReprojectionError(CameraModel::kModelId, observed, &behind));
  Eigen::Vector2d residual;
  EXPECT_FALSE(cost->Evaluate(parameters, residual.data(), nullptr));
}

TEST(FinalBundleAdjusterTest, ReprojectionErrorJacobiansMatchAutoDiff) {
  ExpectJacobiansMatchAutoDiff<colmap::SimplePinholeCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::SimpleRadialCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::OpenCVCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::OpenCVFisheyeCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::FullOpenCVCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::FOVCameraModel>();
  ExpectJacobiansMatchAutoDiff<colmap::ThinPrismFisheyeCameraModel>();
  EXPECT_EQ(CreateRigReprojectionError(-7, Eigen::Vector2d::Zero(), nullptr),
            nullptr);
}

TEST(FinalBundleAdjusterTest, RecoversExactRigFromPerturbedStart) {
  const SyntheticRig rig = MakeSyntheticRig(SceneOptions());
  RigCalibration calibration = PerturbedStart(rig, 2);
  const CalibrationErrors start = Compare(calibration, rig.truth);
  ASSERT_GT(start.rotation_deg, 0.5);
  ASSERT_GT(start.focal_relative, 0.01);

  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  const CalibrationErrors errors = Compare(calibration, rig.truth);
  PrintErrors("exact", errors, summary);
  EXPECT_LT(errors.rotation_deg, 1e-8);
  EXPECT_LT(errors.center, 1e-8);
  EXPECT_LT(errors.focal_relative, 1e-9);
  EXPECT_LT(errors.principal_point_px, 1e-6);
  EXPECT_LT(errors.k1, 1e-8);
  EXPECT_GT(summary.initial_rms_px, 5);
  EXPECT_LT(summary.final_rms_px, 1e-8);
  EXPECT_EQ(summary.num_outliers, 0);
  EXPECT_FALSE(summary.ceres_report.empty());
  int num_observations = 0;
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    const ImageResult& result = calibration.images[i];
    EXPECT_TRUE(result.used);
    EXPECT_EQ(result.num_inliers,
              static_cast<int>(rig.dataset.images[i].correspondences.size()));
    EXPECT_LT(result.rms_px, 1e-8);
    num_observations += result.num_inliers;
  }
  EXPECT_EQ(summary.num_residuals, num_observations);
  EXPECT_TRUE(calibration.refined_points3D.empty());
  // The reference camera defines the rig frame.
  EXPECT_EQ(calibration.cam_from_rig[0].translation, Eigen::Vector3d::Zero());
  EXPECT_EQ(calibration.cam_from_rig[0].rotation.w(), 1.0);
}

TEST(FinalBundleAdjusterTest, NoisyDataWithOutliersIsAccurateAndPrunesThem) {
  // 300 correspondences per image, as in real data: a principal point error
  // of d px is nearly a rotation of d / f (0.44 px ~ 0.05 deg), so the
  // rotation bound needs the principal point well below 1 px.
  SceneOptions scene;
  scene.num_points_per_image = 300;
  scene.noise_px = 0.5;
  scene.outlier_ratio = 0.1;
  const SyntheticRig rig = MakeSyntheticRig(scene);
  RigCalibration calibration = PerturbedStart(rig, 3);

  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  const CalibrationErrors errors = Compare(calibration, rig.truth);
  PrintErrors("noisy", errors, summary);
  EXPECT_LT(errors.rotation_deg, 0.05);
  EXPECT_LT(errors.center, 0.002);
  EXPECT_LT(errors.focal_relative, 0.002);
  EXPECT_LT(errors.principal_point_px, 1);
  EXPECT_LT(errors.k1, 0.005);
  // 0.5 px per coordinate: the RMS of |e| is 0.5 sqrt(2) = 0.71 px.
  EXPECT_NEAR(summary.final_rms_px, 0.5 * std::sqrt(2.0), 0.05);

  int num_gross = 0, num_gross_kept = 0, num_good = 0, num_good_pruned = 0;
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    for (size_t k = 0; k < rig.is_gross_outlier[i].size(); ++k) {
      const bool kept = calibration.images[i].inlier_mask[k];
      if (rig.is_gross_outlier[i][k]) {
        ++num_gross;
        num_gross_kept += kept;
      } else {
        ++num_good;
        num_good_pruned += !kept;
      }
    }
  }
  std::printf(
      "gross outliers kept %d of %d, good observations pruned %d of "
      "%d\n",
      num_gross_kept, num_gross, num_good_pruned, num_good);
  ASSERT_GT(num_gross, 500);
  EXPECT_EQ(num_gross_kept, 0);
  // max(2 px, 4 sigma) prunes |e| > 2 px of 0.5 px noise: exp(-8), ~0.03 %.
  EXPECT_LT(num_good_pruned, 0.002 * num_good);
  EXPECT_EQ(summary.num_outliers, num_gross + num_good_pruned);
}

TEST(FinalBundleAdjusterTest, FixedFocalLengthStaysUnchanged) {
  const SyntheticRig rig = MakeSyntheticRig(SceneOptions());
  const RigCalibration start = PerturbedStart(rig, 4);
  RigCalibration calibration = start;
  FinalBundleAdjustmentOptions options;
  options.refine_focal_length = false;
  ASSERT_TRUE(AdjustRig(options, rig.dataset, &calibration, nullptr));
  for (size_t i = 0; i < start.cameras.size(); ++i) {
    const std::vector<double>& p = calibration.cameras[i].Params();
    const std::vector<double>& q = start.cameras[i].Params();
    EXPECT_EQ(p[0], q[0]);
    EXPECT_EQ(p[1], q[1]);
    EXPECT_NE(p[2], q[2]);  // the principal point is still refined
    EXPECT_NE(p[4], q[4]);  // and the distortion
  }
}

TEST(FinalBundleAdjusterTest, KnownIntrinsicsStayUnchangedAndPosesConverge) {
  const SyntheticRig rig = MakeSyntheticRig(SceneOptions());
  RigCalibration calibration = PerturbedStart(rig, 5);
  calibration.cameras = rig.truth.cameras;
  FinalBundleAdjustmentOptions options;
  options.refine_focal_length = false;
  options.refine_principal_point = false;
  options.refine_extra_params = false;
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(options, rig.dataset, &calibration, &summary));
  for (size_t i = 0; i < rig.truth.cameras.size(); ++i) {
    EXPECT_EQ(calibration.cameras[i].Params(), rig.truth.cameras[i].Params());
  }
  const CalibrationErrors errors = Compare(calibration, rig.truth);
  PrintErrors("known intrinsics", errors, summary);
  EXPECT_LT(errors.rotation_deg, 1e-8);
  EXPECT_LT(errors.center, 1e-8);
}

TEST(FinalBundleAdjusterTest, NothingToRefineStillPrunesOutliers) {
  SceneOptions scene;
  scene.outlier_ratio = 0.1;
  const SyntheticRig rig = MakeSyntheticRig(scene);
  RigCalibration calibration = rig.truth;
  FinalBundleAdjustmentOptions options;
  options.refine_focal_length = false;
  options.refine_principal_point = false;
  options.refine_extra_params = false;
  options.refine_extrinsics = false;
  options.refine_rig_poses = false;
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(options, rig.dataset, &calibration, &summary));
  EXPECT_LT(summary.final_rms_px, 1e-8);
  int num_gross = 0;
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    for (size_t k = 0; k < rig.is_gross_outlier[i].size(); ++k) {
      num_gross += rig.is_gross_outlier[i][k];
      EXPECT_EQ(calibration.images[i].inlier_mask[k],
                !rig.is_gross_outlier[i][k]);
    }
  }
  EXPECT_EQ(summary.num_outliers, num_gross);
  EXPECT_EQ(calibration.cameras[1].Params(), rig.truth.cameras[1].Params());
  EXPECT_EQ(calibration.cam_from_rig[1].translation,
            rig.truth.cam_from_rig[1].translation);
}

TEST(FinalBundleAdjusterTest, RefinesMapPoints) {
  SceneOptions scene;
  scene.shared_points = true;
  const SyntheticRig rig = MakeSyntheticRig(scene);
  // The map is off by 1 cm per point; the observations are exact. Points
  // seen once are dropped: they are held fixed at their noisy position.
  RigDataset dataset = rig.dataset;
  std::unordered_map<int64_t, int> num_observations;
  for (const RigImage& image : dataset.images) {
    for (const Correspondence& correspondence : image.correspondences) {
      ++num_observations[correspondence.point3D_id];
    }
  }
  for (RigImage& image : dataset.images) {
    image.correspondences.erase(
        std::remove_if(image.correspondences.begin(),
                       image.correspondences.end(),
                       [&](const Correspondence& correspondence) {
                         return num_observations[correspondence.point3D_id] < 2;
                       }),
        image.correspondences.end());
  }
  RigCalibration start = rig.truth;
  for (size_t i = 0; i < dataset.images.size(); ++i) {
    start.images[i].inlier_mask.assign(dataset.images[i].correspondences.size(),
                                       1);
  }
  std::mt19937 rng(6);
  std::normal_distribution<double> gaussian(0, 0.01);
  std::unordered_map<int64_t, Eigen::Vector3d> truth_points, map_points;
  for (RigImage& image : dataset.images) {
    for (Correspondence& correspondence : image.correspondences) {
      if (!map_points.count(correspondence.point3D_id)) {
        truth_points[correspondence.point3D_id] = correspondence.point3D;
        map_points[correspondence.point3D_id] =
            correspondence.point3D +
            Eigen::Vector3d(gaussian(rng), gaussian(rng), gaussian(rng));
      }
      correspondence.point3D = map_points[correspondence.point3D_id];
    }
  }
  FinalBundleAdjustmentOptions options;
  RigCalibration fixed_map = start;
  FinalBundleAdjustmentSummary fixed_summary;
  ASSERT_TRUE(AdjustRig(options, dataset, &fixed_map, &fixed_summary));
  EXPECT_TRUE(fixed_map.refined_points3D.empty());

  options.refine_points = true;
  RigCalibration calibration = start;
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(options, dataset, &calibration, &summary));
  std::printf("map fixed: rms %.3g px; map refined: rms %.3g px, %zu points\n",
              fixed_summary.final_rms_px, summary.final_rms_px,
              calibration.refined_points3D.size());
  EXPECT_GT(fixed_summary.final_rms_px, 0.5);
  EXPECT_LT(summary.final_rms_px, 1e-6);
  ASSERT_GT(calibration.refined_points3D.size(), 500);
  double map_error = 0, refined_error = 0;
  for (const auto& [point3D_id, point] : calibration.refined_points3D) {
    ASSERT_TRUE(map_points.count(point3D_id));
    EXPECT_GT((point - map_points[point3D_id]).norm(), 1e-4);
    map_error += (map_points[point3D_id] - truth_points[point3D_id]).norm();
    refined_error += (point - truth_points[point3D_id]).norm();
  }
  // Exact observations pin the points down up to the similarity that
  // re-anchors them to the noisy map, which averages the map's noise out.
  std::printf("mean point error: map %.3g, refined %.3g\n",
              map_error / calibration.refined_points3D.size(),
              refined_error / calibration.refined_points3D.size());
  EXPECT_LT(refined_error, 0.2 * map_error);
  const CalibrationErrors errors = Compare(calibration, rig.truth);
  EXPECT_LT(errors.focal_relative, 1e-6);
  EXPECT_LT(errors.rotation_deg, 0.01);
}

TEST(FinalBundleAdjusterTest, FisheyeRigConverges) {
  SceneOptions scene;
  scene.model_id = colmap::OpenCVFisheyeCameraModel::kModelId;
  const SyntheticRig rig = MakeSyntheticRig(scene);
  RigCalibration calibration = PerturbedStart(rig, 7);
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  const CalibrationErrors errors = Compare(calibration, rig.truth);
  PrintErrors("fisheye", errors, summary);
  EXPECT_LT(errors.rotation_deg, 1e-8);
  EXPECT_LT(errors.center, 1e-8);
  EXPECT_LT(errors.focal_relative, 1e-9);
  EXPECT_LT(errors.principal_point_px, 1e-6);
  EXPECT_LT(errors.k1, 1e-8);
  EXPECT_LT(summary.final_rms_px, 1e-8);
  EXPECT_EQ(summary.num_outliers, 0);
}

TEST(FinalBundleAdjusterTest, RejectsPointsBehindAndFarFromTheCamera) {
  SyntheticRig rig = MakeSyntheticRig(SceneOptions());
  RigImage& image = rig.dataset.images[0];
  const Rigid3d world_from_cam =
      rig.truth.CamFromWorld(image.camera_index, image.frameset_index)
          .Inverse();
  Correspondence behind = image.correspondences[0];
  behind.point3D = world_from_cam * Eigen::Vector3d(0.1, 0.2, -5);
  Correspondence far = image.correspondences[1];
  far.point3D = world_from_cam * Eigen::Vector3d(1000, 0, 5000);
  image.correspondences.push_back(behind);
  image.correspondences.push_back(far);
  rig.truth.images[0].inlier_mask.assign(image.correspondences.size(), 1);
  RigCalibration calibration = PerturbedStart(rig, 8);
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  EXPECT_EQ(summary.num_outliers, 2);
  const std::vector<char>& mask = calibration.images[0].inlier_mask;
  EXPECT_FALSE(mask[mask.size() - 2]);
  EXPECT_FALSE(mask[mask.size() - 1]);
  EXPECT_TRUE(std::isfinite(summary.final_rms_px));
  EXPECT_LT(summary.final_rms_px, 1e-8);
}

TEST(FinalBundleAdjusterTest, UsesOnlyInliersOfPosedFramesetsAndCameras) {
  SyntheticRig rig = MakeSyntheticRig(SceneOptions());
  RigCalibration calibration = PerturbedStart(rig, 9);
  calibration.rig_from_world[1].reset();
  calibration.camera_calibrated[2] = false;
  // Gross outliers the mask already rejects never enter.
  RigImage& first = rig.dataset.images[0];
  first.correspondences[0].point2D += Eigen::Vector2d(100, -50);
  calibration.images[0].inlier_mask[0] = 0;
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  EXPECT_LT(summary.final_rms_px, 1e-8);
  EXPECT_EQ(summary.num_outliers, 0);
  EXPECT_FALSE(calibration.images[0].inlier_mask[0]);
  EXPECT_FALSE(calibration.rig_from_world[1].has_value());
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    const RigImage& image = rig.dataset.images[i];
    const bool expected_used =
        image.frameset_index != 1 && image.camera_index != 2;
    EXPECT_EQ(calibration.images[i].used, expected_used) << image.name;
  }
  // The uncalibrated camera keeps its parameters.
  EXPECT_EQ(calibration.cameras[2].Params(),
            PerturbedStart(rig, 9).cameras[2].Params());
}

TEST(FinalBundleAdjusterTest, RejectsInconsistentInput) {
  const SyntheticRig rig = MakeSyntheticRig(SceneOptions());
  RigCalibration calibration = PerturbedStart(rig, 10);
  RigCalibration bad = calibration;
  bad.rig_from_world.pop_back();
  EXPECT_FALSE(
      AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset, &bad, nullptr));
  bad = calibration;
  bad.images[0].inlier_mask.pop_back();
  EXPECT_FALSE(
      AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset, &bad, nullptr));
  bad = calibration;
  for (ImageResult& result : bad.images) {
    std::fill(result.inlier_mask.begin(), result.inlier_mask.end(), 0);
  }
  EXPECT_FALSE(
      AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset, &bad, nullptr));
  bad = calibration;
  bad.cameras[1].Params().pop_back();
  EXPECT_FALSE(
      AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset, &bad, nullptr));
  FinalBundleAdjustmentOptions options;
  options.loss_scale_px = 0;
  bad = calibration;
  EXPECT_FALSE(AdjustRig(options, rig.dataset, &bad, nullptr));
  // A failed call leaves the calibration as it was.
  EXPECT_EQ(bad.cameras[0].Params(), calibration.cameras[0].Params());
  EXPECT_FALSE(
      AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset, nullptr, nullptr));
}

// A benchmark rather than a test (run with --gtest_also_run_disabled_tests):
// 200 framesets x 10 cameras x 300 correspondences, 0.5 px noise, 5 %
// outliers.
TEST(FinalBundleAdjusterTest, DISABLED_LargeInstanceTiming) {
  SceneOptions scene;
  scene.num_cameras = 10;
  scene.num_framesets = 200;
  scene.num_points_per_image = 300;
  scene.noise_px = 0.5;
  scene.outlier_ratio = 0.05;
  const auto start = std::chrono::steady_clock::now();
  const SyntheticRig rig = MakeSyntheticRig(scene);
  RigCalibration calibration = PerturbedStart(rig, 11);
  std::printf(
      "scene made in %.2f s\n",
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count());
  FinalBundleAdjustmentSummary summary;
  ASSERT_TRUE(AdjustRig(FinalBundleAdjustmentOptions(), rig.dataset,
                        &calibration, &summary));
  PrintErrors("large", Compare(calibration, rig.truth), summary);
  std::printf("%s\n", summary.ceres_report.c_str());
}

}  // namespace
}  // namespace rig_calibrator
