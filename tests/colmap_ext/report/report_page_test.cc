// report.html from real output folders (the model writer's scene): residuals
// recomputed from the model, every section filled from issue 12's contract
// keys or "not computed" without them, written inside the atomic output,
// and its size for a 10-camera, 500-frameset calibration.
#include "colmap_ext/report/report_page.h"

#include <gtest/gtest.h>

#include <boost/filesystem.hpp>
#include <cmath>
#include <fstream>
#include <iostream>
#include <regex>

#include "colmap_ext/io/correspondence_io.h"
#include "colmap_ext/report/model_residuals.h"
#include "tests/colmap_ext/report/report_testing.h"

namespace rig_calibrator {
namespace report_page_test {

using testing::MakeScene;
using testing::ReadBytes;
using testing::Scene;
using testing::ScopedTempDir;
using testing::WriteSceneOutput;

size_t Count(const std::string& text, const std::string& what) {
  size_t count = 0;
  for (size_t at = text.find(what); at != std::string::npos;
       at = text.find(what, at + 1)) {
    ++count;
  }
  return count;
}

std::vector<ReportCamera> SceneCameras() {
  return {{"cam0", "cam0/"}, {"cam1", "cam1/"}, {"cam2", "cam2/"}};
}

TEST(ModelResiduals, ExactModelGivesZeroAndAShiftedObservationShows) {
  const Scene scene = MakeScene();
  ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::string error;
  ASSERT_TRUE(WriteSceneOutput(scene, output, false, &error)) << error;
  ReportInputs inputs;
  ASSERT_TRUE(ReadReportInputs(output, &inputs, &error)) << error;
  ASSERT_TRUE(inputs.rigs_frames.has_value());
  ModelResiduals residuals = ComputeModelResiduals(
      inputs.model, inputs.rigs_frames, SceneCameras(), 16, {});
  ASSERT_EQ(residuals.cameras.size(), 3u);
  int64_t num_observations = 0;
  for (const CameraResiduals& camera : residuals.cameras) {
    EXPECT_FALSE(camera.from_correspondences);
    EXPECT_LT(camera.rms_px, 1e-9);
    EXPECT_EQ(camera.cols, 16);
    EXPECT_EQ(camera.rows, 12);  // 16 * 480 / 640
    num_observations += camera.num_observations;
  }
  EXPECT_EQ(num_observations, scene.num_observations);
  EXPECT_EQ(static_cast<int>(residuals.images.size()), scene.num_registered);
  // Frameset 3 has no rig pose; in frameset 1 cam2's image is not used.
  ASSERT_EQ(residuals.framesets.size(), 3u);
  EXPECT_EQ(residuals.framesets[1].name, "1.png");
  EXPECT_TRUE(std::isnan(residuals.framesets[1].camera_rms_px[2]));
  EXPECT_FALSE(std::isnan(residuals.framesets[1].camera_rms_px[1]));

  // One observation of cam1 in frameset 2 moved by (3, 4) px: that image's
  // RMS is 5 / sqrt(n), its frameset's 5 / sqrt(N), its cell's mean (3, 4).
  colmap::Image* moved = nullptr;
  for (const colmap::image_t image_id : inputs.model.RegImageIds()) {
    if (inputs.model.Image(image_id).Name() == "cam1/2.png") {
      moved = &inputs.model.Image(image_id);
    }
  }
  ASSERT_NE(moved, nullptr);
  colmap::point2D_t moved_index = 0;
  while (!moved->Point2D(moved_index).HasPoint3D()) ++moved_index;
  Eigen::Vector2d& xy = moved->Point2D(moved_index).XY();
  xy += Eigen::Vector2d(3, 4);
  const Eigen::Vector2d moved_xy = xy;
  residuals = ComputeModelResiduals(inputs.model, inputs.rigs_frames,
                                    SceneCameras(), 16, {});
  for (const ImageError& image : residuals.images) {
    const double expected =
        image.name == "cam1/2.png" ? 5 / std::sqrt(image.num_observations) : 0;
    EXPECT_NEAR(image.rms_px, expected, 1e-9) << image.name;
  }
  const FramesetError& frameset = residuals.framesets[2];
  EXPECT_NEAR(frameset.rms_px, 5 / std::sqrt(frameset.num_observations), 1e-9);
  const CameraResiduals& camera = residuals.cameras[1];
  EXPECT_NEAR(camera.max_error_px, 5, 1e-9);
  const int col = static_cast<int>(moved_xy.x() / 640 * 16);
  const int row = static_cast<int>(moved_xy.y() / 480 * 12);
  const ResidualCell& cell = camera.cells[row * 16 + col];
  EXPECT_NEAR(cell.sum_dx, 3, 1e-9);
  EXPECT_NEAR(cell.sum_dy, 4, 1e-9);
  EXPECT_NEAR(cell.sum_squared, 25, 1e-9);
}

// Without a map the model has no 3D points: the residuals come from
// correspondences.txt, and a row 100 px off is left out as an outlier.
TEST(ModelResiduals, WithoutMapPointsTheCorrespondenceRowsAreUsed) {
  Scene scene = MakeScene();
  scene.map = colmap::Reconstruction();
  for (RigImage& image : scene.dataset.images) {
    for (Correspondence& correspondence : image.correspondences) {
      correspondence.point3D_id = -1;
    }
  }
  ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::string error;
  ASSERT_TRUE(WriteSceneOutput(scene, output, false, &error)) << error;
  ReportInputs inputs;
  ASSERT_TRUE(ReadReportInputs(output, &inputs, &error)) << error;
  ASSERT_EQ(inputs.model.NumPoints3D(), 0u);
  ASSERT_FALSE(inputs.correspondences.empty());
  for (ImageCorrespondences& rows : inputs.correspondences) {
    if (rows.image_name == "cam0/0.png") {
      rows.correspondences[0].point2D += Eigen::Vector2d(100, 0);
    }
  }
  const ModelResiduals residuals =
      ComputeModelResiduals(inputs.model, inputs.rigs_frames, SceneCameras(),
                            16, inputs.correspondences);
  for (const CameraResiduals& camera : residuals.cameras) {
    EXPECT_TRUE(camera.from_correspondences);
    EXPECT_DOUBLE_EQ(camera.inlier_threshold_px, 0.01);
    EXPECT_LT(camera.rms_px, 1e-9);
  }
  for (const ImageError& image : residuals.images) {
    // 22 rows per image (the unknown point and the repeated one included),
    // one of them the outlier in cam0/0.png.
    EXPECT_EQ(image.num_observations, image.name == "cam0/0.png" ? 21 : 22)
        << image.name;
  }
}

std::string BuildPage(const std::string& folder) {
  ReportInputs inputs;
  std::string error, html;
  EXPECT_TRUE(ReadReportInputs(folder, &inputs, &error)) << error;
  EXPECT_TRUE(BuildReportHtml(inputs, &html, &error)) << error;
  return html;
}

const char* const kSections[] = {
    "overview",     "parameters",  "intrinsics-table", "poses-table",
    "model-choice", "diagnostics", "diagnostics-list", "validity-table",
    "cameras",      "rig",         "framesets",        "worst-framesets",
    "worst-images", "camchain"};

TEST(ReportPage, WithoutTheContractKeysSaysNotComputed) {
  const Scene scene = MakeScene();
  ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::string error;
  ASSERT_TRUE(WriteSceneOutput(scene, output, false, &error)) << error;
  const std::string html = BuildPage(output);
  for (const char* section : kSections) {
    EXPECT_NE(html.find("id=\"" + std::string(section) + "\""),
              std::string::npos)
        << section;
  }
  for (int c = 0; c < 3; ++c) {
    const std::string i = std::to_string(c);
    for (const std::string figure :
         {"residuals-", "coverage-", "distortion-"}) {
      EXPECT_NE(html.find("<svg id=\"" + figure + i + "\""), std::string::npos)
          << figure << i;
    }
    // No uncertainty: its figure is a note.
    EXPECT_NE(html.find("<figure id=\"fig-uncertainty-" + i +
                        "\" class=\"missing\">"),
              std::string::npos);
  }
  for (const char* reason :
       {"no &quot;uncertainty&quot;", "no &quot;validity&quot; in the summary",
        "no camera has &quot;model_choice&quot;",
        "no &quot;refined&quot; in the summary",
        "no &quot;uncertainty.projection_stddev_px.grid&quot;",
        "no &quot;coverage&quot; in the summary",
        "not computed (no &quot;center_in_rig_stddev&quot;)"}) {
    EXPECT_NE(html.find(reason), std::string::npos) << reason;
  }
  // The summary writer's own word for an uncertainty it did not compute.
  EXPECT_NE(html.find("<th>uncertainty method</th><td>not computed</td>"),
            std::string::npos);
  // No camera has a timing: no timing section, no link to it.
  EXPECT_EQ(html.find("id=\"timing\""), std::string::npos);
  EXPECT_EQ(html.find("#timing"), std::string::npos);
  // 3 x (residuals, coverage, distortion) + 2 rig views + framesets.
  EXPECT_NE(html.find("data-expected-figures=\"12\""), std::string::npos);
  // The diagnostics of the summary, by level.
  EXPECT_NE(html.find("<li class=\"warning\"><b>warning</b> "
                      "parallel_principal_axes: a warning</li>"),
            std::string::npos);
}

TEST(ReportPage, TheContractKeysFillEverySection) {
  const Scene scene = MakeScene();
  ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::string error;
  ASSERT_TRUE(WriteSceneOutput(scene, output, false, &error)) << error;
  testing::MergeContractKeys(output);
  const std::string html = BuildPage(output);
  EXPECT_EQ(html.find("not computed"), std::string::npos);
  // 15 + the time offsets and line delays of the cameras' "timing".
  EXPECT_NE(html.find("data-expected-figures=\"17\""), std::string::npos);
  for (int c = 0; c < 3; ++c) {
    const std::string i = std::to_string(c);
    for (const std::string figure :
         {"residuals-", "coverage-", "uncertainty-", "distortion-"}) {
      EXPECT_NE(html.find("<svg id=\"" + figure + i + "\""), std::string::npos)
          << figure << i;
    }
  }
  // Parameters with sigma (OPENCV_FISHEYE fx of cam0: 300 +- 0.19), refined
  // switches, the pose sigmas, the model choice, the validity, the coverage
  // and projection numbers, the ellipses (4 mm at the rig's scale).
  for (const char* text :
       {"<td>fx 300 \u00b1 0.19<br/>fy 301 \u00b1 0.2</td>",
        "principal_point: no (held)", "\u00b1 0.012", "\u00b1 0.006",
        "<b class=\"chosen\">OPENCV_FISHEYE \u2714</b>", "lowest held-out RMS",
        "<b class=\"bad\">no</b>", "OPENCV_FISHEYE</td>",
        "the distortion folds back at 402 px",
        "From &quot;coverage&quot;: 75 %", "median 0.31 px, max 0.9 px",
        "<ellipse ", "Gauss-Newton covariance",
        "<li class=\"error\"><b>error</b> invalid_camera_model: cam1",
        "a diagnostic &lt;with&gt; markup &amp; quotes &quot;",
        "<section id=\"timing\">", "<a href=\"#timing\">timing</a>",
        "<svg id=\"time-offsets\"",
        "<svg id=\"line-delays\"",
        "<text class=\"value\" x=\"480\" y=\"58.0\">+12.30 \u00b1 0.40 ms</text>",
        "+29.00 \u00b1 0.40 us/row</text>",
        "Source: estimated in the adjustment."}) {
    EXPECT_NE(html.find(text), std::string::npos) << text;
  }
  EXPECT_EQ(Count(html, "<b class=\"chosen\">"), 3u);
}

// Offsets measured after the calibration (capture_timing.h): one figure,
// the offsets with their sigma, the reference's 0, and a caption saying they
// are lower bounds; no line-delay figure without line delays.
TEST(ReportPage, MeasuredTimeOffsetsAreShownAsLowerBounds) {
  const Scene scene = MakeScene();
  ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::string error;
  ASSERT_TRUE(WriteSceneOutput(scene, output, false, &error)) << error;
  const std::string path = output + "/" + kSummaryFile;
  nlohmann::ordered_json summary = testing::ReadJsonFile(path);
  summary["cameras"][0]["timing"] = {{"time_offset_s", 0.0},
                                     {"time_offset_sigma_s", 0.0},
                                     {"source", "measured after calibration"}};
  summary["cameras"][2]["timing"] = {{"time_offset_s", -0.04815},
                                     {"time_offset_sigma_s", 0.00031},
                                     {"source", "measured after calibration"}};
  std::ofstream(path) << summary.dump(2) << "\n";
  const std::string html = BuildPage(output);
  EXPECT_NE(html.find("<svg id=\"time-offsets\""), std::string::npos);
  EXPECT_EQ(html.find("line-delays"), std::string::npos);
  for (const char* text :
       {">+0.00 \u00b1 0.00 ms</text>", ">-48.15 \u00b1 0.31 ms</text>",
        "against cam0", "lower bounds of the true ones"}) {
    EXPECT_NE(html.find(text), std::string::npos) << text;
  }
  EXPECT_EQ(Count(html, "<text class=\"value\""), 2u);
  EXPECT_NE(html.find("data-expected-figures=\"13\""), std::string::npos);
}

TEST(ReportPage, IsWrittenInsideTheOutputAndRebuiltIdentically) {
  const Scene scene = MakeScene();
  ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::string error;
  ASSERT_TRUE(WriteSceneOutput(scene, output, true, &error)) << error;
  const std::string written = ReadBytes(output + "/" + kReportFile);
  ASSERT_FALSE(written.empty());
  // Nothing of the temporary folder's name, and no wall times.
  EXPECT_EQ(written.find(".out.tmp"), std::string::npos);
  EXPECT_EQ(written.find("timings"), std::string::npos);
  const auto before = testing::SnapshotFolder(output);
  ASSERT_TRUE(WriteReportHtml(output, &error)) << error;
  EXPECT_EQ(testing::SnapshotFolder(output), before);
  EXPECT_EQ(testing::ListFolder(dir.path()), std::set<std::string>{"out"});
}

TEST(ReportPage, AFailingReportLeavesNoOutput) {
  const Scene scene = MakeScene();
  ScopedTempDir dir;
  const std::string output = dir.File("out");
  CalibrationSummary summary =
      SummarizeCalibration(scene.dataset, scene.calibration, {});
  RigOutputOptions options;
  options.finish_folder = [](const std::string&, std::string* error) {
    *error = "report failed";
    return false;
  };
  std::string error;
  EXPECT_FALSE(WriteRigOutput(output, scene.map, scene.dataset,
                              scene.calibration, {}, summary, options, nullptr,
                              &error));
  EXPECT_EQ(error, "report failed");
  EXPECT_TRUE(testing::ListFolder(dir.path()).empty());
}

TEST(ReportPage, BadFoldersGiveMessagesNamingTheFile) {
  ScopedTempDir dir;
  std::string error;
  EXPECT_FALSE(WriteReportHtml(dir.File("none"), &error));
  EXPECT_NE(error.find("no calibration output folder at " + dir.File("none")),
            std::string::npos)
      << error;
  EXPECT_FALSE(WriteReportHtml(dir.path(), &error));
  EXPECT_NE(error.find("cannot read " + dir.File(kSummaryFile)),
            std::string::npos)
      << error;
  std::ofstream(dir.File(kSummaryFile)) << "{\"cameras\": [";
  EXPECT_FALSE(WriteReportHtml(dir.path(), &error));
  EXPECT_EQ(error, dir.File(kSummaryFile) + " is not valid JSON");
  std::ofstream(dir.File(kSummaryFile)) << "{\"method\": \"1dr\"}";
  EXPECT_FALSE(WriteReportHtml(dir.path(), &error));
  EXPECT_EQ(error, dir.File(kSummaryFile) + " has no \"cameras\" array");
  std::ofstream(dir.File(kSummaryFile)) << "{\"cameras\": []}";
  EXPECT_FALSE(WriteReportHtml(dir.path(), &error));
  EXPECT_NE(error.find("cannot read the COLMAP model in " + dir.path()),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("has no cameras.txt"), std::string::npos) << error;
  EXPECT_FALSE(boost::filesystem::exists(dir.File(kReportFile)));

  // A summary with values of the wrong types is reported, not a crash.
  const Scene scene = MakeScene();
  const std::string output = dir.File("out");
  ASSERT_TRUE(WriteSceneOutput(scene, output, false, &error)) << error;
  auto summary = testing::ReadJsonFile(output + "/" + kSummaryFile);
  summary["cameras"][0]["params"] = "fx";
  summary["cameras"][1]["uncertainty"] = {{"params_stddev", {"a", "b"}},
                                          {"center_in_rig_stddev", 3}};
  summary["cameras"][2]["coverage"] = {{"grid", {{"cols", 2}, {"rows", 2}}}};
  summary["diagnostics"] = {1, 2};
  std::ofstream(output + "/" + kSummaryFile) << summary.dump();
  EXPECT_TRUE(WriteReportHtml(output, &error)) << error;
}

// 10 cameras, 500 framesets, 20 observations per image: the page's size
// depends on the cameras and framesets, not on the observations.
TEST(ReportPage, SizeForTenCamerasAndFiveHundredFramesets) {
  std::mt19937 random(3);
  Scene scene;
  const std::vector<Eigen::Vector3d> points = testing::MakeMap(&random, &scene);
  constexpr int kNumCameras = 10, kNumFramesets = 500;
  for (int c = 0; c < kNumCameras; ++c) {
    RigCamera camera;
    camera.name = "cam" + std::to_string(c);
    camera.camera = testing::MakeCamera(
        "OPENCV", {500, 502, 321, 239, -0.1, 0.01, 1e-4, -1e-4});
    scene.dataset.cameras.push_back(camera);
    scene.calibration.cameras.push_back(camera.camera);
    scene.calibration.cam_from_rig.push_back(
        c == 0 ? Rigid3d() : testing::SmallPose(&random, 0.2, 0.3));
    scene.calibration.camera_calibrated.push_back(true);
  }
  for (int f = 0; f < kNumFramesets; ++f) {
    scene.dataset.frameset_names.push_back(std::to_string(f) + ".png");
    scene.calibration.rig_from_world.push_back(
        testing::SmallPose(&random, 0.1, 1.0));
    for (int c = 0; c < kNumCameras; ++c) {
      RigImage image;
      image.name = "cam" + std::to_string(c) + "/" + std::to_string(f) + ".png";
      image.camera_index = c;
      image.frameset_index = f;
      ImageResult result;
      result.localized = result.used = true;
      for (int k = 0; k < 20; ++k) {
        const int point = (7 * f + 3 * c + k) % testing::kNumMapPoints;
        Correspondence correspondence;
        correspondence.point3D = points[point];
        correspondence.point2D = testing::Project(
            scene.calibration.cameras[c], scene.calibration.CamFromWorld(c, f),
            points[point]);
        correspondence.point3D_id = point + 1;
        image.correspondences.push_back(correspondence);
        result.inlier_mask.push_back(true);
      }
      result.num_inliers = 20;
      scene.dataset.images.push_back(image);
      scene.calibration.images.push_back(result);
    }
  }
  ScopedTempDir dir;
  const std::string output = dir.File("out");
  std::string error;
  ASSERT_TRUE(WriteSceneOutput(scene, output, true, &error)) << error;
  testing::MergeContractKeys(output);
  ASSERT_TRUE(WriteReportHtml(output, &error)) << error;
  const size_t size = ReadBytes(output + "/" + kReportFile).size();
  std::cout << "report.html of 10 cameras x 500 framesets (100 000 "
               "observations), every section filled: "
            << size << " bytes" << std::endl;
  EXPECT_LT(size, 1500000u);
}

}  // namespace report_page_test
}  // namespace rig_calibrator
