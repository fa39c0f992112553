// The two bundle solver backends (src/solvers/bundle_solver.h: the own
// Levenberg-Marquardt and Ceres') reach the same minimum on every kind of
// problem that the production adjustments build: the radial bundle
// adjustment (AdjustRadialRig) and the final one (RigAdjustment, the
// problem AdjustRig solves) with points fixed, points refined, map images,
// the map adjusted in a free gauge, wrong matches under the Cauchy loss with
// a pruning round (inactive residual blocks, held points), each camera
// model family, and the time model (capture-time offsets and line delays,
// automatic Jacobians). The data come from the synthetic generator
// (synthetic_rig.h), the start is the truth perturbed.
//
// The two backends take the same steps (the own solver follows Ceres'
// Levenberg-Marquardt; their per-iteration costs agree to the printed
// digits), but at the function tolerance Ceres discards the last step and
// the own solver keeps it: in a flat direction (a point seen from nearly
// parallel rays) that step is up to 4e-4 m at tolerance 1e-12. So every
// solve here runs to function tolerance 0 and stops on the parameter
// tolerance (a step below 1e-12 |x| in the final adjustment, 1e-10 in the
// radial one) or the gradient, and the results are then the same minimum.
// The final adjustment is run through RigAdjustment, the problem AdjustRig
// builds and solves, rather than AdjustRig itself, whose tolerances are
// fixed (1e-3, 1e-4); the steps around the solves (the initial rejection,
// pruning, writing back, anchoring a free gauge) are AdjustRig's. The
// radial adjustment runs with pruning off and every correspondence
// selected, so that its objective can be evaluated here.
//
// Each test prints its row of the comparison table (cost ratio, worst
// parameter difference, time ratio own / Ceres, iterations of each); the
// whole binary prints the whole table at the end (docs/solver_comparison.md).
#include <ceres/loss_function.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "src/calibration/final_bundle_adjuster.h"
#include "src/calibration/map_anchoring.h"
#include "src/calibration/radial_bundle_adjuster.h"
#include "src/calibration/rig_adjustment.h"
#include "src/geometry/radial_rig_cost_function.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace bundle_solver_backends_test {

// The bounds of the assertions, a few times above the worst measured
// over repeated runs (docs/solver_comparison.md; Ceres' rounding varies
// with the heap): cost 2.8e-14 relative; parameters 4.5e-6 (a point; the
// cameras' and poses' at most 5e-9).
constexpr double kMaxCostRelativeDifference = 2e-13;
constexpr double kMaxParameterDifference = 2e-5;
// The final adjustment's solves: to the last digits.
constexpr double kFunctionTolerance = 0;

// One backend's result on one problem.
struct BackendRun {
  RigCalibration calibration;
  std::vector<CameraCaptureTime> capture_times;  // with a time model
  double final_cost = 0;  // F of the last solve
  int iterations = 0;     // over all solves
  double seconds = 0;     // of the solves (radial: of AdjustRadialRig)
};

// The largest difference between two results, and what it is: rotations
// (radians), translations and points (map units, metres here), focal
// lengths (relative), principal points (pixels over the focal length, an
// angle), distortion parameters (absolute).
struct Difference {
  double value = 0;
  std::string what = "-";
  void Add(double difference, const std::string& name) {
    if (!(difference <= value)) {  // NaN counts as the worst
      value = difference;
      what = name;
    }
  }
};

void AddPose(const Rigid3d& a, const Rigid3d& b, const std::string& name,
             Difference* difference) {
  difference->Add(a.rotation.angularDistance(b.rotation), name + " rotation");
  difference->Add((a.translation - b.translation).norm(),
                  name + " translation");
}

void AddCamera(const colmap::Camera& a, const colmap::Camera& b,
               const std::string& name, Difference* difference) {
  const std::vector<double>& p = a.Params();
  const std::vector<double>& q = b.Params();
  for (const size_t k : b.FocalLengthIdxs()) {
    difference->Add(std::abs(p[k] / q[k] - 1), name + " focal length");
  }
  for (const size_t k : b.PrincipalPointIdxs()) {
    difference->Add(std::abs(p[k] - q[k]) / b.MeanFocalLength(),
                    name + " principal point");
  }
  for (const size_t k : b.ExtraParamsIdxs()) {
    difference->Add(std::abs(p[k] - q[k]), name + " distortion");
  }
}

Difference Compare(const RigCalibration& a, const RigCalibration& b) {
  Difference difference;
  for (size_t i = 0; i < b.cameras.size(); ++i) {
    AddCamera(a.cameras[i], b.cameras[i], "camera", &difference);
    AddPose(a.cam_from_rig[i], b.cam_from_rig[i], "cam_from_rig", &difference);
  }
  for (size_t j = 0; j < b.rig_from_world.size(); ++j) {
    if (a.rig_from_world[j] && b.rig_from_world[j]) {
      AddPose(*a.rig_from_world[j], *b.rig_from_world[j], "rig_from_world",
              &difference);
    }
  }
  EXPECT_EQ(a.refined_points3D.size(), b.refined_points3D.size());
  for (const auto& [point3D_id, point] : b.refined_points3D) {
    const auto other = a.refined_points3D.find(point3D_id);
    difference.Add(other == a.refined_points3D.end()
                       ? std::numeric_limits<double>::infinity()
                       : (other->second - point).norm(),
                   "point");
  }
  for (size_t k = 0; k < b.map_cam_from_world.size(); ++k) {
    AddPose(a.map_cam_from_world[k], b.map_cam_from_world[k],
            "map cam_from_world", &difference);
  }
  for (size_t k = 0; k < b.map_cameras.size(); ++k) {
    AddCamera(a.map_cameras[k], b.map_cameras[k], "map camera", &difference);
  }
  return difference;
}

// The inliers the two runs kept: the same correspondences.
int NumDifferentInlierFlags(const RigCalibration& a, const RigCalibration& b) {
  int count = 0;
  for (size_t i = 0; i < b.images.size(); ++i) {
    const std::vector<char>& p = a.images[i].inlier_mask;
    const std::vector<char>& q = b.images[i].inlier_mask;
    for (size_t k = 0; k < std::max(p.size(), q.size()); ++k) {
      count += (k < p.size() ? p[k] : -1) != (k < q.size() ? q[k] : -1);
    }
  }
  for (size_t i = 0; i < b.map_observation_rejected.size(); ++i) {
    count += a.map_observation_rejected[i] != b.map_observation_rejected[i];
  }
  return count;
}

// The comparison table, one row per problem kind, printed at the end.
struct Row {
  std::string kind;
  double cost_ratio = 0;
  Difference difference;
  double time_ratio = 0;
  int own_iterations = 0, ceres_iterations = 0;
  double own_seconds = 0, ceres_seconds = 0;
};

std::vector<Row>& Table() {
  static std::vector<Row> table;
  return table;
}

void PrintRow(const Row& row) {
  std::printf("| %s | %.1e | %.1e (%s) | %.2f | %d | %d | %.3f | %.3f |\n",
              row.kind.c_str(), row.cost_ratio - 1, row.difference.value,
              row.difference.what.c_str(), row.time_ratio, row.own_iterations,
              row.ceres_iterations, row.own_seconds, row.ceres_seconds);
}

void PrintHeader() {
  std::printf(
      "| problem | cost own / Ceres - 1 | worst parameter difference | time "
      "own "
      "/ Ceres | iterations own | iterations Ceres | own s | Ceres s |\n"
      "|---|---|---|---|---|---|---|---|\n");
}

class TableEnvironment final : public ::testing::Environment {
 public:
  void TearDown() override {
    if (Table().empty()) return;
    std::printf("\nBundle solver backends, own vs Ceres (one thread):\n\n");
    PrintHeader();
    for (const Row& row : Table()) PrintRow(row);
  }
};
::testing::Environment* const kTableEnvironment =
    ::testing::AddGlobalTestEnvironment(new TableEnvironment);

// Compares the two runs, records and prints the row, and checks the bounds.
void ExpectSameMinimum(const std::string& kind, const BackendRun& own,
                       const BackendRun& ceres) {
  Row row;
  row.kind = kind;
  row.cost_ratio = own.final_cost / ceres.final_cost;
  row.difference = Compare(own.calibration, ceres.calibration);
  // Time offsets (seconds) and line delays as readouts of 1000 rows
  // (seconds).
  for (size_t c = 0; c < ceres.capture_times.size(); ++c) {
    const CameraCaptureTime& a = own.capture_times[c];
    const CameraCaptureTime& b = ceres.capture_times[c];
    row.difference.Add(std::abs(a.time_offset_s - b.time_offset_s),
                       "time offset");
    row.difference.Add(1000 * std::abs(a.line_delay_s - b.line_delay_s),
                       "line delay");
  }
  EXPECT_EQ(own.capture_times.size(), ceres.capture_times.size());
  row.time_ratio = own.seconds / ceres.seconds;
  row.own_iterations = own.iterations;
  row.ceres_iterations = ceres.iterations;
  row.own_seconds = own.seconds;
  row.ceres_seconds = ceres.seconds;
  PrintHeader();
  PrintRow(row);
  Table().push_back(row);
  EXPECT_GT(ceres.final_cost, 0);
  EXPECT_LT(std::abs(row.cost_ratio - 1), kMaxCostRelativeDifference);
  EXPECT_LT(row.difference.value, kMaxParameterDifference)
      << row.difference.what;
  EXPECT_EQ(NumDifferentInlierFlags(own.calibration, ceres.calibration), 0);
}

// A dataset of `preset` with `outlier_ratio` wrong matches and
// `num_map_images` map images.
SyntheticRig MakeRig(RigPreset preset, double outlier_ratio,
                     int num_map_images = 0, unsigned seed = 7) {
  SyntheticRigOptions options;
  options.preset = preset;
  options.num_framesets = 8;
  options.points_per_image = 60;
  options.noise_px = 0.5;
  options.outlier_ratio = outlier_ratio;
  options.missing_image_ratio = 0.1;
  options.num_map_images = num_map_images;
  options.map_noise_px = 0.5;
  options.seed = seed;
  return GenerateSyntheticRig(options);
}

// The rig seen through cameras of `model_name` (PINHOLE, SIMPLE_RADIAL):
// each camera's true intrinsics converted (the mean focal length for one
// focal length, the principal point, k1 where the model has it), every
// correct correspondence's pixel projected again from its true point with
// fresh noise.
void ChangeCameraModel(const std::string& model_name, double noise_px,
                       SyntheticRig* rig) {
  std::mt19937 rng(17);
  std::normal_distribution<double> noise(0, noise_px);
  for (size_t i = 0; i < rig->truth.cameras.size(); ++i) {
    const colmap::Camera& old_camera = rig->truth.cameras[i];
    colmap::Camera camera;
    camera.InitializeWithName(model_name, old_camera.MeanFocalLength(),
                              old_camera.Width(), old_camera.Height());
    camera.SetPrincipalPointX(old_camera.PrincipalPointX());
    camera.SetPrincipalPointY(old_camera.PrincipalPointY());
    if (!camera.ExtraParamsIdxs().empty()) {
      camera.Params(camera.ExtraParamsIdxs()[0]) =
          old_camera.Params(old_camera.ExtraParamsIdxs()[0]);
    }
    rig->truth.cameras[i] = camera;
    rig->dataset.cameras[i].camera = camera;
  }
  for (size_t k = 0; k < rig->dataset.images.size(); ++k) {
    RigImage& image = rig->dataset.images[k];
    const Rigid3d cam_from_world =
        rig->truth.cam_from_rig[image.camera_index] *
        rig->truth.rig_from_world[image.frameset_index];
    const colmap::Camera& camera = rig->truth.cameras[image.camera_index];
    for (size_t c = 0; c < image.correspondences.size(); ++c) {
      if (rig->is_outlier[k][c]) continue;
      Correspondence& correspondence = image.correspondences[c];
      const Eigen::Vector3d point =
          cam_from_world * rig->true_points3D[correspondence.point3D_id];
      correspondence.point2D = camera.WorldToImage(point.hnormalized()) +
                               Eigen::Vector2d(noise(rng), noise(rng));
    }
  }
}

Rigid3d Perturb(const Rigid3d& pose, double angle_deg, double distance,
                std::mt19937* rng) {
  std::normal_distribution<double> gaussian(0, 1);
  const Eigen::Vector3d axis =
      Eigen::Vector3d(gaussian(*rng), gaussian(*rng), gaussian(*rng))
          .normalized();
  return Rigid3d(
      Eigen::Quaterniond(Eigen::AngleAxisd(angle_deg * M_PI / 180, axis)) *
          pose.rotation,
      pose.translation + distance * axis);
}

// The truth perturbed: rotations 0.5 deg, translations 2 cm, focal lengths
// 1 %, principal points 4 px, the first distortion parameter by 10 %; every
// correspondence an inlier.
RigCalibration PerturbedStart(const SyntheticRig& rig) {
  std::mt19937 rng(11);
  RigCalibration start;
  start.cameras = rig.truth.cameras;
  start.cam_from_rig = rig.truth.cam_from_rig;
  start.camera_calibrated.assign(start.cameras.size(), true);
  for (size_t i = 0; i < start.cameras.size(); ++i) {
    colmap::Camera& camera = start.cameras[i];
    const double sign = i % 2 == 0 ? 1 : -1;
    for (const size_t k : camera.FocalLengthIdxs()) {
      camera.Params(k) *= 1 + 0.01 * sign;
    }
    camera.SetPrincipalPointX(camera.PrincipalPointX() + 4 * sign);
    camera.SetPrincipalPointY(camera.PrincipalPointY() - 4);
    if (!camera.ExtraParamsIdxs().empty()) {
      camera.Params(camera.ExtraParamsIdxs()[0]) *= 0.9;
    }
    if (static_cast<int>(i) != rig.dataset.reference_camera) {
      start.cam_from_rig[i] = Perturb(start.cam_from_rig[i], 0.5, 0.02, &rng);
    }
  }
  for (const Rigid3d& pose : rig.truth.rig_from_world) {
    start.rig_from_world.push_back(Perturb(pose, 0.5, 0.02, &rng));
  }
  for (const RigImage& image : rig.dataset.images) {
    ImageResult result;
    result.localized = true;
    result.inlier_mask.assign(image.correspondences.size(), 1);
    start.images.push_back(result);
  }
  return start;
}

// The final adjustment as AdjustRig runs it, each solve to
// kFunctionTolerance (at most 1000 iterations), with one pruning round if
// `prune`.
BackendRun RunFinalAdjustment(const SyntheticRig& rig,
                              const RigCalibration& start,
                              FinalBundleAdjustmentOptions options, bool prune,
                              BundleSolverBackend backend) {
  options.bundle_solver = backend;
  options.num_threads = 1;
  options.max_num_iterations = 1000;
  BackendRun run;
  RigAdjustment adjustment(options, rig.dataset, start);
  adjustment.RejectOutliers(/*prune_residuals=*/false);
  BundleSolverSummary summary;
  const auto solve = [&]() {
    EXPECT_TRUE(adjustment.Solve(kFunctionTolerance, &summary))
        << summary.BriefReport();
    run.iterations +=
        summary.num_successful_steps + summary.num_unsuccessful_steps;
    run.seconds += summary.seconds;
  };
  solve();
  if (prune) {
    EXPECT_GT(adjustment.RejectOutliers(/*prune_residuals=*/true), 0u);
    solve();
  }
  adjustment.RejectMapOutliers();
  run.final_cost = summary.final_cost;
  run.calibration = start;
  adjustment.WriteTo(&run.calibration);
  if (options.HasTimeModel()) run.capture_times = adjustment.CaptureTimes();
  if (options.refine_points && !adjustment.HasFixedPoints()) {
    if (options.refine_map) {
      EXPECT_TRUE(AnchorMapImagesToMap(rig.dataset, &run.calibration));
    } else {
      EXPECT_TRUE(AnchorRefinedPointsToMap(rig.dataset, &run.calibration));
    }
  }
  return run;
}

void CompareFinalAdjustment(const std::string& kind, const SyntheticRig& rig,
                            const FinalBundleAdjustmentOptions& options,
                            bool prune = false) {
  const RigCalibration start = PerturbedStart(rig);
  const BackendRun own =
      RunFinalAdjustment(rig, start, options, prune, BundleSolverBackend::kOwn);
  const BackendRun ceres = RunFinalAdjustment(rig, start, options, prune,
                                              BundleSolverBackend::kCeres);
  ExpectSameMinimum(kind, own, ceres);
}

// F = 1/2 sum rho(|r|^2) of the radial adjustment over every inlier of the
// calibrated cameras in posed framesets (what it solves with pruning off and
// every correspondence selected).
double RadialCost(const RigDataset& dataset, const RigCalibration& calibration,
                  double loss_scale_px) {
  const ceres::CauchyLoss loss(loss_scale_px);
  double cost = 0;
  for (size_t k = 0; k < dataset.images.size(); ++k) {
    const RigImage& image = dataset.images[k];
    const int i = image.camera_index;
    const std::optional<Rigid3d>& rig_from_world =
        calibration.rig_from_world[image.frameset_index];
    if (!calibration.camera_calibrated[i] || !rig_from_world) continue;
    const PoseParams cam_from_rig = ToPoseParams(calibration.cam_from_rig[i]);
    const PoseParams rig_pose = ToPoseParams(*rig_from_world);
    const double principal_point[2] = {
        calibration.cameras[i].PrincipalPointX(),
        calibration.cameras[i].PrincipalPointY()};
    const double* blocks[] = {cam_from_rig.data(), rig_pose.data(),
                              principal_point};
    for (size_t c = 0; c < image.correspondences.size(); ++c) {
      if (!calibration.images[k].inlier_mask[c]) continue;
      double residual[2], rho[3];
      RadialRigCostFunction(image.correspondences[c].point2D,
                            image.correspondences[c].point3D)
          .Evaluate(blocks, residual, nullptr);
      loss.Evaluate(residual[0] * residual[0] + residual[1] * residual[1], rho);
      cost += 0.5 * rho[0];
    }
  }
  return cost;
}

BackendRun RunRadialAdjustment(const SyntheticRig& rig,
                               const RigCalibration& start,
                               BundleSolverBackend backend) {
  RadialBundleAdjustmentOptions options;
  options.bundle_solver = backend;
  options.num_threads = 1;
  options.max_radial_error_px = 0;
  options.max_correspondences_per_image = 0;
  options.function_tolerance = kFunctionTolerance;
  BackendRun run;
  run.calibration = start;
  RadialBundleAdjustmentSummary summary;
  EXPECT_TRUE(AdjustRadialRig(options, rig.dataset, &run.calibration, &summary))
      << summary.message;
  run.final_cost =
      RadialCost(rig.dataset, run.calibration, options.loss_scale_px);
  run.iterations = summary.num_iterations;
  run.seconds = summary.seconds;
  return run;
}

TEST(BundleSolverBackendsTest, RadialAdjustmentWithWrongMatches) {
  const SyntheticRig rig = MakeRig(RigPreset::kRing5, 0.2);
  const RigCalibration start = PerturbedStart(rig);
  ExpectSameMinimum(
      "radial BA, ring5, 20 % wrong matches",
      RunRadialAdjustment(rig, start, BundleSolverBackend::kOwn),
      RunRadialAdjustment(rig, start, BundleSolverBackend::kCeres));
}

TEST(BundleSolverBackendsTest, FinalAdjustmentPointsFixed) {
  FinalBundleAdjustmentOptions options;
  options.refine_points = false;
  CompareFinalAdjustment("final BA, points fixed, ring5 (OPENCV)",
                         MakeRig(RigPreset::kRing5, 0), options);
}

TEST(BundleSolverBackendsTest, FinalAdjustmentPointsRefined) {
  FinalBundleAdjustmentOptions options;
  options.refine_points = true;
  CompareFinalAdjustment("final BA, points refined, ring5",
                         MakeRig(RigPreset::kRing5, 0), options);
}

TEST(BundleSolverBackendsTest, FinalAdjustmentWithMapImages) {
  FinalBundleAdjustmentOptions options;
  options.refine_points = true;
  options.use_map_observations = true;
  CompareFinalAdjustment("final BA, map images (poses held), ring5",
                         MakeRig(RigPreset::kRing5, 0, 12), options);
}

TEST(BundleSolverBackendsTest, FinalAdjustmentRefineMapFreeGauge) {
  // Every rig point has a map track: nothing is held, the gauge is free,
  // and each result is anchored to the map (map_anchoring.h).
  SyntheticRig rig = MakeRig(RigPreset::kRing5, 0, 12);
  KeepCorrespondencesWithMapTracks(&rig);
  FinalBundleAdjustmentOptions options;
  options.refine_points = true;
  options.use_map_observations = true;
  options.refine_map = true;
  options.refine_map_intrinsics = true;
  CompareFinalAdjustment("final BA, refine_map + map intrinsics, free gauge",
                         rig, options);
}

TEST(BundleSolverBackendsTest, FinalAdjustmentWrongMatchesAndPruning) {
  // The Cauchy loss over 20 % wrong matches, then a pruning round: pruned
  // residual blocks inactive, points left with one observation held. The
  // first solve creeps along the loss' flat tail and stops at 1000
  // iterations in both (NO_CONVERGENCE), at the same point.
  FinalBundleAdjustmentOptions options;
  options.refine_points = true;
  options.use_map_observations = true;
  CompareFinalAdjustment("final BA, 20 % wrong matches, pruning, map images",
                         MakeRig(RigPreset::kRing5, 0.2, 12), options,
                         /*prune=*/true);
}

TEST(BundleSolverBackendsTest, FinalAdjustmentFisheye) {
  FinalBundleAdjustmentOptions options;
  options.refine_points = true;
  CompareFinalAdjustment("final BA, fisheye_helmet5 (OPENCV_FISHEYE)",
                         MakeRig(RigPreset::kFisheyeHelmet5, 0), options);
}

TEST(BundleSolverBackendsTest, FinalAdjustmentMixedModels) {
  FinalBundleAdjustmentOptions options;
  options.refine_points = true;
  CompareFinalAdjustment(
      "final BA, car_surround4 (OPENCV, OPENCV_FISHEYE, RADIAL)",
      MakeRig(RigPreset::kCarSurround4, 0), options);
}

TEST(BundleSolverBackendsTest, FinalAdjustmentSimpleRadial) {
  SyntheticRig rig = MakeRig(RigPreset::kRing5, 0);
  ChangeCameraModel("SIMPLE_RADIAL", 0.5, &rig);
  FinalBundleAdjustmentOptions options;
  options.refine_points = true;
  CompareFinalAdjustment("final BA, ring5 as SIMPLE_RADIAL", rig, options);
}

TEST(BundleSolverBackendsTest, FinalAdjustmentPinhole) {
  SyntheticRig rig = MakeRig(RigPreset::kRing5, 0);
  ChangeCameraModel("PINHOLE", 0.5, &rig);
  FinalBundleAdjustmentOptions options;
  options.refine_points = true;
  CompareFinalAdjustment("final BA, ring5 as PINHOLE", rig, options);
}

TEST(BundleSolverBackendsTest, FinalAdjustmentTimeModel) {
  // ring5 at 15 Hz with capture-time offsets in +-50 ms and line delays of
  // 20-30 us per row; the offsets start 2 ms off, the line delays 10 % (the
  // rest as every test here: the truth perturbed).
  SyntheticRigOptions rig_options;
  rig_options.preset = RigPreset::kRing5;
  rig_options.num_framesets = 12;
  rig_options.points_per_image = 60;
  rig_options.noise_px = 0.5;
  rig_options.outlier_ratio = 0;
  rig_options.missing_image_ratio = 0.1;
  rig_options.frameset_rate_hz = 15;
  rig_options.max_time_offset_s = 0.05;
  rig_options.min_line_delay_s = 20e-6;
  rig_options.max_line_delay_s = 30e-6;
  rig_options.seed = 7;
  const SyntheticRig rig = GenerateSyntheticRig(rig_options);
  // Points held: at 15 Hz consecutive framesets see a point from nearly the
  // same place, and such points creep along their rays for 1000 iterations
  // in both backends.
  FinalBundleAdjustmentOptions options;
  options.refine_points = false;
  options.estimate_time_offsets = true;
  options.estimate_line_delays = true;
  for (size_t c = 0; c < rig.truth.time_offsets_s.size(); ++c) {
    options.initial_time_offsets_s.push_back(
        c == 0 ? 0.0 : rig.truth.time_offsets_s[c] + 2e-3);
    options.initial_line_delays_s.push_back(0.9 * rig.truth.line_delays_s[c]);
  }
  CompareFinalAdjustment("final BA, time model (offsets, line delays), ring5",
                         rig, options);
}

// The comparison can fail: a Ceres solve stopped after 2 iterations is
// beyond both bounds.
TEST(BundleSolverBackendsTest, UnconvergedSolveIsDetected) {
  const SyntheticRig rig = MakeRig(RigPreset::kRing5, 0);
  const RigCalibration start = PerturbedStart(rig);
  FinalBundleAdjustmentOptions options;
  const BackendRun own =
      RunFinalAdjustment(rig, start, options, false, BundleSolverBackend::kOwn);
  options.bundle_solver = BundleSolverBackend::kCeres;
  options.num_threads = 1;
  options.max_num_iterations = 2;
  RigAdjustment adjustment(options, rig.dataset, start);
  adjustment.RejectOutliers(/*prune_residuals=*/false);
  BundleSolverSummary summary;
  ASSERT_TRUE(adjustment.Solve(kFunctionTolerance, &summary));
  EXPECT_EQ(summary.termination,
            BundleSolverSummary::Termination::kNoConvergence);
  RigCalibration stopped = start;
  adjustment.WriteTo(&stopped);
  EXPECT_GT(std::abs(own.final_cost / summary.final_cost - 1),
            kMaxCostRelativeDifference);
  EXPECT_GT(Compare(own.calibration, stopped).value, kMaxParameterDifference);
}

}  // namespace bundle_solver_backends_test
}  // namespace rig_calibrator
