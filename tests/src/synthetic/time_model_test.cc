// The generator's time model (SyntheticRigOptions::frameset_rate_hz > 0):
// on exact data every observation reprojects with the pose of its own
// capture time (the frameset time, the camera's offset, the row's line
// delay), the truth and the dataset carry the times, the defaults keep the
// data of earlier versions, and bad options are refused with a message.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "src/synthetic/capture_model.h"
#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {
namespace time_model_test {

// Small, exact (no noise, no wrong matches), 5 framesets per second.
SyntheticRigOptions ExactTimedOptions(RigPreset preset) {
  SyntheticRigOptions options;
  options.preset = preset;
  options.num_framesets = 8;
  options.points_per_image = 60;
  options.noise_px = 0;
  options.outlier_ratio = 0;
  options.frameset_rate_hz = 5;
  options.seed = 3;
  return options;
}

// The reprojection error of a correspondence with the camera pose at `time`.
double ErrorAtTime(const SyntheticRig& rig, const RigImage& image,
                   const Correspondence& correspondence, double time) {
  const Rigid3d cam_from_world = rig.truth.cam_from_rig[image.camera_index] *
                                 RigFromWorldAtTime(rig.truth, time);
  const Eigen::Vector3d in_camera = cam_from_world * correspondence.point3D;
  if (in_camera.z() <= 0) return std::numeric_limits<double>::infinity();
  return (rig.truth.cameras[image.camera_index].WorldToImage(
              in_camera.hnormalized()) -
          correspondence.point2D)
      .norm();
}

// The capture time of a correspondence's row, t_f + delta_c + rho_c (y - 0.5).
double RowTime(const SyntheticRig& rig, const RigImage& image,
               const Correspondence& correspondence) {
  return rig.truth.frameset_times_s[image.frameset_index] +
         rig.truth.time_offsets_s[image.camera_index] +
         rig.truth.line_delays_s[image.camera_index] *
             (correspondence.point2D.y() - 0.5);
}

// Per correspondence, the largest error at its own row time, and the median
// of the errors with the frameset's nominal pose rig_from_world[f].
void Errors(const SyntheticRig& rig, double* max_own_time_error,
            double* median_nominal_error) {
  *max_own_time_error = 0;
  std::vector<double> nominal;
  for (const RigImage& image : rig.dataset.images) {
    for (const Correspondence& correspondence : image.correspondences) {
      *max_own_time_error =
          std::max(*max_own_time_error,
                   ErrorAtTime(rig, image, correspondence,
                               RowTime(rig, image, correspondence)));
      nominal.push_back(ErrorAtTime(
          rig, image, correspondence,
          rig.truth.frameset_times_s[image.frameset_index]));
    }
  }
  ASSERT_FALSE(nominal.empty());
  std::nth_element(nominal.begin(), nominal.begin() + nominal.size() / 2,
                   nominal.end());
  *median_nominal_error = nominal[nominal.size() / 2];
}

// Synchronized global shutters on the continuous trajectory: the times are
// f / rate in the truth and the dataset (which validates), rig_from_world[f]
// is the trajectory's pose at t_f, the offsets and line delays are 0, and
// every observation reprojects with its frameset's pose.
TEST(SyntheticTimeModel, SynchronizedGlobalShutter) {
  for (const RigPreset preset : AllRigPresets()) {
    SCOPED_TRACE(RigPresetName(preset));
    const SyntheticRig rig = GenerateSyntheticRig(ExactTimedOptions(preset));
    ASSERT_EQ(rig.truth.frameset_times_s.size(), 8);
    for (int f = 0; f < 8; ++f) {
      EXPECT_EQ(rig.truth.frameset_times_s[f], f / 5.0);
      const Rigid3d at_time = RigFromWorldAtTime(rig.truth, f / 5.0);
      EXPECT_EQ(rig.truth.rig_from_world[f].rotation.coeffs(),
                at_time.rotation.coeffs());
      EXPECT_EQ(rig.truth.rig_from_world[f].translation, at_time.translation);
    }
    EXPECT_EQ(rig.dataset.frameset_times_s, rig.truth.frameset_times_s);
    const size_t num_cameras = rig.truth.cameras.size();
    EXPECT_EQ(rig.truth.time_offsets_s, std::vector<double>(num_cameras, 0.0));
    EXPECT_EQ(rig.truth.line_delays_s, std::vector<double>(num_cameras, 0.0));
    std::string error;
    EXPECT_TRUE(ValidateDataset(rig.dataset, &error)) << error;
    double max_error = 0, median_nominal = 0;
    Errors(rig, &max_error, &median_nominal);
    EXPECT_LT(max_error, 1e-9);
    EXPECT_LT(median_nominal, 1e-9);
    // 1.5 m/s at 5 Hz: the rig moves by 0.3 m between framesets (chords
    // of the turning track are a little shorter).
    const double step = (rig.truth.rig_from_world[4].Center() -
                         rig.truth.rig_from_world[3].Center())
                            .head<2>()
                            .norm();
    EXPECT_GT(step, 0.25);
    EXPECT_LT(step, 0.35);
  }
}

// Offsets drawn in +-50 ms (the reference camera's 0): every observation
// reprojects with the pose at t_f + delta_c, and not with the nominal pose.
TEST(SyntheticTimeModel, TimeOffsetsReproduce) {
  SyntheticRigOptions options = ExactTimedOptions(RigPreset::kRing5);
  options.max_time_offset_s = 0.05;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  ASSERT_EQ(rig.truth.time_offsets_s.size(), 5);
  EXPECT_EQ(rig.truth.time_offsets_s[0], 0.0);
  double largest_offset = 0;
  for (const double offset : rig.truth.time_offsets_s) {
    EXPECT_LE(std::abs(offset), 0.05);
    largest_offset = std::max(largest_offset, std::abs(offset));
  }
  EXPECT_GT(largest_offset, 0.01);
  EXPECT_EQ(rig.truth.line_delays_s, std::vector<double>(5, 0.0));
  double max_error = 0, median_nominal = 0;
  Errors(rig, &max_error, &median_nominal);
  EXPECT_LT(max_error, 1e-9);
  EXPECT_GT(median_nominal, 1.0);
}

// Line delays drawn in 20-30 microseconds per row, with and without
// offsets: every observation reprojects with the pose of its own row's
// time, and the observations span the rows (the shutter matters).
TEST(SyntheticTimeModel, LineDelaysReproduce) {
  for (const double max_offset : {0.0, 0.05}) {
    for (const RigPreset preset :
         {RigPreset::kFisheyeHelmet5, RigPreset::kCarSurround4}) {
      SCOPED_TRACE(RigPresetName(preset) + " offsets " +
                   std::to_string(max_offset));
      SyntheticRigOptions options = ExactTimedOptions(preset);
      options.max_time_offset_s = max_offset;
      options.min_line_delay_s = 20e-6;
      options.max_line_delay_s = 30e-6;
      const SyntheticRig rig = GenerateSyntheticRig(options);
      for (const double delay : rig.truth.line_delays_s) {
        EXPECT_GE(delay, 20e-6);
        EXPECT_LE(delay, 30e-6);
      }
      double max_error = 0, median_nominal = 0;
      Errors(rig, &max_error, &median_nominal);
      EXPECT_LT(max_error, 1e-9);
      EXPECT_GT(median_nominal, 0.3);
      // Images keep (nearly) all their points: the fixed point converges.
      size_t num_correspondences = 0;
      for (const RigImage& image : rig.dataset.images) {
        num_correspondences += image.correspondences.size();
      }
      EXPECT_GE(num_correspondences,
                0.95 * 60 * rig.dataset.images.size());
    }
  }
}

// Given offsets and line delays are taken as they are; wrong matches are
// wrong by more than 20 px at their own row's pose; the noise is as asked
// (the time model changes the poses, not the noise).
TEST(SyntheticTimeModel, GivenTimesOutliersAndNoise) {
  SyntheticRigOptions options = ExactTimedOptions(RigPreset::kRing5);
  options.time_offsets_s = {0, 0.01, -0.02, 0.03, -0.04};
  options.line_delays_s = {0, 25e-6, 0, 30e-6, 20e-6};
  options.outlier_ratio = 0.3;
  options.noise_px = 0.5;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  EXPECT_EQ(rig.truth.time_offsets_s, options.time_offsets_s);
  EXPECT_EQ(rig.truth.line_delays_s, options.line_delays_s);
  double sum_squares = 0;
  int num_inliers = 0, num_outliers = 0;
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    const RigImage& image = rig.dataset.images[i];
    for (size_t k = 0; k < image.correspondences.size(); ++k) {
      const Correspondence& correspondence = image.correspondences[k];
      const double error = ErrorAtTime(rig, image, correspondence,
                                       RowTime(rig, image, correspondence));
      if (rig.is_outlier[i][k]) {
        EXPECT_GT(error, 20.0 - 3.0);  // 20 px before the noise
        ++num_outliers;
      } else {
        sum_squares += error * error;
        ++num_inliers;
      }
    }
  }
  EXPECT_GT(num_outliers, 0);
  // The error of a noisy pixel: 2 coordinates of 0.5 px (the row's time
  // moves with the noise, by a negligible 1e-3 px here).
  const double rms_per_coordinate = std::sqrt(sum_squares / (2 * num_inliers));
  EXPECT_GT(rms_per_coordinate, 0.45);
  EXPECT_LT(rms_per_coordinate, 0.55);
}

// The new options at their defaults, or set explicitly to them, give the
// same data as before the time model (the recorded fingerprints in
// dataset_fingerprint_test hold the earlier data): no times anywhere.
TEST(SyntheticTimeModel, DefaultsKeepTheEarlierData) {
  SyntheticRigOptions defaults;
  defaults.preset = RigPreset::kCarSurround4;
  defaults.num_framesets = 6;
  defaults.points_per_image = 50;
  defaults.seed = 12;
  SyntheticRigOptions explicit_zero = defaults;
  explicit_zero.frameset_rate_hz = 0;
  explicit_zero.speed_m_s = 1.5;
  explicit_zero.max_turn_rate_deg_s = 60;
  explicit_zero.max_time_offset_s = 0;
  explicit_zero.min_line_delay_s = 0;
  explicit_zero.max_line_delay_s = 0;
  explicit_zero.time_offsets_s.clear();
  explicit_zero.line_delays_s.clear();
  const SyntheticRig a = GenerateSyntheticRig(defaults);
  const SyntheticRig b = GenerateSyntheticRig(explicit_zero);
  ASSERT_EQ(a.dataset.images.size(), b.dataset.images.size());
  for (size_t i = 0; i < a.dataset.images.size(); ++i) {
    const RigImage& image_a = a.dataset.images[i];
    const RigImage& image_b = b.dataset.images[i];
    ASSERT_EQ(image_a.correspondences.size(), image_b.correspondences.size());
    for (size_t k = 0; k < image_a.correspondences.size(); ++k) {
      EXPECT_EQ(image_a.correspondences[k].point2D,
                image_b.correspondences[k].point2D);
      EXPECT_EQ(image_a.correspondences[k].point3D,
                image_b.correspondences[k].point3D);
    }
  }
  for (size_t f = 0; f < a.truth.rig_from_world.size(); ++f) {
    EXPECT_EQ(a.truth.rig_from_world[f].translation,
              b.truth.rig_from_world[f].translation);
  }
  for (const SyntheticRig* rig : {&a, &b}) {
    EXPECT_TRUE(rig->dataset.frameset_times_s.empty());
    EXPECT_TRUE(rig->truth.frameset_times_s.empty());
    EXPECT_TRUE(rig->truth.time_offsets_s.empty());
    EXPECT_TRUE(rig->truth.line_delays_s.empty());
    EXPECT_FALSE(rig->truth.trajectory.has_value());
  }
}

// Selecting framesets keeps their times in the truth and, in time order, in
// the dataset; map_scale scales the continuous poses like the sampled ones.
// bob_hz replaces the preset's bob (the car's 1.25 Hz) by one at that
// frequency with the preset's amplitude: the body's height repeats after
// 1 / bob_hz, and the data still reproduce with every observation's time.
TEST(SyntheticTimeModel, BobAtTheAskedFrequency) {
  SyntheticRigOptions options = ExactTimedOptions(RigPreset::kCarSurround4);
  options.bob_hz = 4;
  options.max_time_offset_s = 0.05;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  ASSERT_TRUE(rig.truth.trajectory.has_value());
  const RigTrajectory& trajectory = *rig.truth.trajectory;
  double max_vertical_speed = 0;
  for (double t = 0; t < 2; t += 0.01) {
    EXPECT_NEAR(trajectory.WorldFromBody(t + 0.25).translation.z(),
                trajectory.WorldFromBody(t).translation.z(), 1e-12);
    max_vertical_speed = std::max(max_vertical_speed,
                                  std::abs(trajectory.LinearVelocity(t).z()));
  }
  // b 2 pi f, the preset's 1 cm at 4 Hz.
  EXPECT_NEAR(max_vertical_speed, 0.01 * 2 * M_PI * 4, 1e-3);
  double max_error = 0, median_nominal = 0;
  Errors(rig, &max_error, &median_nominal);
  EXPECT_LT(max_error, 1e-9);
}

TEST(SyntheticTimeModel, SelectedFramesetsAndMapScale) {
  SyntheticRigOptions options = ExactTimedOptions(RigPreset::kRing5);
  options.points_per_image = 10;
  options.max_line_delay_s = 20e-6;
  const SyntheticRig rig = GenerateSyntheticRig(options);
  const SyntheticRig in_order = SelectFramesets(rig, {2, 5, 6});
  EXPECT_EQ(in_order.truth.frameset_times_s,
            std::vector<double>({0.4, 1.0, 1.2}));
  EXPECT_EQ(in_order.dataset.frameset_times_s,
            in_order.truth.frameset_times_s);
  const SyntheticRig reordered = SelectFramesets(rig, {5, 2});
  EXPECT_EQ(reordered.truth.frameset_times_s, std::vector<double>({1.0, 0.4}));
  EXPECT_TRUE(reordered.dataset.frameset_times_s.empty());
  std::string error;
  EXPECT_TRUE(ValidateDataset(reordered.dataset, &error)) << error;

  options.map_scale = 1000;
  const SyntheticRig scaled = GenerateSyntheticRig(options);
  for (const double time : {0.0, 0.5, 1.3}) {
    EXPECT_LT((RigFromWorldAtTime(scaled.truth, time).translation -
               1000 * RigFromWorldAtTime(rig.truth, time).translation)
                  .norm(),
              1e-9);
  }
  EXPECT_LT((scaled.truth.rig_from_world[3].translation -
             1000 * rig.truth.rig_from_world[3].translation)
                .norm(),
            1e-9);
}

// Every bad time-model option is refused with a message naming it.
TEST(SyntheticTimeModel, BadOptionsAreRefused) {
  const std::vector<
      std::pair<std::function<void(SyntheticRigOptions*)>, std::string>>
      cases = {
          {[](SyntheticRigOptions* o) { o->frameset_rate_hz = -1; },
           "frameset_rate_hz must be >= 0"},
          {[](SyntheticRigOptions* o) { o->frameset_rate_hz = NAN; },
           "frameset_rate_hz must be >= 0"},
          {[](SyntheticRigOptions* o) { o->speed_m_s = 0; }, "speed_m_s"},
          {[](SyntheticRigOptions* o) { o->max_turn_rate_deg_s = -5; },
           "max_turn_rate_deg_s"},
          {[](SyntheticRigOptions* o) { o->bob_hz = -1; },
           "bob_hz must be >= 0"},
          {[](SyntheticRigOptions* o) {
             o->frameset_rate_hz = 0;
             o->bob_hz = 2;
           },
           "need the time model"},
          {[](SyntheticRigOptions* o) { o->max_time_offset_s = -0.01; },
           "max_time_offset_s must be >= 0"},
          {[](SyntheticRigOptions* o) { o->max_line_delay_s = -1e-6; },
           "min_line_delay_s <= max_line_delay_s"},
          {[](SyntheticRigOptions* o) {
             o->min_line_delay_s = 30e-6;
             o->max_line_delay_s = 20e-6;
           },
           "min_line_delay_s <= max_line_delay_s"},
          {[](SyntheticRigOptions* o) {
             o->frameset_rate_hz = 0;
             o->max_time_offset_s = 0.05;
           },
           "need the time model, frameset_rate_hz > 0"},
          {[](SyntheticRigOptions* o) {
             o->frameset_rate_hz = 0;
             o->max_line_delay_s = 20e-6;
           },
           "need the time model"},
          {[](SyntheticRigOptions* o) {
             o->frameset_rate_hz = 0;
             o->speed_m_s = 3;
           },
           "need the time model"},
          {[](SyntheticRigOptions* o) {
             o->time_offsets_s = {0, 0.01};
           },
           "time_offsets_s needs one finite offset per camera (5)"},
          {[](SyntheticRigOptions* o) {
             o->time_offsets_s = {0.01, 0, 0, 0, 0};
           },
           "the reference camera's 0"},
          {[](SyntheticRigOptions* o) {
             o->time_offsets_s = {0, 0, 0, 0, 0};
             o->max_time_offset_s = 0.01;
           },
           "no max_time_offset_s"},
          {[](SyntheticRigOptions* o) {
             o->line_delays_s = {0, 0, -1e-6, 0, 0};
           },
           "line_delays_s needs one finite delay >= 0 per camera"},
          {[](SyntheticRigOptions* o) {
             o->line_delays_s = {0, 0, 0, 0};
           },
           "line_delays_s needs one finite delay >= 0 per camera (5)"},
          // 480 rows of 1 ms: 0.48 s, longer than the 0.2 s period.
          {[](SyntheticRigOptions* o) { o->max_line_delay_s = 1e-3; },
           "the readout of camera cam0"},
      };
  for (const auto& [modify, expected] : cases) {
    SyntheticRigOptions options = ExactTimedOptions(RigPreset::kRing5);
    modify(&options);
    std::string error;
    EXPECT_FALSE(options.Check(&error)) << expected;
    EXPECT_NE(error.find(expected), std::string::npos)
        << "expected '" << expected << "' in: " << error;
    EXPECT_TRUE(GenerateSyntheticRig(options).dataset.images.empty());
  }
  std::string error;
  EXPECT_TRUE(ExactTimedOptions(RigPreset::kRing5).Check(&error)) << error;
}

}  // namespace time_model_test
}  // namespace rig_calibrator
