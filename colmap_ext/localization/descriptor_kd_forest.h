// FLANN's randomized kd-tree forest over SIFT descriptors (the index COLMAP's
// CPU matcher uses), built so that the same descriptors and seed always give
// the same trees, and hence the same approximate neighbours.
//
// Why a wrapper: FLANN 1.9 builds every tree of a forest after shuffling the
// points with a std::mt19937 seeded from std::random_device
// (flann/algorithms/kdtree_index.h, KDTreeIndex::buildIndexImpl), which no
// option can seed, and picks each split dimension among the 5 of highest
// variance with std::rand (flann::rand_int). A search with a limited number of
// leaf checks (approximate) therefore returned other neighbours on every run:
// other 2D-3D correspondences for the same database. Here the shuffle uses a
// std::mt19937 with its default seed and std::rand is seeded with `seed`
// (flann::seed_random) right before the build, under a lock that every build
// of this class takes. Building once per map costs nothing extra. Searching
// is FLANN's, with the same neighbours, minus its per-query allocation and
// zeroing of buffers sized to the whole index (descriptor_kd_forest.cc).
#pragma once

#include <colmap/feature/types.h>

#include <Eigen/Core>
#include <memory>

namespace rig_calibrator {

class DescriptorKdForest {
 public:
  using IndexMatrix =
      Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  // Indexes the rows of `descriptors` (128 columns; none is fine), which must
  // outlive the forest and stay unchanged. Deterministic for (descriptors,
  // num_trees, seed) as long as no other thread calls std::rand during the
  // build.
  DescriptorKdForest(const colmap::FeatureDescriptors& descriptors,
                     int num_trees, unsigned int seed);
  ~DescriptorKdForest();
  DescriptorKdForest(const DescriptorKdForest&) = delete;
  DescriptorKdForest& operator=(const DescriptorKdForest&) = delete;

  // Row indices (-1: none) of the k nearest descriptors (L2) of every query
  // row, nearest first, visiting at most num_checks leaves. One thread; safe
  // to call from several threads at once.
  void KnnSearch(const colmap::FeatureDescriptors& query, int k, int num_checks,
                 IndexMatrix* indices) const;

 private:
  class Index;
  std::unique_ptr<Index> index_;
};

}  // namespace rig_calibrator
