#include "colmap_ext/benchmarks/runtime_benchmark.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

namespace rig_calibrator {
namespace runtime_benchmark_test {

CalibrationRuntime MakeRun(int num_framesets, int num_cameras,
                           double cpu_seconds) {
  CalibrationRuntime run;
  run.num_framesets = num_framesets;
  run.num_cameras = num_cameras;
  run.num_images = num_framesets * num_cameras;
  run.num_correspondences = 300L * run.num_images;
  run.generation_seconds = 0.25;
  run.stages = {
      {"Single-image localization", 0.5, 0.9, 0},
      {"Final bundle adjustment", cpu_seconds / 3, cpu_seconds / 2, 17}};
  run.seconds = cpu_seconds / 1.5;
  run.cpu_seconds = cpu_seconds;
  run.peak_memory_mb = 123.4;
  run.success = true;
  run.final_rms_px = 0.705;
  run.max_rotation_error_deg = 0.02;
  run.max_center_error_m = 0.0005;
  return run;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream stream(text);
  std::string line;
  while (std::getline(stream, line)) lines.push_back(line);
  return lines;
}

TEST(RuntimeBenchmark, MedianOfRepeatsPerStage) {
  std::vector<CalibrationRuntime> runs = {MakeRun(10, 5, 30), MakeRun(10, 5, 9),
                                          MakeRun(10, 5, 12)};
  runs[1].peak_memory_mb = 200;
  runs[2].stages[0].seconds = 0.1;  // localization fastest in another run
  const CalibrationRuntime median = MedianCalibrationRuntime(runs);
  ASSERT_TRUE(median.success);
  EXPECT_DOUBLE_EQ(median.cpu_seconds, 12);
  EXPECT_DOUBLE_EQ(median.seconds, 12 / 1.5);
  ASSERT_EQ(median.stages.size(), 2u);
  EXPECT_DOUBLE_EQ(median.stages[0].seconds, 0.5);
  EXPECT_DOUBLE_EQ(median.stages[1].seconds, 12.0 / 3);
  EXPECT_DOUBLE_EQ(median.stages[1].cpu_seconds, 12.0 / 2);
  EXPECT_EQ(median.stages[1].num_iterations, 17);
  EXPECT_DOUBLE_EQ(median.peak_memory_mb, 200);
  // An even count: the mean of the middle two.
  runs.pop_back();
  EXPECT_DOUBLE_EQ(MedianCalibrationRuntime(runs).cpu_seconds, (30 + 9) / 2.0);
  // A failed run stands for all.
  runs[1].success = false;
  runs[1].error = "diverged";
  EXPECT_FALSE(MedianCalibrationRuntime(runs).success);
  EXPECT_EQ(MedianCalibrationRuntime(runs).error, "diverged");
}

TEST(RuntimeBenchmark, CalibrationRuntimeRoundTrips) {
  CalibrationRuntime run = MakeRun(500, 10, 41.5);
  run.success = false;
  run.error = "the radial rig initialization failed:\nno seed";
  CalibrationRuntime parsed;
  std::string error;
  ASSERT_TRUE(ParseCalibrationRuntime(SerializeCalibrationRuntime(run), &parsed,
                                      &error))
      << error;
  EXPECT_EQ(parsed.num_framesets, 500);
  EXPECT_EQ(parsed.num_cameras, 10);
  EXPECT_EQ(parsed.num_images, 5000);
  EXPECT_EQ(parsed.num_correspondences, 1500000);
  EXPECT_DOUBLE_EQ(parsed.cpu_seconds, 41.5);
  EXPECT_NEAR(parsed.seconds, 41.5 / 1.5, 1e-8);
  EXPECT_FALSE(parsed.success);
  // The message stays on one line.
  EXPECT_EQ(parsed.error, "the radial rig initialization failed: no seed");
  EXPECT_DOUBLE_EQ(parsed.generation_seconds, 0.25);
  EXPECT_DOUBLE_EQ(parsed.final_rms_px, 0.705);
  EXPECT_DOUBLE_EQ(parsed.max_rotation_error_deg, 0.02);
  EXPECT_DOUBLE_EQ(parsed.max_center_error_m, 0.0005);
  ASSERT_EQ(parsed.stages.size(), 2u);
  EXPECT_EQ(parsed.stages[0].stage, "Single-image localization");
  EXPECT_DOUBLE_EQ(parsed.stages[0].seconds, 0.5);
  EXPECT_DOUBLE_EQ(parsed.stages[0].cpu_seconds, 0.9);
  EXPECT_EQ(parsed.stages[1].stage, "Final bundle adjustment");
  EXPECT_NEAR(parsed.stages[1].seconds, 41.5 / 3, 1e-8);
  EXPECT_NEAR(parsed.stages[1].cpu_seconds, 41.5 / 2, 1e-8);
  EXPECT_EQ(parsed.stages[1].num_iterations, 17);

  EXPECT_FALSE(ParseCalibrationRuntime("something else\n", &parsed, &error));
  EXPECT_NE(error.find("header"), std::string::npos);
  std::string text = SerializeCalibrationRuntime(run);
  text.replace(text.find("cpu_seconds 41.5"), 16, "cpu_seconds x");
  EXPECT_FALSE(ParseCalibrationRuntime(text, &parsed, &error));
  EXPECT_NE(error.find("cpu_seconds"), std::string::npos);
}

TEST(RuntimeBenchmark, LocalizationRuntimeRoundTrips) {
  LocalizationRuntime run;
  run.mode = "direct";
  run.num_map_images = 300;
  run.num_map_points = 90000;
  run.num_indexed_descriptors = 360000;
  run.features_per_rig_image = 2000;
  run.num_checks = 64;
  run.num_images = 40;
  run.index_seconds = 3.5;
  run.seconds = 5;
  run.cpu_seconds = 9.5;
  run.recall = 0.97;
  run.precision = 0.99;
  run.radial_pose_seconds_per_image = 0.002;
  run.num_poses_correct = 39;
  run.index_cpu_seconds = 6.25;
  LocalizationRuntime parsed;
  std::string error;
  ASSERT_TRUE(ParseLocalizationRuntime(SerializeLocalizationRuntime(run),
                                       &parsed, &error))
      << error;
  EXPECT_EQ(parsed.mode, "direct");
  EXPECT_EQ(parsed.num_map_images, 300);
  EXPECT_EQ(parsed.num_map_points, 90000);
  EXPECT_EQ(parsed.num_indexed_descriptors, 360000);
  EXPECT_EQ(parsed.features_per_rig_image, 2000);
  EXPECT_EQ(parsed.num_checks, 64);
  EXPECT_EQ(parsed.num_images, 40);
  EXPECT_DOUBLE_EQ(parsed.index_seconds, 3.5);
  EXPECT_DOUBLE_EQ(parsed.index_cpu_seconds, 6.25);
  EXPECT_DOUBLE_EQ(parsed.seconds, 5);
  EXPECT_DOUBLE_EQ(parsed.cpu_seconds, 9.5);
  EXPECT_DOUBLE_EQ(parsed.recall, 0.97);
  EXPECT_DOUBLE_EQ(parsed.precision, 0.99);
  EXPECT_DOUBLE_EQ(parsed.radial_pose_seconds_per_image, 0.002);
  EXPECT_EQ(parsed.num_poses_correct, 39);
  EXPECT_DOUBLE_EQ(parsed.ImagesPerSecond(), 8.0);
  EXPECT_FALSE(ParseLocalizationRuntime(
      SerializeCalibrationRuntime(MakeRun(10, 5, 1)), &parsed, &error));
}

TEST(RuntimeBenchmark, CsvHasThreeColumnsPerStageAndOneRowPerRun) {
  std::vector<CalibrationRuntime> runs = {MakeRun(10, 5, 1.0),
                                          MakeRun(50, 5, 5.0)};
  // A fallback run has an extra stage: a column for it, empty elsewhere.
  runs[1].stages.push_back({"Rig initialization", 0.125, 0.25, 0});
  const std::vector<std::string> lines = Lines(CalibrationRuntimeCsv(runs));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].rfind("framesets,cameras,images,correspondences,success,"
                           "\"Single-image localization wall s\"",
                           0),
            0u);
  EXPECT_NE(lines[0].find("\"Rig initialization CPU s\""), std::string::npos);
  EXPECT_NE(lines[0].find("\"Final bundle adjustment iterations\""),
            std::string::npos);
  const auto count_commas = [](const std::string& line) {
    return std::count(line.begin(), line.end(), ',');
  };
  EXPECT_EQ(count_commas(lines[1]), count_commas(lines[0]));
  EXPECT_EQ(count_commas(lines[2]), count_commas(lines[0]));
  EXPECT_EQ(lines[1].rfind("10,5,50,15000,1,0.500,0.900,0,0.333,0.500,17,", 0),
            0u);
  EXPECT_NE(lines[1].find(",,,,"), std::string::npos);  // no Rig init.
  EXPECT_NE(lines[2].find(",0.125,0.250,0,"), std::string::npos);
}

TEST(RuntimeBenchmark, BeforeAfterTableGivesRatiosAndErrorChanges) {
  const CalibrationRuntime before = MakeRun(500, 10, 120.0);
  CalibrationRuntime after = MakeRun(500, 10, 30.0);
  after.max_center_error_m = 0.00051;
  const std::string markdown =
      CalibrationBeforeAfterMarkdown({before}, {after});
  // Final BA: 40 (60) [17] before, 10 (15) [17] after: 4x wall and CPU.
  EXPECT_NE(markdown.find("| Final bundle adjustment | 40.00 (60.00) [17] | "
                          "10.00 (15.00) [17] | 4.00 | 4.00 |"),
            std::string::npos)
      << markdown;
  // Totals: 80 (120) before, 20 (30) after.
  EXPECT_NE(markdown.find("| **total** | 80.00 (120.00) | 20.00 (30.00) | "
                          "4.00 | 4.00 |"),
            std::string::npos)
      << markdown;
  EXPECT_NE(markdown.find("| worst camera center error mm | 0.500 | 0.510 | "
                          "2.0 % |"),
            std::string::npos)
      << markdown;
  EXPECT_NE(markdown.find("| final RMS px | 0.7050 | 0.7050 | 0.0 % |"),
            std::string::npos)
      << markdown;
}

TEST(RuntimeBenchmark, LocalizationTablesGiveCpuSecondsPerImage) {
  LocalizationRuntime run;
  run.mode = "retrieval";
  run.num_checks = 64;
  run.num_images = 40;
  run.seconds = 5;
  run.cpu_seconds = 10;
  LocalizationRuntime empty = run;
  empty.num_images = 0;
  const std::vector<std::string> csv =
      Lines(LocalizationRuntimeCsv({run, empty}));
  ASSERT_EQ(csv.size(), 3u);
  // Columns 12 and 13 (from 0): images per s = 40 / 5, CPU s per image =
  // 10 / 40; without images neither is defined.
  const auto column = [](const std::string& line, int index) {
    std::stringstream stream(line);
    std::string cell;
    for (int i = 0; i <= index; ++i) std::getline(stream, cell, ',');
    return cell;
  };
  EXPECT_EQ(column(csv[0], 11), "images per s");
  EXPECT_EQ(column(csv[0], 12), "CPU s per image");
  EXPECT_EQ(column(csv[1], 11), "8.00");
  EXPECT_EQ(column(csv[1], 12), "0.2500");
  EXPECT_EQ(column(csv[2], 12), "-");
  // The Markdown table shows the checks of direct runs only.
  const std::string markdown = LocalizationRuntimeMarkdown({run});
  EXPECT_NE(markdown.find("| retrieval | 0 | 0 | 0 | - | 40 |"),
            std::string::npos)
      << markdown;
  EXPECT_NE(markdown.find("| 8.00 | 0.250 |"), std::string::npos) << markdown;
}

TEST(RuntimeBenchmark, GrowthExponentOfPowerLaws) {
  std::vector<CalibrationRuntime> runs;
  for (const int framesets : {10, 50, 100, 500}) {
    runs.push_back(MakeRun(framesets, 5, 0.02 * framesets));  // linear
    runs.push_back(MakeRun(framesets, 10, 1e-3 * framesets * framesets));
  }
  EXPECT_NEAR(GrowthExponent(runs, 5), 1.0, 1e-12);
  EXPECT_NEAR(GrowthExponent(runs, 10), 2.0, 1e-12);
  EXPECT_TRUE(std::isnan(GrowthExponent(runs, 4)));
  // Failed runs do not count.
  runs.back().success = false;
  runs.back().cpu_seconds = 1e6;
  EXPECT_NEAR(GrowthExponent(runs, 10), 2.0, 1e-12);
  const std::string markdown = CalibrationRuntimeMarkdown(runs);
  EXPECT_NE(markdown.find("framesets^1.00"), std::string::npos);
  EXPECT_NE(markdown.find("framesets^2.00"), std::string::npos);
}

TEST(RuntimeBenchmark, SvgHasTwoSeriesPerCameraCount) {
  std::vector<CalibrationRuntime> runs;
  for (const int framesets : {10, 50, 100, 500}) {
    runs.push_back(MakeRun(framesets, 5, 0.02 * framesets));
    runs.push_back(MakeRun(framesets, 10, 0.04 * framesets));
  }
  const std::string svg = CalibrationRuntimeSvg(runs);
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  for (const std::string label : {"5 cameras, wall", "5 cameras, CPU",
                                  "10 cameras, wall", "10 cameras, CPU"}) {
    EXPECT_NE(svg.find(label), std::string::npos) << label;
  }
  EXPECT_NE(svg.find("framesets"), std::string::npos);
}

}  // namespace runtime_benchmark_test
}  // namespace rig_calibrator
