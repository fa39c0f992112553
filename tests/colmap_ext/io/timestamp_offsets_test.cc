#include "colmap_ext/io/timestamp_offsets.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "colmap_ext/io/rig_layout.h"

namespace rig_calibrator {
namespace timestamp_offsets_test {

// Nanosecond names of `num_cameras` cameras over `num_frames` framesets at
// 20 Hz: camera c's name is the frameset's time + offsets[c] + a jitter
// uniform in +-jitter_ns; (c, f) with missing(c, f) true is left out.
template <typename Missing>
std::vector<std::string> Names(const std::vector<int64_t>& offsets,
                               int num_frames, int64_t jitter_ns,
                               std::mt19937* random, Missing missing) {
  std::uniform_int_distribution<int64_t> jitter(-jitter_ns, jitter_ns);
  std::vector<std::string> names;
  for (int f = 0; f < num_frames; ++f) {
    for (size_t c = 0; c < offsets.size(); ++c) {
      const int64_t time = 1403715273000000000 + f * int64_t{50000000} +
                           offsets[c] + (jitter_ns > 0 ? jitter(*random) : 0);
      if (!missing(static_cast<int>(c), f)) {
        names.push_back("cam" + std::to_string(c) + "/" +
                        std::to_string(time) + ".png");
      }
    }
  }
  return names;
}

// The framesets as sets of (camera, frame) positions in `names`, so that
// two layouts of differently named images compare.
std::vector<int> FramesetOf(const RigLayout& layout) {
  std::vector<int> framesets;
  for (const RigLayoutImage& image : layout.images) {
    framesets.push_back(image.frameset_index);
  }
  return framesets;
}

const auto kNoneMissing = [](int, int) { return false; };

// Cameras whose names are 12 and -10 ms off the reference's (beyond the 5 ms
// tolerance; all pairwise differences below half the 50 ms period, beyond
// which names alone cannot tell the frameset) group into the same framesets as
// the unshifted names, and the offsets are reported in the names' units;
// with --RigCalibrator.timestamp_offsets 0 they do not pair.
TEST(TimestampOffsets, ShiftedNamesGroupLikeUnshiftedOnes) {
  std::mt19937 random(1);
  const std::vector<std::string> unshifted =
      Names({0, 0, 0}, 40, 0, &random, kNoneMissing);
  const std::vector<std::string> shifted =
      Names({0, 12000000, -10000000}, 40, 0, &random, kNoneMissing);
  RigLayoutOptions options;
  options.timestamp_tolerance = 5e6;
  RigLayout expected, layout;
  std::string error;
  ASSERT_TRUE(DiscoverRigLayout(unshifted, options, &expected, &error))
      << error;
  EXPECT_EQ(expected.timestamp_offsets, (std::vector<double>{0, 0, 0}));
  ASSERT_TRUE(DiscoverRigLayout(shifted, options, &layout, &error)) << error;
  EXPECT_EQ(FramesetOf(layout), FramesetOf(expected));
  EXPECT_EQ(layout.frameset_names.size(), 40u);
  EXPECT_TRUE(layout.unmatched_images.empty());
  EXPECT_EQ(layout.timestamp_offsets,
            (std::vector<double>{0, 12000000, -10000000}));
  // The frameset times are the reference camera's names.
  EXPECT_EQ(FramesetTimes(layout, 0, 1e-9), FramesetTimes(expected, 0, 1e-9));
  const std::string table = RigLayoutTable(shifted, layout);
  EXPECT_NE(table.find("timestamp offsets removed before grouping (names "
                       "minus cam0's, names' units): cam0 +0, cam1 "
                       "+12000000, cam2 -10000000"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("after removing each camera's timestamp offset"),
            std::string::npos)
      << table;
  EXPECT_EQ(RigLayoutTable(unshifted, expected).find("timestamp offsets"),
            std::string::npos);

  // Relative to another reference camera.
  options.reference_camera = "cam1";
  ASSERT_TRUE(DiscoverRigLayout(shifted, options, &layout, &error)) << error;
  EXPECT_EQ(layout.reference_camera, 1);
  EXPECT_EQ(FramesetOf(layout), FramesetOf(expected));
  EXPECT_EQ(layout.timestamp_offsets,
            (std::vector<double>{-12000000, 0, -22000000}));

  options.reference_camera = "cam7";
  EXPECT_FALSE(DiscoverRigLayout(shifted, options, &layout, &error));
  EXPECT_NE(error.find("--RigCalibrator.reference_camera cam7 is not a camera"),
            std::string::npos)
      << error;

  options.reference_camera.clear();
  options.estimate_timestamp_offsets = false;
  EXPECT_FALSE(DiscoverRigLayout(shifted, options, &layout, &error));
  EXPECT_NE(error.find("never share a frameset"), std::string::npos) << error;
  EXPECT_NE(error.find("let --RigCalibrator.timestamp_offsets auto remove it"),
            std::string::npos)
      << error;
}

// Random frameset times (periods of 40-60 ms), names with +-1 ms of jitter,
// offsets of 20 and -12 ms against a 5 ms tolerance: the same framesets as
// without offsets, each offset within the jitter.
TEST(TimestampOffsets, RandomTimesWithJitter) {
  std::mt19937 random(7);
  std::uniform_int_distribution<int64_t> period(40000000, 60000000);
  std::uniform_int_distribution<int64_t> jitter(-1000000, 1000000);
  const std::vector<int64_t> offsets = {0, 20000000, -12000000};
  std::vector<std::string> unshifted, shifted;
  int64_t time = 1403715273000000000;
  for (int f = 0; f < 60; ++f) {
    time += period(random);
    for (size_t c = 0; c < offsets.size(); ++c) {
      const int64_t noisy = time + jitter(random);
      const std::string camera = "cam" + std::to_string(c) + "/";
      unshifted.push_back(camera + std::to_string(noisy) + ".png");
      shifted.push_back(camera + std::to_string(noisy + offsets[c]) + ".png");
    }
  }
  RigLayoutOptions options;
  options.timestamp_tolerance = 5e6;
  RigLayout expected, layout;
  std::string error;
  ASSERT_TRUE(DiscoverRigLayout(unshifted, options, &expected, &error))
      << error;
  ASSERT_EQ(expected.frameset_names.size(), 60u);
  ASSERT_TRUE(DiscoverRigLayout(shifted, options, &layout, &error)) << error;
  EXPECT_EQ(FramesetOf(layout), FramesetOf(expected));
  for (size_t c = 0; c < offsets.size(); ++c) {
    EXPECT_NEAR(layout.timestamp_offsets[c], offsets[c], 1e6) << c;
  }
}

// A camera missing a third of its images (and the reference a tenth): the
// missing partners' differences fall a period away and do not move the
// offset; the images present pair as without the offset.
TEST(TimestampOffsets, CameraWithMissingImages) {
  std::mt19937 random(3);
  const auto missing = [](int c, int f) {
    return (c == 1 && f % 3 == 1) || (c == 0 && f % 10 == 4);
  };
  const std::vector<std::string> unshifted =
      Names({0, 0}, 45, 1000000, &random, missing);
  random.seed(3);
  const std::vector<std::string> shifted =
      Names({0, 22000000}, 45, 1000000, &random, missing);
  RigLayoutOptions options;
  options.timestamp_tolerance = 5e6;
  RigLayout expected, layout;
  std::string error;
  ASSERT_TRUE(DiscoverRigLayout(unshifted, options, &expected, &error))
      << error;
  ASSERT_TRUE(DiscoverRigLayout(shifted, options, &layout, &error)) << error;
  EXPECT_EQ(FramesetOf(layout), FramesetOf(expected));
  EXPECT_EQ(layout.unmatched_images, expected.unmatched_images);
  EXPECT_NEAR(layout.timestamp_offsets[1], 22000000, 1.1e6);
}

// Offsets within the tolerance pair as well at 0 as at their value: the
// estimate is 0 and the grouping today's; and too few pairings (fewer than
// kMinTimestampPairs) are no evidence.
TEST(TimestampOffsets, SmallOffsetsAndTooLittleEvidenceGiveZero) {
  const std::vector<TimedName> names = {
      {0, 0, 100}, {1, 0, 103}, {0, 0, 150}, {1, 0, 152}, {0, 0, 200},
      {1, 0, 204}, {0, 0, 250}, {1, 0, 251}};
  EXPECT_EQ(EstimateTimestampOffsets(names, 2, 0, 5),
            (std::vector<long double>{0, 0}));
  // 20 apart, tolerance 5: paired at 20, but only twice.
  const std::vector<TimedName> two = {
      {0, 0, 100}, {1, 0, 120}, {0, 0, 150}, {1, 0, 170}};
  EXPECT_EQ(EstimateTimestampOffsets(two, 2, 0, 5),
            (std::vector<long double>{0, 0}));
  // Three times: 20. Names in another folder never pair with the
  // reference's.
  std::vector<TimedName> three = two;
  three.push_back({0, 0, 200});
  three.push_back({1, 0, 220});
  three.push_back({1, 1, 300});
  EXPECT_EQ(EstimateTimestampOffsets(three, 2, 0, 5),
            (std::vector<long double>{0, 20}));
}

}  // namespace timestamp_offsets_test
}  // namespace rig_calibrator
