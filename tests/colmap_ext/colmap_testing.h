// Fixtures shared by the colmap_ext tests: running a sub-command, SQL on a
// test's own database and SIFT-like random descriptors.
#pragma once

#include <colmap/feature/types.h>

#include <Eigen/Core>
#include <random>
#include <string>
#include <vector>

namespace rig_calibrator {
namespace testing {

// Runs a sub-command (RunCalibrate, RunSynthetic, ...) in process with
// argv = {"rig_calibrator", arguments...}; returns its exit code.
int RunCommand(int (*command)(int, char**), std::vector<std::string> arguments);

// Runs SQL on a database the test owns (never on a database under test
// through the reader); fails the test on an SQLite error.
void ExecuteSql(const std::string& path, const std::string& sql);

// Random descriptors shaped like COLMAP's SIFT: half of the 128 bins empty,
// the rest |N(0, 1)|, L2 norm 512, quantized to uint8.
class SiftLikeDescriptors {
 public:
  explicit SiftLikeDescriptors(unsigned seed) : random_(seed) {}

  // A base descriptor (not quantized), norm 512.
  Eigen::VectorXf RandomBase();
  // The base plus per-bin N(0, noise^2) (clamped at 0), renormalized and
  // quantized: ~0.25 rad from the base for noise 10.
  colmap::FeatureDescriptor Observe(const Eigen::VectorXf& base, double noise);
  // Scaled to norm 512 and rounded to uint8.
  static colmap::FeatureDescriptor Quantize(const Eigen::VectorXf& vector);

  std::mt19937& random() { return random_; }

 private:
  std::mt19937 random_;
  std::normal_distribution<float> normal_;
  std::bernoulli_distribution coin_{0.5};
};

}  // namespace testing
}  // namespace rig_calibrator
