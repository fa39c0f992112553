// SelectCameraModel on exact and noisy correspondences of known cameras: a
// fisheye model for a 150-degree lens, the pinhole-type model of the data
// for narrow lenses, and no more parameters than the data need; with too few
// framesets OPENCV unless it cannot represent the lens, then OPENCV_FISHEYE;
// with many rows the candidates compared on a subset, the winner fitted to
// all.
#include "src/calibration/model_selection.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "tests/testing.h"

namespace rig_calibrator {
namespace model_selection_test {

using testing::MakeCamera;

struct Data {
  std::vector<Eigen::Vector2d> points2D;
  std::vector<Eigen::Vector3d> points_cam;  // without tz
  std::vector<int> groups;
};

// Pixels uniform over the image, their rays at depths 2-10, the camera
// points moved by -tz (the upgrade adds tz back); `noise_px` Gaussian pixel
// noise and `outlier_fraction` of rows with a random pixel.
Data MakeData(const colmap::Camera& truth, double tz, int num_points,
              double noise_px, double outlier_fraction, unsigned seed,
              int num_groups = 20) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> x(0, truth.Width());
  std::uniform_real_distribution<double> y(0, truth.Height());
  std::uniform_real_distribution<double> depth(2, 10);
  std::uniform_real_distribution<double> unit(0, 1);
  std::normal_distribution<double> noise(0, noise_px);
  Data data;
  for (int i = 0; i < num_points; ++i) {
    const Eigen::Vector2d pixel(x(generator), y(generator));
    const Eigen::Vector2d uv = truth.ImageToWorld(pixel);
    const Eigen::Vector3d ray = uv.homogeneous().normalized();
    const Eigen::Vector3d point = depth(generator) * ray;
    Eigen::Vector2d observed = truth.WorldToImage(point.hnormalized());
    observed += Eigen::Vector2d(noise(generator), noise(generator));
    if (unit(generator) < outlier_fraction) {
      observed = Eigen::Vector2d(x(generator), y(generator));
    }
    data.points2D.push_back(observed);
    data.points_cam.push_back(point - Eigen::Vector3d(0, 0, tz));
    data.groups.push_back(i % num_groups);
  }
  return data;
}

// Mean and largest distance over a 10 px grid between where the two cameras
// project the rays of the first one's pixels.
void ProjectionDifference(const colmap::Camera& truth,
                          const colmap::Camera& estimate, double* mean_px,
                          double* max_px) {
  double sum = 0;
  int count = 0;
  *max_px = 0;
  for (double y = 5; y < truth.Height(); y += 10) {
    for (double x = 5; x < truth.Width(); x += 10) {
      const Eigen::Vector2d pixel(x, y);
      const double d =
          (estimate.WorldToImage(truth.ImageToWorld(pixel)) - pixel).norm();
      sum += d;
      ++count;
      *max_px = std::max(*max_px, d);
    }
  }
  *mean_px = sum / count;
}

struct Selected {
  bool success = false;
  colmap::Camera camera;
  CameraUpgradeResult result;
  ModelChoice choice;
};

Selected Select(
    const colmap::Camera& truth, const Data& data,
    const ModelSelectionOptions& options = ModelSelectionOptions()) {
  Selected selected;
  selected.camera = MakeCamera(
      "OPENCV", truth.Width(), truth.Height(),
      {1.2 * truth.Width(), 1.2 * truth.Width(), truth.PrincipalPointX() + 3,
       truth.PrincipalPointY() - 2, 0, 0, 0, 0});
  selected.success = SelectCameraModel(
      options, CameraUpgradeOptions(), data.points2D, data.points_cam,
      data.groups, &selected.camera, &selected.result, &selected.choice);
  std::cout << FormatModelChoice(selected.choice, "  ");
  return selected;
}

const ModelCandidate& Candidate(const ModelChoice& choice,
                                const std::string& model) {
  for (const ModelCandidate& candidate : choice.candidates) {
    if (candidate.model == model) return candidate;
  }
  ADD_FAILURE() << "no candidate " << model;
  return choice.candidates.front();
}

// fisheye_helmet5's cam2 (155 degrees diagonal).
colmap::Camera WideFisheye() {
  return MakeCamera("OPENCV_FISHEYE", 640, 480,
                    {290.4, 290.1, 323, 248, 0.015, -0.008, 0.004, -0.0006});
}

TEST(ModelSelection, ExactWideFisheyeGetsOpenCVFisheye) {
  const colmap::Camera truth = WideFisheye();
  const Selected selected = Select(truth, MakeData(truth, 0.1, 3000, 0, 0, 1));
  ASSERT_TRUE(selected.success);
  EXPECT_EQ(selected.choice.chosen, "OPENCV_FISHEYE");
  EXPECT_EQ(selected.camera.ModelName(), "OPENCV_FISHEYE");
  for (size_t i = 0; i < truth.NumParams(); ++i) {
    EXPECT_NEAR(selected.camera.Params()[i], truth.Params()[i],
                1e-6 * std::max(1.0, std::abs(truth.Params()[i])))
        << i;
  }
  EXPECT_NEAR(selected.result.tz, 0.1, 1e-8);
  EXPECT_LT(Candidate(selected.choice, "OPENCV_FISHEYE").heldout_rms_px, 1e-6);
  // A polynomial cannot follow the lens to its corners: dropped, or worse
  // already on its training error (not held out), or far worse held out.
  const ModelCandidate& opencv = Candidate(selected.choice, "OPENCV");
  EXPECT_TRUE(!opencv.valid ||
              (!opencv.as_good_as_best && !(opencv.heldout_rms_px <= 0.5)));
  EXPECT_GT(opencv.train_rms_px, 0.5);
}

TEST(ModelSelection, ExactOpenCVGetsOpenCV) {
  // ring5's cam0: radial-tangential distortion.
  const colmap::Camera truth = MakeCamera(
      "OPENCV", 640, 480, {420, 421, 332, 232, -0.30, 0.080, 4e-4, -3e-4});
  const Selected selected =
      Select(truth, MakeData(truth, -0.05, 3000, 0, 0, 2));
  ASSERT_TRUE(selected.success);
  EXPECT_EQ(selected.choice.chosen, "OPENCV");
  for (size_t i = 0; i < truth.NumParams(); ++i) {
    EXPECT_NEAR(selected.camera.Params()[i], truth.Params()[i],
                1e-7 * std::max(1.0, std::abs(truth.Params()[i])))
        << i;
  }
}

TEST(ModelSelection, ExactRadialGetsRadialNotMore) {
  // car_surround4's back camera: OPENCV fits it as exactly with p1 = p2 = 0,
  // fx = fy, and must not win for its three extra parameters.
  const colmap::Camera truth =
      MakeCamera("RADIAL", 640, 480, {380, 326, 236, -0.20, 0.04});
  const Selected selected = Select(truth, MakeData(truth, 0.2, 3000, 0, 0, 3));
  ASSERT_TRUE(selected.success);
  EXPECT_EQ(selected.choice.chosen, "RADIAL");
  for (size_t i = 0; i < truth.NumParams(); ++i) {
    EXPECT_NEAR(selected.camera.Params()[i], truth.Params()[i],
                1e-7 * std::max(1.0, std::abs(truth.Params()[i])))
        << i;
  }
}

TEST(ModelSelection, NoisyWideFisheyeGetsAFisheyeModelAsAccurateAsTheTruth) {
  const colmap::Camera truth = WideFisheye();
  const Data data = MakeData(truth, 0.1, 4000, 0.5, 0.2, 4);
  const Selected selected = Select(truth, data);
  ASSERT_TRUE(selected.success);
  EXPECT_TRUE(IsFisheyeCameraModel(selected.camera.ModelId()));
  // The true model fitted by hand to the same data.
  colmap::Camera by_hand = selected.camera;
  by_hand.InitializeWithName("OPENCV_FISHEYE", 700, 640, 480);
  by_hand.SetPrincipalPointX(326);
  by_hand.SetPrincipalPointY(246);
  CameraUpgradeResult hand_result;
  ASSERT_TRUE(UpgradeCamera(CameraUpgradeOptions(), data.points2D,
                            data.points_cam, &by_hand, &hand_result));
  double auto_mean, auto_max, hand_mean, hand_max;
  ProjectionDifference(truth, selected.camera, &auto_mean, &auto_max);
  ProjectionDifference(truth, by_hand, &hand_mean, &hand_max);
  std::cout << "noisy fisheye: " << selected.choice.chosen
            << " mean/max projection error " << auto_mean << "/" << auto_max
            << " px; OPENCV_FISHEYE by hand " << hand_mean << "/" << hand_max
            << " px" << std::endl;
  EXPECT_LT(auto_mean, 1.5 * hand_mean + 0.02);
  EXPECT_LT(auto_max, 1.5 * hand_max + 0.05);
}

TEST(ModelSelection, NoisyNarrowLensGetsAPinholeTypeModel) {
  // EuRoC's cam0 (stereo_pair), about 80 degrees horizontally.
  const colmap::Camera truth =
      MakeCamera("OPENCV", 752, 480,
                 {458.654, 457.296, 367.215, 248.375, -0.28340811, 0.07395907,
                  0.00019359, 1.76187114e-05});
  const Data data = MakeData(truth, 0.0, 4000, 0.5, 0.2, 5);
  const Selected selected = Select(truth, data);
  ASSERT_TRUE(selected.success);
  EXPECT_FALSE(IsFisheyeCameraModel(selected.camera.ModelId()));
  double mean_px, max_px;
  ProjectionDifference(truth, selected.camera, &mean_px, &max_px);
  std::cout << "noisy narrow lens: " << selected.choice.chosen
            << " mean/max projection error " << mean_px << "/" << max_px
            << " px" << std::endl;
  EXPECT_LT(mean_px, 0.1);
}

TEST(ModelSelection, FewFramesetsNarrowLensGetsOpenCV) {
  // 4 framesets: no held-out comparison; OPENCV fits and follows the lens.
  const colmap::Camera truth =
      MakeCamera("OPENCV", 752, 480,
                 {458.654, 457.296, 367.215, 248.375, -0.28340811, 0.07395907,
                  0.00019359, 1.76187114e-05});
  const Selected selected =
      Select(truth, MakeData(truth, 0.0, 2000, 0.5, 0.2, 7, /*num_groups=*/4));
  ASSERT_TRUE(selected.success);
  EXPECT_EQ(selected.choice.chosen, "OPENCV");
  EXPECT_EQ(selected.choice.candidates.size(), 1u);
  EXPECT_NE(selected.choice.reason.find("4 framesets"), std::string::npos);
  double mean_px, max_px;
  ProjectionDifference(truth, selected.camera, &mean_px, &max_px);
  EXPECT_LT(mean_px, 0.1);
}

TEST(ModelSelection, FewFramesetsWideFisheyeGetsOpenCVFisheye) {
  // 4 framesets of a 155-degree lens: OPENCV folds or cannot follow it
  // (checks 1-3 of model_validity.h), OPENCV_FISHEYE is taken, as accurate
  // as the true model by hand.
  const colmap::Camera truth = WideFisheye();
  const Data data = MakeData(truth, 0.1, 3000, 0.5, 0.2, 8, /*num_groups=*/4);
  const Selected selected = Select(truth, data);
  ASSERT_TRUE(selected.success);
  EXPECT_EQ(selected.choice.chosen, "OPENCV_FISHEYE");
  ASSERT_EQ(selected.choice.candidates.size(), 2u);
  EXPECT_FALSE(Candidate(selected.choice, "OPENCV").valid);
  double mean_px, max_px;
  ProjectionDifference(truth, selected.camera, &mean_px, &max_px);
  std::cout << "few framesets, fisheye: mean/max projection error " << mean_px
            << "/" << max_px << " px" << std::endl;
  EXPECT_LT(mean_px, 0.2);
}

TEST(ModelSelection, FewFramesetsWithNoCandidateFollowingTheLensStillCalibrates) {
  // 4 framesets of a narrow lens whose image radius ripples by 2 px with a
  // 150 px period: neither OPENCV nor OPENCV_FISHEYE follows it (OPENCV
  // fails the ring check, OPENCV_FISHEYE folds). Before, the camera was left
  // uncalibrated; now it is calibrated with the candidate valid over the
  // image that misfits least, the choice marked uncertain, its projection
  // within the ripple of the truth.
  const colmap::Camera truth =
      MakeCamera("OPENCV", 752, 480,
                 {458.654, 457.296, 367.215, 248.375, -0.28340811, 0.07395907,
                  0.00019359, 1.76187114e-05});
  Data data = MakeData(truth, 0.0, 3000, 0.3, 0, 10, /*num_groups=*/4);
  const Eigen::Vector2d pp(truth.PrincipalPointX(), truth.PrincipalPointY());
  for (Eigen::Vector2d& point : data.points2D) {
    const Eigen::Vector2d offset = point - pp;
    const double radius = offset.norm();
    if (radius > 1) {
      point += 2.0 * std::sin(2 * M_PI * radius / 150) * offset / radius;
    }
  }
  const Selected selected = Select(truth, data);
  ASSERT_TRUE(selected.success) << selected.result.error_message;
  EXPECT_TRUE(selected.choice.uncertain);
  ASSERT_EQ(selected.choice.candidates.size(), 2u);
  EXPECT_FALSE(Candidate(selected.choice, "OPENCV").valid);
  EXPECT_FALSE(Candidate(selected.choice, "OPENCV_FISHEYE").valid);
  EXPECT_TRUE(selected.choice.chosen == "OPENCV" ||
              selected.choice.chosen == "OPENCV_FISHEYE");
  EXPECT_NE(selected.choice.reason.find("not sure"), std::string::npos);
  double mean_px, max_px;
  ProjectionDifference(truth, selected.camera, &mean_px, &max_px);
  std::cout << "rippled lens: " << selected.choice.chosen
            << " mean/max projection error " << mean_px << "/" << max_px
            << " px" << std::endl;
  EXPECT_LT(mean_px, 2.5);
}

TEST(ModelSelection, CandidatesOnASubsetWinnerOnAllRows) {
  // 1500 of 4000 rows compare the candidates; the winner is fitted to all
  // 4000 (its inlier mask covers them) and is exact.
  const colmap::Camera truth = WideFisheye();
  const Data data = MakeData(truth, 0.1, 4000, 0, 0, 9);
  ModelSelectionOptions options;
  options.max_num_fit_rows = 1500;
  const Selected selected = Select(truth, data, options);
  ASSERT_TRUE(selected.success);
  EXPECT_EQ(selected.choice.chosen, "OPENCV_FISHEYE");
  EXPECT_EQ(Candidate(selected.choice, "OPENCV_FISHEYE").num_inliers, 1500);
  ASSERT_EQ(selected.result.inlier_mask.size(), 4000u);
  EXPECT_EQ(selected.result.num_inliers, 4000);
  EXPECT_NE(selected.choice.reason.find("compared on 1500 of 4000"),
            std::string::npos);
  for (size_t i = 0; i < truth.NumParams(); ++i) {
    EXPECT_NEAR(selected.camera.Params()[i], truth.Params()[i],
                1e-6 * std::max(1.0, std::abs(truth.Params()[i])))
        << i;
  }
}

TEST(ModelSelection, MismatchedGroupsFail) {
  const colmap::Camera truth = WideFisheye();
  Data data = MakeData(truth, 0.1, 100, 0, 0, 6);
  data.groups.pop_back();
  colmap::Camera camera = truth;
  CameraUpgradeResult result;
  ModelChoice choice;
  EXPECT_FALSE(SelectCameraModel(
      ModelSelectionOptions(), CameraUpgradeOptions(), data.points2D,
      data.points_cam, data.groups, &camera, &result, &choice));
  EXPECT_FALSE(result.error_message.empty());
  EXPECT_EQ(camera.ModelName(), "OPENCV_FISHEYE");
}

// The folds are run only for candidates that can still be as good as the
// best, and the choice is the one with every candidate held out.
TEST(ModelSelection, CandidatesWorseOnTrainingErrorAloneAreNotHeldOut) {
  const int n = 400;
  // Per row: training errors, and the held-out errors a few percent higher.
  const auto rows = [&](double level, double wiggle) {
    std::vector<double> errors(n);
    for (int e = 0; e < n; ++e) errors[e] = level + wiggle * ((e * 37) % 11);
    return errors;
  };
  const std::vector<std::vector<double>> training = {
      rows(1.00, 0.01), rows(2.00, 0.01), rows(1.02, 0.01), {}};
  const std::vector<std::vector<double>> held_out = {
      rows(1.06, 0.01), rows(2.10, 0.01), rows(1.05, 0.01), {}};
  std::vector<int> clusters(n);
  for (int e = 0; e < n; ++e) clusters[e] = e / 4;
  ModelChoice pruned, full;
  for (const char* model : {"RADIAL", "OPENCV", "OPENCV_FISHEYE", "PINHOLE"}) {
    ModelCandidate candidate;
    candidate.model = model;
    candidate.num_params = 8;
    pruned.candidates.push_back(candidate);
  }
  full = pruned;
  std::vector<size_t> held;
  const std::vector<std::vector<double>> errors = HeldOutErrorsOfContenders(
      2.0, training, clusters,
      [&](size_t m) {
        held.push_back(m);
        return held_out[m];
      },
      &pruned);
  // By increasing training error; OPENCV (training 2.0 against the best's
  // held-out 1.06) is left out, the invalid PINHOLE is never considered.
  EXPECT_EQ(held, (std::vector<size_t>{0, 2}));
  EXPECT_TRUE(errors[1].empty());
  EXPECT_TRUE(errors[3].empty());
  EXPECT_NE(pruned.candidates[1].note.find("training error alone"),
            std::string::npos);
  EXPECT_TRUE(std::isnan(pruned.candidates[1].heldout_rms_px));
  const int chosen_pruned =
      ChooseByHeldOutError(2.0, errors, clusters, "rows", &pruned);
  const int chosen_full =
      ChooseByHeldOutError(2.0, {held_out[0], held_out[1], held_out[2], {}},
                           clusters, "rows", &full);
  EXPECT_EQ(chosen_pruned, chosen_full);
  EXPECT_EQ(pruned.chosen, full.chosen);
  EXPECT_FALSE(full.candidates[1].as_good_as_best);
}

}  // namespace model_selection_test
}  // namespace rig_calibrator
