// The bundle adjustments on one thread give the same result bit for bit
// wherever the heap put their parameter blocks. Ceres lists the blocks of an
// ordering group by address (a std::set<double*>); the map points live in
// hash-map nodes and each camera's parameters in a vector of its own, so an
// ordering that put them in one group made the elimination order, and the
// rounding, depend on the allocator's history (the output folder's name
// changed the calibration at 1e-15). Between the two runs the heap is
// rearranged: freed chunks of the size of a map-point node, handed out
// last-freed first, reverse the address order of the next run's points.
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <vector>

#include "src/calibration/final_bundle_adjuster.h"
#include "src/calibration/radial_bundle_adjuster.h"
#include "tests/src/calibration/final_ba_scene.h"

namespace rig_calibrator {
namespace bundle_adjustment_determinism_test {

using namespace final_ba_testing;  // NOLINT: the shared test fixture

// Keeps every other one of many blocks of a map-point node's size (key,
// Vector3d, next pointer: 40 bytes) allocated, the others freed.
class RearrangedHeap {
 public:
  RearrangedHeap() {
    std::vector<std::unique_ptr<std::array<double, 5>>> blocks(20000);
    for (auto& block : blocks)
      block = std::make_unique<std::array<double, 5>>();
    for (size_t i = 0; i < blocks.size(); i += 2) {
      kept_.push_back(std::move(blocks[i]));
    }
  }

 private:
  std::vector<std::unique_ptr<std::array<double, 5>>> kept_;
};

void ExpectIdentical(const RigCalibration& a, const RigCalibration& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (size_t c = 0; c < a.cameras.size(); ++c) {
    EXPECT_EQ(a.cameras[c].Params(), b.cameras[c].Params()) << "camera " << c;
    EXPECT_EQ(a.cam_from_rig[c].rotation.coeffs(),
              b.cam_from_rig[c].rotation.coeffs());
    EXPECT_EQ(a.cam_from_rig[c].translation, b.cam_from_rig[c].translation);
  }
  ASSERT_EQ(a.rig_from_world.size(), b.rig_from_world.size());
  for (size_t j = 0; j < a.rig_from_world.size(); ++j) {
    ASSERT_EQ(a.rig_from_world[j].has_value(), b.rig_from_world[j].has_value());
    if (!a.rig_from_world[j]) continue;
    EXPECT_EQ(a.rig_from_world[j]->rotation.coeffs(),
              b.rig_from_world[j]->rotation.coeffs());
    EXPECT_EQ(a.rig_from_world[j]->translation,
              b.rig_from_world[j]->translation);
  }
  EXPECT_EQ(a.refined_points3D, b.refined_points3D);
  for (size_t i = 0; i < a.images.size(); ++i) {
    EXPECT_EQ(a.images[i].inlier_mask, b.images[i].inlier_mask) << i;
  }
}

// Noisy data from a perturbed start: many iterations, so that any change of
// the summation order shows in the last digits.
SyntheticBaScene NoisyScene(const bool shared_points) {
  SceneOptions options;
  options.shared_points = shared_points;
  options.noise_px = 0.5;
  options.num_framesets = 12;
  return MakeSyntheticRig(options);
}

RigCalibration Adjust(const SyntheticBaScene& rig, const bool refine_points) {
  FinalBundleAdjustmentOptions options;
  options.refine_points = refine_points;
  options.num_threads = 1;
  RigCalibration calibration = PerturbedStart(rig, 3);
  FinalBundleAdjustmentSummary summary;
  EXPECT_TRUE(AdjustRig(options, rig.dataset, &calibration, &summary));
  return calibration;
}

TEST(BundleAdjustmentDeterminism, FinalWithRefinedPoints) {
  const SyntheticBaScene rig = NoisyScene(/*shared_points=*/true);
  const RigCalibration first = Adjust(rig, true);
  ASSERT_FALSE(first.refined_points3D.empty());
  const RearrangedHeap heap;
  ExpectIdentical(first, Adjust(rig, true));
}

TEST(BundleAdjustmentDeterminism, FinalWithFixedPoints) {
  const SyntheticBaScene rig = NoisyScene(/*shared_points=*/false);
  const RigCalibration first = Adjust(rig, false);
  const RearrangedHeap heap;
  ExpectIdentical(first, Adjust(rig, false));
}

}  // namespace bundle_adjustment_determinism_test
}  // namespace rig_calibrator
