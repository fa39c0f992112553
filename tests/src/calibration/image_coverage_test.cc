#include "src/calibration/image_coverage.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rig_calibrator {
namespace image_coverage_test {

colmap::Camera Camera(int width, int height) {
  colmap::Camera camera;
  camera.InitializeWithName("OPENCV", 500, width, height);
  return camera;
}

TEST(ImageCoverage, GridCellsAreAboutSquare) {
  const ImageCoverage landscape = ComputeImageCoverage(Camera(640, 480), {});
  EXPECT_EQ(landscape.grid_cols, 10);
  EXPECT_EQ(landscape.grid_rows, 8);
  const ImageCoverage wide = ComputeImageCoverage(Camera(1920, 1080), {});
  EXPECT_EQ(wide.grid_cols, 10);
  EXPECT_EQ(wide.grid_rows, 6);
  const ImageCoverage portrait = ComputeImageCoverage(Camera(480, 640), {});
  EXPECT_EQ(portrait.grid_cols, 8);
  EXPECT_EQ(portrait.grid_rows, 10);
  EXPECT_EQ(portrait.counts.size(), 80u);
  EXPECT_EQ(portrait.fraction_cells, 0);
  EXPECT_EQ(portrait.radius_ratio, 0);
}

// Counts, radii and ratio of points placed by hand; points outside the
// image or not finite are ignored.
TEST(ImageCoverage, CountsAndRadiiOfKnownPoints) {
  colmap::Camera camera = Camera(640, 480);
  camera.SetPrincipalPointX(300);
  camera.SetPrincipalPointY(250);
  const ImageCoverage coverage = ComputeImageCoverage(
      camera, {{0.5, 0.5},
               {63.9, 59.9},  // still cell (0, 0): 64 x 60 px cells
               {639.5, 479.5},
               {300, 250},
               {-1, 10},
               {640, 10},
               {NAN, 3}});
  EXPECT_EQ(coverage.num_points, 4);
  EXPECT_EQ(coverage.counts[0], 2);
  EXPECT_EQ(coverage.counts[7 * 10 + 9], 1);
  EXPECT_EQ(coverage.counts[4 * 10 + 4], 1);  // (300, 250): col 4, row 4
  EXPECT_DOUBLE_EQ(coverage.fraction_cells, 3.0 / 80);
  // The farthest corner from (300, 250) is (640, 0).
  EXPECT_DOUBLE_EQ(coverage.corner_radius_px, std::hypot(340.0, 250.0));
  EXPECT_DOUBLE_EQ(coverage.max_observed_radius_px, std::hypot(339.5, 229.5));
  EXPECT_DOUBLE_EQ(coverage.radius_ratio,
                   std::hypot(339.5, 229.5) / std::hypot(340.0, 250.0));
}

// Points on a grid over the whole image: full coverage, no warning; the
// same points within 150 px of the centre (0.375 of the corner radius): both
// criteria fail, with the numbers in the message.
TEST(ImageCoverage, PoorCoverageIsDetectedWithItsNumbers) {
  const colmap::Camera camera = Camera(640, 480);
  std::vector<Eigen::Vector2d> all, central;
  for (double x = 1; x < 640; x += 8) {
    for (double y = 1; y < 480; y += 8) {
      all.emplace_back(x, y);
      if (std::hypot(x - 320, y - 240) < 150) central.emplace_back(x, y);
    }
  }
  std::string why;
  const ImageCoverage full = ComputeImageCoverage(camera, all);
  EXPECT_EQ(full.fraction_cells, 1);
  EXPECT_GT(full.radius_ratio, 0.98);
  EXPECT_FALSE(IsPoorCoverage(full, &why)) << why;
  EXPECT_TRUE(why.empty());

  const ImageCoverage poor = ComputeImageCoverage(camera, central);
  EXPECT_LT(poor.radius_ratio, 0.5);
  EXPECT_LT(poor.fraction_cells, 0.5);
  ASSERT_TRUE(IsPoorCoverage(poor, &why));
  EXPECT_NE(why.find("of the corner radius 400 px"), std::string::npos) << why;
  EXPECT_NE(why.find("10x8 image cells"), std::string::npos) << why;
}

}  // namespace image_coverage_test
}  // namespace rig_calibrator
