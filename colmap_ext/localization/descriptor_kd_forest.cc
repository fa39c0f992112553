#include "colmap_ext/localization/descriptor_kd_forest.h"

// Everything kdtree_index.h includes is parsed first, without the
// redefinition below, so that only KDTreeIndex's own code sees it.
#include <flann/algorithms/dist.h>
#include <flann/algorithms/nn_index.h>
#include <flann/general.h>
#include <flann/util/allocator.h>
#include <flann/util/dynamic_bitset.h>
#include <flann/util/heap.h>
#include <flann/util/matrix.h>
#include <flann/util/random.h>
#include <flann/util/result_set.h>
#include <flann/util/saving.h>

#include <mutex>
#include <random>
#include <vector>

// KDTreeIndex::buildIndexImpl shuffles with
//   std::random_device rd; std::mt19937 g(rd());
// which becomes a default-seeded std::mt19937 drawing the seed of g: the
// shuffle is then fixed, and the trees still differ from each other because
// every tree shuffles the order the previous one left (divideTree partitions
// the index array in place). std::rand, seeded below, picks the split
// dimensions.
#define random_device mt19937
#include <flann/algorithms/kdtree_index.h>
#undef random_device

namespace rig_calibrator {
namespace {

constexpr int kDescriptorDim = 128;

// A distance type of this file only, so that KDTreeIndex<SiftL2> is a
// template instance of its own and never shares (link-time) code with the
// KDTreeIndex<flann::L2<uint8_t>> that COLMAP's libraries instantiate without
// the redefinition above.
struct SiftL2 : flann::L2<uint8_t> {};

// std::rand is one process-wide generator: builds of forests are serialized.
std::mutex& FlannRandomMutex() {
  static std::mutex mutex;
  return mutex;
}

}  // namespace

class DescriptorKdForest::Index {
 public:
  Index(const colmap::FeatureDescriptors& descriptors, const int num_trees,
        const unsigned int seed)
      : index_(flann::Matrix<uint8_t>(const_cast<uint8_t*>(descriptors.data()),
                                      descriptors.rows(), kDescriptorDim),
               flann::KDTreeIndexParams(num_trees)) {
    std::lock_guard<std::mutex> lock(FlannRandomMutex());
    // + 1: glibc's srand treats seeds 0 and 1 alike.
    flann::seed_random(seed + 1);
    index_.buildIndex();
  }

  void KnnSearch(const colmap::FeatureDescriptors& query, const int k,
                 const int num_checks, IndexMatrix* indices) const {
    indices->setConstant(query.rows(), k, -1);
    if (query.rows() == 0 || k <= 0) return;
    std::vector<float> distances(query.rows() * k);
    flann::Matrix<uint8_t> query_matrix(const_cast<uint8_t*>(query.data()),
                                        query.rows(), kDescriptorDim);
    flann::Matrix<int> indices_matrix(indices->data(), query.rows(), k);
    flann::Matrix<float> distances_matrix(distances.data(), query.rows(), k);
    flann::SearchParams search_params(num_checks);
    search_params.cores = 1;  // callers parallelize over images
    index_.knnSearch(query_matrix, indices_matrix, distances_matrix, k,
                     search_params);
  }

 private:
  flann::KDTreeIndex<SiftL2> index_;
};

DescriptorKdForest::DescriptorKdForest(
    const colmap::FeatureDescriptors& descriptors, const int num_trees,
    const unsigned int seed)
    : index_(descriptors.rows() > 0
                 ? std::make_unique<Index>(descriptors, num_trees, seed)
                 : nullptr) {}

DescriptorKdForest::~DescriptorKdForest() = default;

void DescriptorKdForest::KnnSearch(const colmap::FeatureDescriptors& query,
                                   const int k, const int num_checks,
                                   IndexMatrix* indices) const {
  if (index_ == nullptr) {
    indices->setConstant(query.rows(), k, -1);
    return;
  }
  index_->KnnSearch(query, k, num_checks, indices);
}

}  // namespace rig_calibrator
