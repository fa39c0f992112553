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

#include <algorithm>
#include <cstdint>
#include <mutex>
#include <random>
#include <vector>

namespace rig_calibrator {
namespace flann_search {

// KDTreeIndex::getNeighbors, once per query, allocates and zeroes a bitset of
// one bit per indexed descriptor ("visited", so that a leaf reached in two
// trees is checked once) and reserves a branch heap of one entry per
// descriptor: at 4e6 descriptors (10^6 map points) 500 kB zeroed and 64 MB
// reserved (mmap'ed and unmapped) per feature, for a search that visits
// num_checks (64) leaves. The two classes below replace those two types in
// kdtree_index.h only (the #defines around its #include).

// The visited set: a bitset kept per thread, all zero between searches; a
// search records the words it sets and clears only those when it ends, so a
// query costs O(checks) instead of O(descriptors). getNeighbors creates one
// per query and never two at once on a thread.
class ReusedVisitedBitset {
 public:
  explicit ReusedVisitedBitset(const size_t size)
      : words_(ThreadWords()), touched_(ThreadTouched()) {
    const size_t num_words = size / kWordBits + 1;
    if (words_.size() < num_words) words_.resize(num_words, 0);
  }
  ~ReusedVisitedBitset() {
    for (const size_t word : touched_) words_[word] = 0;
    touched_.clear();
  }
  ReusedVisitedBitset(const ReusedVisitedBitset&) = delete;
  ReusedVisitedBitset& operator=(const ReusedVisitedBitset&) = delete;

  bool test(const size_t index) const {
    return (words_[index / kWordBits] >> (index % kWordBits)) & 1u;
  }
  void set(const size_t index) {
    uint64_t& word = words_[index / kWordBits];
    if (word == 0) touched_.push_back(index / kWordBits);
    word |= uint64_t{1} << (index % kWordBits);
  }

 private:
  static constexpr size_t kWordBits = 64;
  static std::vector<uint64_t>& ThreadWords() {
    thread_local std::vector<uint64_t> words;
    return words;
  }
  static std::vector<size_t>& ThreadTouched() {
    thread_local std::vector<size_t> touched;
    return touched;
  }
  std::vector<uint64_t>& words_;
  std::vector<size_t>& touched_;
};

// flann::Heap without the up-front reserve of `capacity` entries: the
// vector grows to the branches a search actually pushes (hundreds). Same
// order and capacity rule, so the same neighbours.
template <typename T>
class GrowingHeap {
 public:
  explicit GrowingHeap(const int capacity) : capacity_(capacity) {}
  void insert(const T& value) {
    if (static_cast<int>(heap_.size()) == capacity_) return;
    heap_.push_back(value);
    std::push_heap(heap_.begin(), heap_.end(), Greater());
  }
  bool popMin(T& value) {
    if (heap_.empty()) return false;
    std::pop_heap(heap_.begin(), heap_.end(), Greater());
    value = heap_.back();
    heap_.pop_back();
    return true;
  }

 private:
  struct Greater {
    bool operator()(const T& a, const T& b) const { return b < a; }
  };
  int capacity_;
  std::vector<T> heap_;
};

}  // namespace flann_search
}  // namespace rig_calibrator

// KDTreeIndex::buildIndexImpl shuffles with
//   std::random_device rd; std::mt19937 g(rd());
// which becomes a default-seeded std::mt19937 drawing the seed of g: the
// shuffle is then fixed, and the trees still differ from each other because
// every tree shuffles the order the previous one left (divideTree partitions
// the index array in place). std::rand, seeded below, picks the split
// dimensions.
#define random_device mt19937
#define DynamicBitset ::rig_calibrator::flann_search::ReusedVisitedBitset
#define Heap ::rig_calibrator::flann_search::GrowingHeap
#include <flann/algorithms/kdtree_index.h>
#undef Heap
#undef DynamicBitset
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
