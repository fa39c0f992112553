#include "src/calibration/camera_model_stage.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "tests/src/calibration/final_ba_scene.h"

namespace rig_calibrator {
namespace camera_model_stage_test {

bool HasDiagnostic(const PipelineReport& report, const std::string& code,
                   int camera) {
  return std::any_of(report.diagnostics.begin(), report.diagnostics.end(),
                     [&](const Diagnostic& diagnostic) {
                       return diagnostic.code == code &&
                              diagnostic.cameras == std::vector<int>{camera};
                     });
}

// CheckCameraModels checks the cameras on all threads and reports them in
// camera order: the same validities and diagnostics, in the same order, on
// one and two threads, with a model whose distortion folds inside the image
// (camera 1) and held intrinsics that do not fit their data (camera 2)
// among valid ones.
TEST(CameraModelStage, CheckCameraModelsReportsTheSameOnAnyThreadCount) {
  final_ba_testing::SceneOptions scene;
  scene.num_framesets = 10;
  scene.noise_px = 0.3;
  final_ba_testing::SyntheticBaScene rig =
      final_ba_testing::MakeSyntheticRig(scene);
  RigCalibration calibration = rig.truth;
  for (ImageResult& image : calibration.images) image.used = true;
  // OPENCV with k1 = -0.8, k2 = 0: r (1 + k1 r^2) turns back at r = 0.65,
  // ~330 px from the principal point, inside the 400 px to the corners.
  std::vector<double> folding = calibration.cameras[1].Params();
  folding[4] = -0.8;
  folding[5] = 0;
  calibration.cameras[1].SetParams(folding);
  // Held focal lengths 2 % off: radial residuals of up to ~6 px.
  rig.dataset.cameras[2].refinement.focal_length = false;
  std::vector<double> off = calibration.cameras[2].Params();
  off[0] *= 1.02;
  off[1] *= 1.02;
  calibration.cameras[2].SetParams(off);

  PipelineOptions options;
  options.num_threads = 1;
  PipelineReport one;
  CheckCameraModels(options, rig.dataset, calibration, &one);
  options.num_threads = 2;
  PipelineReport two;
  CheckCameraModels(options, rig.dataset, calibration, &two);

  EXPECT_TRUE(HasDiagnostic(one, "invalid_camera_model", 1));
  EXPECT_TRUE(HasDiagnostic(one, "held_intrinsics_misfit", 2));
  ASSERT_EQ(one.camera_models.size(), rig.dataset.cameras.size());
  ASSERT_EQ(two.camera_models.size(), one.camera_models.size());
  for (size_t c = 0; c < one.camera_models.size(); ++c) {
    SCOPED_TRACE("camera " + std::to_string(c));
    ASSERT_TRUE(one.camera_models[c].validity.has_value());
    ASSERT_TRUE(two.camera_models[c].validity.has_value());
    const ModelValidity& a = *one.camera_models[c].validity;
    const ModelValidity& b = *two.camera_models[c].validity;
    EXPECT_EQ(a.valid, c != 1);
    EXPECT_EQ(a.valid, b.valid);
    EXPECT_EQ(a.fits_data, b.fits_data);
    EXPECT_EQ(a.max_roundtrip_error_px, b.max_roundtrip_error_px);
    EXPECT_EQ(a.message, b.message);
  }
  ASSERT_EQ(one.diagnostics.size(), two.diagnostics.size());
  for (size_t k = 0; k < one.diagnostics.size(); ++k) {
    EXPECT_EQ(one.diagnostics[k].code, two.diagnostics[k].code);
    EXPECT_EQ(one.diagnostics[k].message, two.diagnostics[k].message);
    EXPECT_EQ(one.diagnostics[k].cameras, two.diagnostics[k].cameras);
  }
}

}  // namespace camera_model_stage_test
}  // namespace rig_calibrator
