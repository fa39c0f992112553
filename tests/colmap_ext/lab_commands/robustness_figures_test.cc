#include "colmap_ext/lab_commands/robustness_figures.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

namespace rig_calibrator {
namespace robustness_figures_test {

// A cell of two methods, the second with fallbacks, as the experiment
// records it: per camera errors, infinity where a camera failed.
RobustnessCell TwoMethodCell() {
  RobustnessCell cell;
  cell.spec.preset = RigPreset::kRing5;
  EXPECT_TRUE(BenchmarkSceneFromName("indoor", &cell.spec.scene));
  EXPECT_TRUE(BenchmarkDifficultyFromName("easy", &cell.spec.difficulty));
  const double failed = std::numeric_limits<double>::infinity();
  for (const CalibrationMethod method :
       {CalibrationMethod::kRdRa, CalibrationMethod::kRadial1D}) {
    ShortSequenceResult result;
    result.method = method;
    result.num_sequences = 2;
    result.num_complete = 2;
    result.num_good = method == CalibrationMethod::kRdRa ? 1 : 2;
    result.initial_rotation_deg = {0, 0.5, 2, failed};
    result.initial_center_error = {0, 0.01, 0.03, failed};
    result.final_rotation_deg = {0, 0.01, 0.02, 0.03};
    result.final_center_error = {0, 0.001, 0.002, 0.003};
    result.num_fallbacks = method == CalibrationMethod::kRadial1D ? 1 : 0;
    cell.results.push_back(result);
  }
  return cell;
}

TEST(RobustnessFigures, ErrorDistributionHasOneCurvePerMethod) {
  const RobustnessCell cell = TwoMethodCell();
  for (const bool rotation : {true, false}) {
    for (const bool final_errors : {true, false}) {
      const std::string svg =
          ErrorDistributionSvg(cell, rotation, final_errors);
      EXPECT_NE(svg.find(">rd_ra<"), std::string::npos);
      // 1dr fell back to rd_ra once.
      EXPECT_NE(svg.find(">1dr (rd_ra)<"), std::string::npos);
      EXPECT_NE(svg.find(rotation ? "rotation error (deg)"
                                  : "camera center error (cm)"),
                std::string::npos);
      EXPECT_NE(svg.find(final_errors ? ">Final " : ">Initial "),
                std::string::npos);
      EXPECT_NE(svg.find("</svg>"), std::string::npos);
    }
  }
}

TEST(RobustnessFigures, GoodCalibrationsHasOneGroupPerCell) {
  const std::string svg = GoodCalibrationsSvg({TwoMethodCell()});
  EXPECT_NE(svg.find(">ring5 ind easy<"), std::string::npos);
  EXPECT_NE(svg.find(">rd_ra<"), std::string::npos);
  EXPECT_NE(svg.find(">1dr<"), std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
}

}  // namespace robustness_figures_test
}  // namespace rig_calibrator
