#include "colmap_ext/benchmarks/colmap_rig_ba_comparison.h"

#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace rig_calibrator {
namespace colmap_rig_ba_comparison_test {

// What COLMAP 3.8 rig_bundle_adjuster prints (src/exe/sfm.cc and
// PrintSolverSummary), shortened.
const char kColmapOutput[] = R"(
==============================================================================
Camera rig configuration
==============================================================================

Camera Rig 1
------------------------------------------------------------------------------
Cameras: 5
Snapshots: 9

==============================================================================
Rig bundle adjustment
==============================================================================

iter      cost      cost_change  |gradient|   |step|    tr_ratio  tr_radius  ls_iter  iter_time  total_time
   0  4.123e+04    0.00e+00    1.2e+06   0.00e+00   0.00e+00  1.00e+04        0    1.2e-02    2.1e-02
   1  1.321e+03    3.99e+04    2.3e+04   1.1e+00   9.9e-01  3.00e+04        1    2.2e-02    4.3e-02

Rig Bundle adjustment report
------------------------------------------------------------------------------
    Residuals : 26418
   Parameters : 14017
   Iterations : 7
         Time : 0.218513 [s]
 Initial cost : 1.24921 [px]
   Final cost : 0.353612 [px]
  Termination : Convergence

)";

TEST(ParseColmapSolverSummary, ReadsEveryField) {
  ColmapSolverSummary summary;
  std::string error;
  ASSERT_TRUE(ParseColmapSolverSummary(kColmapOutput, &summary, &error))
      << error;
  EXPECT_EQ(summary.num_residuals, 26418);
  EXPECT_EQ(summary.num_iterations, 7);
  EXPECT_DOUBLE_EQ(summary.seconds, 0.218513);
  EXPECT_DOUBLE_EQ(summary.initial_cost_px, 1.24921);
  EXPECT_DOUBLE_EQ(summary.final_cost_px, 0.353612);
  EXPECT_EQ(summary.termination, "Convergence");
  EXPECT_EQ(summary.num_snapshots, 9);
}

TEST(ParseColmapSolverSummary, TakesTheLastReport) {
  std::string text = kColmapOutput;
  text +=
      "Rig Bundle adjustment report\n   Residuals : 10\n"
      "  Iterations : 3\n        Time : 1.5 [s]\n"
      "Initial cost : 2 [px]\n  Final cost : 1 [px]\n"
      " Termination : No convergence\n";
  ColmapSolverSummary summary;
  std::string error;
  ASSERT_TRUE(ParseColmapSolverSummary(text, &summary, &error)) << error;
  EXPECT_EQ(summary.num_residuals, 10);
  EXPECT_EQ(summary.num_iterations, 3);
  EXPECT_DOUBLE_EQ(summary.seconds, 1.5);
  EXPECT_EQ(summary.termination, "No convergence");
}

TEST(ParseColmapSolverSummary, NamesTheMissingField) {
  std::string text = kColmapOutput;
  text.erase(text.find("         Time"),
             text.find(" Initial") - text.find("         Time"));
  ColmapSolverSummary summary;
  std::string error;
  EXPECT_FALSE(ParseColmapSolverSummary(text, &summary, &error));
  EXPECT_NE(error.find("Time"), std::string::npos) << error;
  EXPECT_FALSE(ParseColmapSolverSummary("no report here", &summary, &error));
}

// A pinhole camera f = 100, c = (50, 50) at the origin looking along z.
ModelView OneCameraView() {
  ModelView view;
  colmap::Camera camera;
  camera.InitializeWithName("PINHOLE", 100.0, 100, 100);
  view.image_cameras = {camera, camera};
  view.image_cam_from_world = {
      Rigid3d(),
      Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-1, 0, 0))};
  view.points3D[7] = Eigen::Vector3d(0, 0, 10);
  view.points3D[8] = Eigen::Vector3d(1, 0, 10);
  return view;
}

TEST(RmsReprojectionError, IsTheRootMeanSquareOverObservations) {
  const ModelView view = OneCameraView();
  // Exact: (50, 50) and, in image 1, point 8 at x = 0 -> (50, 50).
  std::vector<ObservedPoint> observations = {{0, 7, Eigen::Vector2d(50, 50)},
                                             {1, 8, Eigen::Vector2d(50, 50)}};
  EXPECT_NEAR(RmsReprojectionError(observations, view).rms_px, 0, 1e-12);
  // Errors of 3-4-5 and 1 px: sqrt((25 + 1) / 2).
  observations[0].point2D = Eigen::Vector2d(53, 54);
  observations[1].point2D = Eigen::Vector2d(50, 49);
  EXPECT_NEAR(RmsReprojectionError(observations, view).rms_px, std::sqrt(13.0),
              1e-12);
  // Point 8 in image 0: x = 100 * 1 / 10 + 50 = 60.
  observations.push_back({0, 8, Eigen::Vector2d(60, 50)});
  const ReprojectionRms rms = RmsReprojectionError(observations, view);
  EXPECT_NEAR(rms.rms_px, std::sqrt(26.0 / 3), 1e-12);
  EXPECT_EQ(rms.num_used, 3);
  EXPECT_EQ(rms.num_unusable, 0);
  EXPECT_EQ(RmsReprojectionError({}, view).rms_px, 0);
}

TEST(RmsReprojectionError, CountsUnusableObservationsApart) {
  ModelView view = OneCameraView();
  // An unknown point, an unknown image, then point 7 behind the camera; the
  // one usable observation is 2 px off.
  std::vector<ObservedPoint> observations = {{0, 9, Eigen::Vector2d(50, 50)},
                                             {2, 7, Eigen::Vector2d(50, 50)},
                                             {1, 8, Eigen::Vector2d(52, 50)}};
  ReprojectionRms rms = RmsReprojectionError(observations, view);
  EXPECT_EQ(rms.num_unusable, 2);
  EXPECT_EQ(rms.num_used, 1);
  EXPECT_NEAR(rms.rms_px, 2, 1e-12);
  view.points3D[7].z() = -10;
  rms = RmsReprojectionError({{0, 7, Eigen::Vector2d(50, 50)}}, view);
  EXPECT_EQ(rms.num_unusable, 1);
  EXPECT_EQ(rms.rms_px, 0);
}

TEST(RunColmapRigBaComparison, NamesTheBadOption) {
  ColmapRigBaComparisonOptions options;
  options.output_path = ::testing::TempDir() + "/colmap_rig_ba_bad_options";
  std::string error;
  options.framesets = "10,x";
  EXPECT_FALSE(RunColmapRigBaComparison(options, &error));
  EXPECT_NE(error.find("--framesets"), std::string::npos) << error;
  options.framesets = "10";
  options.colmap_executable = "/nonexistent/colmap";
  EXPECT_FALSE(RunColmapRigBaComparison(options, &error));
  EXPECT_NE(error.find("--colmap_executable: /nonexistent/colmap"),
            std::string::npos)
      << error;
}

}  // namespace colmap_rig_ba_comparison_test
}  // namespace rig_calibrator
