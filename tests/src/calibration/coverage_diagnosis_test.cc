// The pipeline's coverage report: every calibrated camera has its coverage;
// a camera whose inliers all lie near the image centre gets a
// "poor_coverage" warning naming it, the others none.
#include "src/calibration/coverage_diagnosis.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>

#include "src/calibration/pipeline.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace coverage_diagnosis_test {

SyntheticRig Ring5() {
  SyntheticRigOptions options;
  options.preset = RigPreset::kRing5;
  options.num_framesets = 12;
  options.noise_px = 0.5;
  options.outlier_ratio = 0.1;
  options.min_depth = 2.0;
  options.max_depth = 10.0;
  options.seed = 3;
  return GenerateSyntheticRig(options);
}

std::vector<const Diagnostic*> PoorCoverage(const PipelineReport& report) {
  std::vector<const Diagnostic*> found;
  for (const Diagnostic& diagnostic : report.diagnostics) {
    if (diagnostic.code == "poor_coverage") found.push_back(&diagnostic);
  }
  return found;
}

TEST(CoverageDiagnosis, CentralObservationsArePoorCoverage) {
  SyntheticRig rig = Ring5();
  PipelineOptions options;
  options.print_progress = false;
  RigCalibration calibration;
  PipelineReport report;
  ASSERT_TRUE(CalibrateRig(options, rig.dataset, &calibration, &report));
  ASSERT_EQ(report.coverage.size(), 5u);
  for (size_t c = 0; c < 5; ++c) {
    ASSERT_TRUE(report.coverage[c]);
    std::cout << rig.dataset.cameras[c].name << ": cells "
              << report.coverage[c]->fraction_cells << ", radius ratio "
              << report.coverage[c]->radius_ratio << std::endl;
    EXPECT_GT(report.coverage[c]->fraction_cells, 0.9);
    EXPECT_GT(report.coverage[c]->radius_ratio, 0.9);
  }
  EXPECT_TRUE(PoorCoverage(report).empty());

  // cam2 sees only what is within 0.45 of its corner radius of the centre.
  const colmap::Camera& camera = rig.dataset.cameras[2].camera;
  const Eigen::Vector2d centre(camera.Width() / 2.0, camera.Height() / 2.0);
  const double max_radius = 0.45 * centre.norm();
  for (RigImage& image : rig.dataset.images) {
    if (image.camera_index != 2) continue;
    std::vector<Correspondence> kept;
    for (const Correspondence& correspondence : image.correspondences) {
      if ((correspondence.point2D - centre).norm() < max_radius) {
        kept.push_back(correspondence);
      }
    }
    image.correspondences = kept;
  }
  ASSERT_TRUE(CalibrateRig(options, rig.dataset, &calibration, &report))
      << report.error;
  const std::vector<const Diagnostic*> poor = PoorCoverage(report);
  ASSERT_EQ(poor.size(), 1u);
  EXPECT_EQ(poor[0]->level, Diagnostic::Level::kWarning);
  EXPECT_EQ(poor[0]->cameras, std::vector<int>({2}));
  EXPECT_NE(poor[0]->message.find("camera cam2"), std::string::npos);
  EXPECT_NE(poor[0]->message.find("of the corner radius"), std::string::npos);
  std::cout << poor[0]->message << std::endl;
  EXPECT_LT(report.coverage[2]->radius_ratio, 0.5);
}

}  // namespace coverage_diagnosis_test
}  // namespace rig_calibrator
