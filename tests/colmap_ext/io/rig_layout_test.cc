#include "colmap_ext/io/rig_layout.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace rig_calibrator {
namespace rig_layout_test {

// The camera and frameset names of image i.
std::pair<std::string, std::string> Where(const RigLayout& layout, int i) {
  const RigLayoutImage& image = layout.images[i];
  return {layout.camera_names[image.camera_index],
          layout.frameset_names[image.frameset_index]};
}

TEST(RigLayout, SameFileNamesAcrossCameraFolders) {
  // Unsorted input, natural order (cam2 before cam10), a missing image.
  const std::vector<std::string> names = {
      "cam10/frame_2.png",  "cam2/frame_10.png", "cam2/frame_2.png",
      "cam10/frame_10.png", "cam1/frame_2.png",  "cam1/frame_10.png",
      "cam2/frame_3.png",   "cam1/frame_3.png"};
  RigLayout layout;
  std::string error;
  ASSERT_TRUE(DiscoverRigLayout(names, RigLayoutOptions(), &layout, &error))
      << error;
  EXPECT_EQ(layout.camera_names,
            (std::vector<std::string>{"cam1", "cam2", "cam10"}));
  EXPECT_EQ(layout.camera_prefixes,
            (std::vector<std::string>{"cam1/", "cam2/", "cam10/"}));
  EXPECT_EQ(
      layout.frameset_names,
      (std::vector<std::string>{"frame_2.png", "frame_3.png", "frame_10.png"}));
  EXPECT_EQ(Where(layout, 0),
            std::make_pair(std::string("cam10"), std::string("frame_2.png")));
  EXPECT_EQ(Where(layout, 1),
            std::make_pair(std::string("cam2"), std::string("frame_10.png")));
  EXPECT_EQ(Where(layout, 7),
            std::make_pair(std::string("cam1"), std::string("frame_3.png")));
  EXPECT_TRUE(layout.unmatched_images.empty());
  EXPECT_TRUE(layout.ignored_images.empty());
  const std::string table = RigLayoutTable(names, layout);
  EXPECT_NE(table.find("framesets with k cameras: 1: 0, 2: 1, 3: 2"),
            std::string::npos)
      << table;
}

TEST(RigLayout, GivenFramesAreTheFramesets) {
  // COLMAP rig_configurator's frames: the names after the prefix differ, the
  // timestamp tolerance is not used, an image without a frame is alone.
  const std::vector<std::string> names = {
      "cam0/a.png", "cam0/b.png", "cam1/x.png", "cam1/y.png", "cam1/z.png"};
  RigLayoutOptions options;
  options.frame_ids = {7, 3, 3, 7, -1};
  options.frame_source = "the test's frames";
  options.timestamp_tolerance = 5;
  RigLayout layout;
  std::string error;
  ASSERT_TRUE(DiscoverRigLayout(names, options, &layout, &error)) << error;
  EXPECT_EQ(layout.frameset_names,
            (std::vector<std::string>{"a.png", "b.png", "z.png"}));
  EXPECT_EQ(Where(layout, 3),
            std::make_pair(std::string("cam1"), std::string("a.png")));
  EXPECT_EQ(Where(layout, 2),
            std::make_pair(std::string("cam1"), std::string("b.png")));
  EXPECT_EQ(layout.unmatched_images, (std::vector<int>{4}));
  const std::string table = RigLayoutTable(names, layout);
  EXPECT_NE(table.find("Rig layout: 2 cameras, 3 framesets (from the test's "
                       "frames)"),
            std::string::npos)
      << table;

  // Without them the names decide: five framesets of one image, and the
  // cameras never meet.
  options.frame_ids.clear();
  options.timestamp_tolerance = 0;
  EXPECT_FALSE(DiscoverRigLayout(names, options, &layout, &error));
  EXPECT_NE(error.find("never share a frameset"), std::string::npos) << error;

  // A frame with two images of one camera prefix.
  options.frame_ids = {1, 1, 2, 3, 4};
  EXPECT_FALSE(DiscoverRigLayout(names, options, &layout, &error));
  EXPECT_NE(error.find("frame 1 of the test's frames holds two images of "
                       "camera cam0/ (cam0/a.png, cam0/b.png)"),
            std::string::npos)
      << error;
}

TEST(RigLayout, TheTableSaysWhereTheFramesetsComeFrom) {
  RigLayout layout;
  std::string error;
  const std::vector<std::string> names = {"cam0/1.png", "cam1/1.png"};
  ASSERT_TRUE(DiscoverRigLayout(names, RigLayoutOptions(), &layout, &error));
  EXPECT_NE(RigLayoutTable(names, layout)
                .find("1 framesets (from identical names after the camera "
                      "prefix)"),
            std::string::npos);
  RigLayoutOptions timed;
  timed.timestamp_tolerance = 2.5;
  ASSERT_TRUE(DiscoverRigLayout(names, timed, &layout, &error));
  EXPECT_NE(RigLayoutTable(names, layout)
                .find("(from numeric names (timestamps) within 2.5)"),
            std::string::npos);
}

TEST(RigLayout, UnmatchedAndIgnoredImagesAreReported) {
  const std::vector<std::string> names = {
      "cam0/a.png", "cam1/a.png", "cam0/b.png", "readme.txt", "cam1/c.png"};
  RigLayout layout;
  std::string error;
  ASSERT_TRUE(DiscoverRigLayout(names, RigLayoutOptions(), &layout, &error))
      << error;
  EXPECT_EQ(layout.frameset_names.size(), 3u);
  EXPECT_EQ(layout.unmatched_images, (std::vector<int>{2, 4}));
  EXPECT_EQ(layout.ignored_images, (std::vector<int>{3}));
  EXPECT_EQ(layout.images[3].camera_index, -1);
  const std::string table = RigLayoutTable(names, layout);
  EXPECT_NE(table.find("2 unmatched images"), std::string::npos) << table;
  EXPECT_NE(table.find("cam0/b.png cam1/c.png"), std::string::npos) << table;
  EXPECT_NE(table.find("1 ignored images (in no camera): readme.txt"),
            std::string::npos)
      << table;
}

TEST(RigLayout, NanosecondTimestampsWithinTolerance) {
  // EuRoC-like names, 19 digits: cam1 lags cam0 by up to 2 ms, 50 ms period;
  // cam1 misses the third frameset, cam0 misses the fourth.
  const std::vector<std::string> names = {
      "cam0/1403715273262142976.png", "cam1/1403715273263142976.png",
      "cam0/1403715273312142976.png", "cam1/1403715273314142976.png",
      "cam0/1403715273362142976.png", "cam1/1403715273414142976.png",
      "cam0/1403715273462142976.png", "cam1/1403715273461142976.png"};
  RigLayoutOptions options;
  options.timestamp_tolerance = 5e6;  // 5 ms in nanoseconds
  RigLayout layout;
  std::string error;
  ASSERT_TRUE(DiscoverRigLayout(names, options, &layout, &error)) << error;
  ASSERT_EQ(layout.frameset_names.size(), 5u);
  EXPECT_EQ(layout.frameset_names[0], "1403715273262142976.png");
  EXPECT_EQ(layout.images[0].frameset_index, layout.images[1].frameset_index);
  EXPECT_EQ(layout.images[2].frameset_index, layout.images[3].frameset_index);
  EXPECT_NE(layout.images[4].frameset_index, layout.images[5].frameset_index);
  // cam1 came first (1 ms earlier): its name names the frameset.
  EXPECT_EQ(layout.images[6].frameset_index, layout.images[7].frameset_index);
  EXPECT_EQ(layout.frameset_names[layout.images[7].frameset_index],
            "1403715273461142976.png");
  EXPECT_EQ(layout.unmatched_images, (std::vector<int>{4, 5}));

  // Identical names only, without a tolerance: nothing pairs up... except
  // that the cameras then never share a frameset, which is an error.
  EXPECT_FALSE(DiscoverRigLayout(names, RigLayoutOptions(), &layout, &error));
  EXPECT_NE(error.find("never share a frameset"), std::string::npos) << error;
}

// The frameset times of the capture-time offsets: the reference camera's
// stamp, else the median of the frameset's stamps, in seconds from the
// earliest name (19-digit nanosecond names keep their nanoseconds); none
// without timestamps, with a unit that is not positive, or when framesets of
// two subfolders are not in time order.
TEST(RigLayout, FramesetTimesFromNanosecondNames) {
  const std::vector<std::string> names = {
      "cam0/1403715273262142976.png", "cam1/1403715273263142976.png",
      "cam0/1403715273312142976.png", "cam1/1403715273314142976.png",
      "cam0/1403715273362142976.png", "cam1/1403715273414142976.png",
      "cam0/1403715273462142976.png", "cam1/1403715273461142976.png",
      "cam1/1403715273513142976.png", "cam1/1403715273513142976.jpg"};
  RigLayoutOptions options;
  options.timestamp_tolerance = 5e6;
  RigLayout layout;
  std::string error;
  ASSERT_TRUE(DiscoverRigLayout(names, options, &layout, &error)) << error;
  ASSERT_EQ(layout.frameset_names.size(), 7u);
  // The last two are cam1 at one time: two framesets of one image each, not
  // strictly increasing.
  EXPECT_TRUE(FramesetTimes(layout, 0, 1e-9).empty());

  const std::vector<std::string> increasing(names.begin(), names.end() - 1);
  ASSERT_TRUE(DiscoverRigLayout(increasing, options, &layout, &error))
      << error;
  ASSERT_EQ(layout.frameset_names.size(), 6u);
  const std::vector<double> cam0_times = FramesetTimes(layout, 0, 1e-9);
  const std::vector<double> expected0 = {0, 0.050, 0.100, 0.152, 0.200, 0.251};
  ASSERT_EQ(cam0_times.size(), expected0.size());
  for (size_t f = 0; f < expected0.size(); ++f) {
    EXPECT_NEAR(cam0_times[f], expected0[f], 1e-12) << f;
  }
  // cam1 as reference: its stamps where present; the frameset of cam0 alone
  // (0.100) is the median of its one stamp. Two stamps: their mean.
  const std::vector<double> cam1_times = FramesetTimes(layout, 1, 1e-9);
  const std::vector<double> expected1 = {0.001, 0.052, 0.100,
                                         0.152, 0.199, 0.251};
  ASSERT_EQ(cam1_times.size(), expected1.size());
  for (size_t f = 0; f < expected1.size(); ++f) {
    EXPECT_NEAR(cam1_times[f], expected1[f], 1e-12) << f;
  }
  // Milliseconds as units.
  EXPECT_NEAR(FramesetTimes(layout, 0, 1e-3)[1], 50e3, 1e-6);
  EXPECT_TRUE(FramesetTimes(layout, 0, 0).empty());

  // Names without a tolerance: no times.
  ASSERT_TRUE(DiscoverRigLayout({"cam0/1.png", "cam1/1.png", "cam0/2.png",
                                 "cam1/2.png"},
                                RigLayoutOptions(), &layout, &error))
      << error;
  EXPECT_TRUE(layout.image_times.empty());
  EXPECT_TRUE(FramesetTimes(layout, 0, 1e-9).empty());

  // Two subfolders: framesets ordered by folder, b's earlier than a's.
  options.timestamp_tolerance = 0.5;
  ASSERT_TRUE(DiscoverRigLayout({"cam0/a/5.png", "cam1/a/5.png",
                                 "cam0/b/1.png", "cam1/b/1.png"},
                                options, &layout, &error))
      << error;
  EXPECT_EQ(layout.image_times.size(), 4u);
  EXPECT_TRUE(FramesetTimes(layout, 0, 1.0).empty());
}

// Degenerate data (issue 15): timestamps that do not match within the
// tolerance (cam1's clock 12 ms behind cam0's, the tolerance 5 ms) leave the
// cameras without a common frameset. The error names the groups, the closest
// pair of images and the tolerance that would pair them, and what to do.
TEST(RigLayout, TimestampsOutsideTheToleranceAreDiagnosed) {
  const std::vector<std::string> names = {
      "cam0/1403715273262142976.png", "cam1/1403715273274142976.png",
      "cam0/1403715273312142976.png", "cam1/1403715273324142976.png",
      "cam2/1403715273262142976.png"};
  RigLayoutOptions options;
  options.timestamp_tolerance = 5e6;
  RigLayout layout;
  std::string error;
  EXPECT_FALSE(DiscoverRigLayout(names, options, &layout, &error));
  EXPECT_NE(error.find("the cameras fall into 2 groups that never share a "
                       "frameset: {cam0/, cam2/} {cam1/}"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("The closest images of two of the groups are "
                       "cam2/1403715273262142976.png and "
                       "cam1/1403715273274142976.png, 12000000 apart"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("set --RigCalibrator.timestamp_tolerance to at least"),
            std::string::npos)
      << error;
  EXPECT_TRUE(layout.images.empty());
  // With the suggested tolerance they pair up.
  options.timestamp_tolerance = 12e6;
  ASSERT_TRUE(DiscoverRigLayout(names, options, &layout, &error)) << error;
  EXPECT_EQ(layout.frameset_names.size(), 2u);
}

// A camera never in a frameset with the others (its images named apart):
// named, with what to do, and no timestamp hint for names that are not
// numbers.
TEST(RigLayout, CameraNeverInAFramesetWithTheOthersIsDiagnosed) {
  const std::vector<std::string> names = {
      "cam0/frame_1.png", "cam1/frame_1.png", "cam0/frame_2.png",
      "cam1/frame_2.png", "cam2/img_1.png",   "cam2/img_2.png"};
  RigLayout layout;
  std::string error;
  EXPECT_FALSE(DiscoverRigLayout(names, RigLayoutOptions(), &layout, &error));
  EXPECT_NE(error.find("2 groups that never share a frameset: {cam0/, cam1/} "
                       "{cam2/}"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("Name the images so that the images taken together "
                       "have the same name in every camera folder"),
            std::string::npos)
      << error;
  EXPECT_EQ(error.find("closest images"), std::string::npos) << error;
}

TEST(RigLayout, TimestampClustersTakeOneImagePerCamera) {
  // With a tolerance wider than the frame period, a camera's second image
  // starts a new frameset instead of joining the first.
  const std::vector<std::string> names = {"a/100.png", "b/101.png", "a/103.png",
                                          "b/104.png"};
  RigLayoutOptions options;
  options.timestamp_tolerance = 10;
  RigLayout layout;
  std::string error;
  ASSERT_TRUE(DiscoverRigLayout(names, options, &layout, &error)) << error;
  ASSERT_EQ(layout.frameset_names.size(), 2u);
  EXPECT_EQ(layout.images[0].frameset_index, layout.images[1].frameset_index);
  EXPECT_EQ(layout.images[2].frameset_index, layout.images[3].frameset_index);
  EXPECT_NE(layout.images[0].frameset_index, layout.images[2].frameset_index);
}

TEST(RigLayout, TimestampToleranceNeedsNumericNames) {
  RigLayoutOptions options;
  options.timestamp_tolerance = 1;
  RigLayout layout;
  std::string error;
  EXPECT_FALSE(DiscoverRigLayout({"cam0/1.png", "cam1/frame.png"}, options,
                                 &layout, &error));
  EXPECT_NE(error.find("cam1/frame.png has no numeric name"), std::string::npos)
      << error;
  // Seconds with a decimal point, with and without an extension.
  ASSERT_TRUE(DiscoverRigLayout({"cam0/10.25.png", "cam1/10.5"}, options,
                                &layout, &error))
      << error;
  EXPECT_EQ(layout.frameset_names.size(), 1u);
}

TEST(RigLayout, UserPrefixes) {
  const std::vector<std::string> names = {
      "rig/left_image_0001.jpg", "rig/right_image_0001.jpg",
      "rig/left_image_0002.jpg", "rig/right_image_0002.jpg", "map/0001.jpg"};
  RigLayoutOptions options;
  options.camera_prefixes = {"rig/right_image_", "rig/left_image_"};
  RigLayout layout;
  std::string error;
  ASSERT_TRUE(DiscoverRigLayout(names, options, &layout, &error)) << error;
  EXPECT_EQ(layout.camera_names,
            (std::vector<std::string>{"rig/left_image_", "rig/right_image_"}));
  EXPECT_EQ(layout.frameset_names,
            (std::vector<std::string>{"0001.jpg", "0002.jpg"}));
  EXPECT_EQ(layout.images[1].camera_index, 1);
  EXPECT_EQ(layout.images[1].frameset_index, 0);
  EXPECT_EQ(layout.ignored_images, (std::vector<int>{4}));

  // Nested prefixes: the longest one wins.
  options.camera_prefixes = {"cam1/", "cam1/sub/"};
  ASSERT_TRUE(DiscoverRigLayout({"cam1/x.png", "cam1/sub/x.png"}, options,
                                &layout, &error))
      << error;
  EXPECT_EQ(layout.images[0].camera_index, 0);
  EXPECT_EQ(layout.images[1].camera_index, 1);

  options.camera_prefixes = {"cam0/", "cam7/"};
  EXPECT_FALSE(DiscoverRigLayout({"cam0/x.png", "cam1/x.png"}, options, &layout,
                                 &error));
  EXPECT_EQ(error, "the camera prefix cam7/ matches no image");
}

TEST(RigLayout, ErrorsForNoFoldersAndOneCamera) {
  RigLayout layout;
  std::string error;
  EXPECT_FALSE(DiscoverRigLayout({"a.png", "b.png"}, RigLayoutOptions(),
                                 &layout, &error));
  EXPECT_NE(error.find("no camera folders"), std::string::npos) << error;

  EXPECT_FALSE(DiscoverRigLayout({"cam0/a.png", "cam0/b.png", "c.png"},
                                 RigLayoutOptions(), &layout, &error));
  EXPECT_NE(error.find("a rig needs at least two cameras: found only cam0/ "
                       "(2 images)"),
            std::string::npos)
      << error;

  EXPECT_FALSE(DiscoverRigLayout({"cam0/a.png", "cam0/a.png", "cam1/a.png"},
                                 RigLayoutOptions(), &layout, &error));
  EXPECT_NE(error.find("appears twice"), std::string::npos) << error;
}

TEST(RigLayout, DisconnectedCamerasAreAnError) {
  // cam0 and cam1 share framesets, cam2 and cam3 share others, but the two
  // pairs never do: their relative pose is undetermined.
  const std::vector<std::string> names = {"cam0/1.png", "cam1/1.png",
                                          "cam2/2.png", "cam3/2.png"};
  RigLayout layout;
  std::string error;
  EXPECT_FALSE(DiscoverRigLayout(names, RigLayoutOptions(), &layout, &error));
  EXPECT_NE(error.find("{cam0/, cam1/} {cam2/, cam3/}"), std::string::npos)
      << error;
}

TEST(RigLayout, NaturalOrder) {
  EXPECT_TRUE(NaturalLess("cam2", "cam10"));
  EXPECT_FALSE(NaturalLess("cam10", "cam2"));
  EXPECT_TRUE(NaturalLess("cam", "cam0"));
  EXPECT_TRUE(NaturalLess("a9b", "a10a"));
  EXPECT_TRUE(NaturalLess("01", "1"));  // equal numbers: plain order
  EXPECT_FALSE(NaturalLess("1", "01"));
  EXPECT_FALSE(NaturalLess("x", "x"));
}

}  // namespace rig_layout_test
}  // namespace rig_calibrator
