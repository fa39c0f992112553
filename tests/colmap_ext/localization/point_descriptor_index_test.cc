#include "colmap_ext/localization/point_descriptor_index.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "tests/colmap_ext/colmap_testing.h"

namespace rig_calibrator {
namespace point_descriptor_index_test {

TEST(SiftDescriptorAngleTest, FollowsColmapsNormalization) {
  colmap::FeatureDescriptor a = colmap::FeatureDescriptor::Zero(1, 128);
  colmap::FeatureDescriptor b = colmap::FeatureDescriptor::Zero(1, 128);
  // 4 bins of 256 have norm 512: a.a / 512^2 = 1.
  for (int j = 0; j < 4; ++j) a(j) = 255;
  for (int j = 64; j < 68; ++j) b(j) = 255;
  EXPECT_NEAR(SiftDescriptorAngle(a.data(), a.data()),
              std::acos(4.0 * 255 * 255 / (512.0 * 512.0)), 1e-3);
  EXPECT_NEAR(SiftDescriptorAngle(a.data(), b.data()), M_PI / 2, 1e-6);
  b(0) = 255;  // one shared bin of four: cos = 1/4
  EXPECT_NEAR(SiftDescriptorAngle(a.data(), b.data()),
              std::acos(255.0 * 255 / (512.0 * 512.0)), 1e-5);
}

TEST(SelectRepresentativeDescriptorsTest, CoversDistinctViewpoints) {
  // Rows 0-2 are near copies of one descriptor, rows 3 and 4 of two others:
  // three representatives must cover the three groups, starting with the
  // group that dominates the mean.
  testing::SiftLikeDescriptors generator(3);
  const Eigen::VectorXf bases[3] = {
      generator.RandomBase(), generator.RandomBase(), generator.RandomBase()};
  colmap::FeatureDescriptors descriptors(5, 128);
  const int group_of_row[5] = {0, 0, 0, 1, 2};
  for (int row = 0; row < 5; ++row) {
    descriptors.row(row) = generator.Observe(bases[group_of_row[row]], 2);
  }
  const std::vector<int> selected =
      SelectRepresentativeDescriptors(descriptors, 3);
  ASSERT_EQ(selected.size(), 3u);
  std::set<int> groups;
  for (const int row : selected) groups.insert(group_of_row[row]);
  EXPECT_EQ(groups.size(), 3u);
  EXPECT_EQ(group_of_row[selected[0]], 0);
  EXPECT_EQ(SelectRepresentativeDescriptors(descriptors, 9).size(), 5u);
  EXPECT_EQ(SelectRepresentativeDescriptors(descriptors, 1).size(), 1u);
}

TEST(PointDescriptorIndexTest, RatioTestComparesWithOtherPointsOnly) {
  testing::SiftLikeDescriptors generator(11);
  const Eigen::VectorXf a = generator.RandomBase();
  const Eigen::VectorXf b = generator.RandomBase();
  const Eigen::VectorXf c = generator.RandomBase();
  // Point 1 has three near-identical descriptors: a k = 2 search would find
  // two of them and fail the ratio test against point 1 itself.
  colmap::FeatureDescriptors descriptors(5, 128);
  descriptors.row(0) = generator.Observe(a, 2);
  descriptors.row(1) = generator.Observe(a, 2);
  descriptors.row(2) = generator.Observe(a, 2);
  descriptors.row(3) = generator.Observe(b, 2);
  descriptors.row(4) = generator.Observe(c, 2);
  PointDescriptorIndex index;
  index.SetDescriptors(descriptors, {1, 1, 1, 2, 3});
  EXPECT_EQ(index.NumDescriptors(), 5u);
  EXPECT_EQ(index.NumPoints(), 3u);
  EXPECT_FALSE(index.HasSearchIndex());
  index.BuildSearchIndex(PointDescriptorIndex::Options());
  ASSERT_TRUE(index.HasSearchIndex());

  colmap::FeatureDescriptors queries(3, 128);
  queries.row(0) = generator.Observe(a, 4);    // clearly point 1
  queries.row(1) = generator.Quantize(a + b);  // as close to 1 as to 2
  queries.row(2) = generator.Quantize(generator.RandomBase());  // far
  std::vector<PointDescriptorIndex::PointMatch> matches;
  index.Match(queries, 0.8, 0.7, &matches);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].query_idx, 0u);
  EXPECT_EQ(matches[0].point3D_id, 1u);
  EXPECT_FLOAT_EQ(matches[0].angle,
                  index.AngleToPoint(queries.row(0).data(), 1));
  float nearest_row_angle = M_PI;
  for (int row = 0; row < 3; ++row) {
    nearest_row_angle = std::min(
        nearest_row_angle, SiftDescriptorAngle(queries.row(0).data(),
                                               descriptors.row(row).data()));
  }
  EXPECT_FLOAT_EQ(matches[0].angle, nearest_row_angle);
  EXPECT_FLOAT_EQ(index.AngleToPoint(queries.row(0).data(), 99), M_PI / 2);

  // The far query passes the ratio test but not max_distance.
  index.Match(queries, 0.99, M_PI / 2, &matches);
  EXPECT_EQ(matches.size(), 2u);
}

TEST(PointDescriptorIndexTest, MatchesTheExhaustiveRuleWithEnoughChecks) {
  testing::SiftLikeDescriptors generator(5);
  const int num_points = 400;
  std::vector<Eigen::VectorXf> bases;
  std::vector<colmap::point3D_t> point3D_ids;
  colmap::FeatureDescriptors descriptors(0, 128);
  std::vector<colmap::FeatureDescriptor> rows;
  for (int p = 0; p < num_points; ++p) {
    bases.push_back(generator.RandomBase());
    for (int k = 0; k < 1 + p % 4; ++k) {
      rows.push_back(generator.Observe(bases[p], 12));
      point3D_ids.push_back(1000 + p);
    }
  }
  descriptors.resize(rows.size(), 128);
  for (size_t i = 0; i < rows.size(); ++i) descriptors.row(i) = rows[i];
  colmap::FeatureDescriptors queries(300, 128);
  for (int q = 0; q < queries.rows(); ++q) {
    // Two thirds observe map points (more noise than the map), a third are
    // new.
    queries.row(q) = q % 3 < 2 ? generator.Observe(bases[q % num_points], 16)
                               : generator.Quantize(generator.RandomBase());
  }

  PointDescriptorIndex index;
  index.SetDescriptors(descriptors, point3D_ids);
  PointDescriptorIndex::Options options;
  options.num_checks = 100000;  // visits every leaf: exact search
  index.BuildSearchIndex(options);
  std::vector<PointDescriptorIndex::PointMatch> matches;
  const double max_ratio = 0.8;
  const double max_distance = 0.7;
  index.Match(queries, max_ratio, max_distance, &matches);

  // The same rule by brute force over points.
  std::vector<PointDescriptorIndex::PointMatch> expected;
  for (int q = 0; q < queries.rows(); ++q) {
    float best = M_PI;
    float second = M_PI / 2;
    colmap::point3D_t best_id = 0;
    for (int p = 0; p < num_points; ++p) {
      const float angle = index.AngleToPoint(queries.row(q).data(), 1000 + p);
      if (angle < best) {
        if (best_id != 0) second = std::min(second, best);
        best = angle;
        best_id = 1000 + p;
      } else {
        second = std::min(second, angle);
      }
    }
    if (best <= max_distance && best < max_ratio * second) {
      expected.push_back({static_cast<colmap::point2D_t>(q), best_id, best});
    }
  }
  ASSERT_EQ(matches.size(), expected.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    EXPECT_EQ(matches[i].query_idx, expected[i].query_idx);
    EXPECT_EQ(matches[i].point3D_id, expected[i].point3D_id);
    EXPECT_FLOAT_EQ(matches[i].angle, expected[i].angle);
  }
  // Most observed points are found, and only those.
  int num_correct = 0;
  for (const auto& match : matches) {
    EXPECT_LT(match.query_idx % 3, 2u);
    num_correct += match.point3D_id == 1000 + match.query_idx % num_points;
  }
  EXPECT_EQ(num_correct, static_cast<int>(matches.size()));
  EXPECT_GT(num_correct, 0.95 * 200);
}

TEST(PointDescriptorIndexTest, EmptyIndexMatchesNothing) {
  PointDescriptorIndex index;
  index.SetDescriptors(colmap::FeatureDescriptors(0, 128), {});
  index.BuildSearchIndex(PointDescriptorIndex::Options());
  EXPECT_FALSE(index.HasSearchIndex());
  std::vector<PointDescriptorIndex::PointMatch> matches(3);
  index.Match(colmap::FeatureDescriptors::Zero(2, 128), 0.8, 0.7, &matches);
  EXPECT_TRUE(matches.empty());
}

}  // namespace point_descriptor_index_test
}  // namespace rig_calibrator
