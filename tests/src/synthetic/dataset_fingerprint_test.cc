// The generated datasets are fixed for a seed: a fingerprint (FNV-1a over the
// bytes of every number and name) of a set of synthetic rigs and rendered
// dataset plans that together draw every random stream of the generators
// (each preset, partial feature windows, ground points, tracks, outliers,
// missing images, enlarged rings; the time model separately), compared with
// the value recorded when the generators were last changed on purpose.
// Refactorings must keep it; a deliberate change of the generated data
// updates it and says so.
//
// std::normal_distribution and std::shuffle are implementation-defined, so the
// recorded values hold for libstdc++ only; elsewhere the test only checks that
// two runs agree.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "src/synthetic/rendered_dataset.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace dataset_fingerprint_test {

class Fingerprint {
 public:
  void Add(const void* data, size_t size) {
    const unsigned char* bytes = static_cast<const unsigned char*>(data);
    for (size_t k = 0; k < size; ++k) {
      hash_ = (hash_ ^ bytes[k]) * 0x100000001b3ull;
    }
  }
  void Add(double value) { Add(&value, sizeof(value)); }
  void Add(int64_t value) { Add(&value, sizeof(value)); }
  void Add(const std::string& text) {
    Add(static_cast<int64_t>(text.size()));
    Add(text.data(), text.size());
  }
  template <typename Derived>
  void Add(const Eigen::MatrixBase<Derived>& matrix) {
    for (int k = 0; k < matrix.size(); ++k) Add(double(matrix(k)));
  }
  void Add(const Rigid3d& pose) {
    Add(pose.rotation.coeffs());
    Add(pose.translation);
  }
  void Add(const colmap::Camera& camera) {
    Add(static_cast<int64_t>(camera.ModelId()));
    Add(static_cast<int64_t>(camera.Width()));
    Add(static_cast<int64_t>(camera.Height()));
    for (const double param : camera.Params()) Add(param);
  }
  void Add(const RigGroundTruth& truth) {
    for (const colmap::Camera& camera : truth.cameras) Add(camera);
    for (const Rigid3d& pose : truth.cam_from_rig) Add(pose);
    for (const Rigid3d& pose : truth.rig_from_world) Add(pose);
    for (const std::string& name : truth.camera_names) Add(name);
    // The time model's (empty without it: the earlier values hold).
    for (const double time : truth.frameset_times_s) Add(time);
    for (const double offset : truth.time_offsets_s) Add(offset);
    for (const double delay : truth.line_delays_s) Add(delay);
    if (truth.trajectory) {
      for (const double time : {-0.05, 0.0, 0.37, 2.0}) {
        Add(truth.trajectory->WorldFromBody(time));
      }
    }
  }
  void Add(const SyntheticRig& rig) {
    Add(rig.truth);
    for (const RigCamera& camera : rig.dataset.cameras) {
      Add(camera.name);
      Add(camera.camera);
    }
    for (const std::string& name : rig.dataset.frameset_names) Add(name);
    for (const RigImage& image : rig.dataset.images) {
      Add(image.name);
      Add(static_cast<int64_t>(image.camera_index));
      Add(static_cast<int64_t>(image.frameset_index));
      for (const Correspondence& correspondence : image.correspondences) {
        Add(correspondence.point2D);
        Add(correspondence.point3D);
        Add(correspondence.point3D_id);
      }
    }
    for (const std::vector<char>& flags : rig.is_outlier) {
      Add(flags.data(), flags.size());
    }
  }

  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 0xcbf29ce484222325ull;
};

SyntheticRigOptions Case(RigPreset preset, int num_framesets,
                         int points_per_image, unsigned int seed) {
  SyntheticRigOptions options;
  options.preset = preset;
  options.num_framesets = num_framesets;
  options.points_per_image = points_per_image;
  options.seed = seed;
  return options;
}

std::vector<SyntheticRigOptions> SyntheticCases() {
  std::vector<SyntheticRigOptions> cases;
  for (const RigPreset preset : AllRigPresets()) {
    cases.push_back(Case(preset, 8, 60, 11));
  }
  SyntheticRigOptions varied = Case(RigPreset::kCarSurround4, 10, 80, 3);
  varied.noise_px = 1.5;
  varied.outlier_ratio = 0.4;
  varied.missing_image_ratio = 0.25;
  varied.near_planar_ratio = 0.5;
  varied.track_ratio = 0.8;
  varied.feature_window = 0.4;
  cases.push_back(varied);
  SyntheticRigOptions ring = Case(RigPreset::kRing5, 4, 40, 5);
  ring.ring_num_cameras = 12;
  cases.push_back(ring);
  return cases;
}

uint64_t SyntheticFingerprint() {
  Fingerprint fingerprint;
  for (const SyntheticRigOptions& options : SyntheticCases()) {
    fingerprint.Add(GenerateSyntheticRig(options));
  }
  return fingerprint.value();
}

// The time model: continuous trajectories, drawn and given offsets, rolling
// shutters (their fixed points), rotation only.
uint64_t TimeModelFingerprint() {
  Fingerprint fingerprint;
  SyntheticRigOptions ring = Case(RigPreset::kRing5, 6, 50, 21);
  ring.frameset_rate_hz = 5;
  ring.max_time_offset_s = 0.05;
  ring.min_line_delay_s = 20e-6;
  ring.max_line_delay_s = 30e-6;
  SyntheticRigOptions car = Case(RigPreset::kCarSurround4, 5, 40, 4);
  car.frameset_rate_hz = 10;
  car.speed_m_s = 4;
  car.max_turn_rate_deg_s = 30;
  car.time_offsets_s = {0, 0.012, -0.03, 0.045};
  car.line_delays_s = {25e-6, 0, 30e-6, 20e-6};
  SyntheticRigOptions helmet = Case(RigPreset::kFisheyeHelmet5, 4, 40, 2);
  helmet.frameset_rate_hz = 20;
  helmet.max_line_delay_s = 20e-6;
  helmet.rotation_only = true;
  for (const SyntheticRigOptions& options : {ring, car, helmet}) {
    const SyntheticRig rig = GenerateSyntheticRig(options);
    fingerprint.Add(rig);
    for (const double time : rig.dataset.frameset_times_s) {
      fingerprint.Add(time);
    }
  }
  return fingerprint.value();
}

uint64_t RenderedPlanFingerprint() {
  Fingerprint fingerprint;
  for (const SceneType scene : AllSceneTypes()) {
    RenderedDatasetOptions options;
    options.scene = scene;
    options.preset = scene == SceneType::kRoom ? RigPreset::kRing5
                                               : RigPreset::kCarSurround4;
    options.num_map_images = 20;
    options.num_framesets = 6;
    options.seed = 9;
    RenderedDatasetPlan plan;
    std::string error;
    EXPECT_TRUE(PlanRenderedDataset(options, &plan, &error)) << error;
    fingerprint.Add(plan.map_camera);
    for (const std::string& name : plan.map_image_names) fingerprint.Add(name);
    for (const Rigid3d& pose : plan.map_cam_from_world) fingerprint.Add(pose);
    fingerprint.Add(plan.rig);
    for (const std::string& name : plan.frameset_names) fingerprint.Add(name);
  }
  return fingerprint.value();
}

TEST(DatasetFingerprint, SameSeedGivesTheRecordedDatasets) {
  const uint64_t synthetic = SyntheticFingerprint();
  const uint64_t rendered = RenderedPlanFingerprint();
  std::printf("synthetic rigs %016llx, rendered plans %016llx\n",
              static_cast<unsigned long long>(synthetic),
              static_cast<unsigned long long>(rendered));
  EXPECT_EQ(SyntheticFingerprint(), synthetic);
  EXPECT_EQ(RenderedPlanFingerprint(), rendered);
#ifdef __GLIBCXX__
  EXPECT_EQ(synthetic, 0x743dc55262ad7d7full);
  EXPECT_EQ(rendered, 0x126c6d298b11d9c9ull);
#endif
}

// The time model's data, recorded when it was made (as above: a deliberate
// change updates the value and says so).
TEST(DatasetFingerprint, TimeModelGivesTheRecordedDatasets) {
  const uint64_t time_model = TimeModelFingerprint();
  std::printf("time model %016llx\n",
              static_cast<unsigned long long>(time_model));
  EXPECT_EQ(TimeModelFingerprint(), time_model);
#ifdef __GLIBCXX__
  // The car's bob at its own 1.25 Hz, not every 2 profile steps
  // (rig_presets.cc); ring and helmet unchanged.
  EXPECT_EQ(time_model, 0xf554d0d6e055205cull);
#endif
}

}  // namespace dataset_fingerprint_test
}  // namespace rig_calibrator
