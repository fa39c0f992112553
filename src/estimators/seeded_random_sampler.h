// A sampler in COLMAP's concept (<colmap/optim/sampler.h>) with its own
// generator. colmap::RandomSampler draws from COLMAP's thread-local generator,
// whose state depends on whatever ran before on the thread (the pipeline
// upgrades cameras on a thread pool); this one has a fixed seed, so a RANSAC
// that uses it depends only on its input.
#pragma once

#include <colmap/optim/sampler.h>
#include <glog/logging.h>

#include <limits>
#include <numeric>
#include <random>
#include <vector>

namespace rig_calibrator {

class SeededRandomSampler : public colmap::Sampler {
 public:
  explicit SeededRandomSampler(const size_t num_samples)
      : num_samples_(num_samples) {}

  void Initialize(const size_t total_num_samples) override {
    CHECK_LE(num_samples_, total_num_samples);
    indices_.resize(total_num_samples);
    std::iota(indices_.begin(), indices_.end(), 0);
  }

  size_t MaxNumSamples() override { return std::numeric_limits<size_t>::max(); }

  // Partial Fisher-Yates shuffle: the first num_samples_ indices.
  std::vector<size_t> Sample() override {
    for (size_t i = 0; i < num_samples_; ++i) {
      std::uniform_int_distribution<size_t> distribution(i,
                                                         indices_.size() - 1);
      std::swap(indices_[i], indices_[distribution(generator_)]);
    }
    return {indices_.begin(), indices_.begin() + num_samples_};
  }

 private:
  const size_t num_samples_;
  std::vector<size_t> indices_;
  std::mt19937 generator_{0};
};

}  // namespace rig_calibrator
