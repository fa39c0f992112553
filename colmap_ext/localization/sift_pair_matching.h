// SIFT matching of two images with COLMAP's CPU rule
// (MatchSiftFeaturesCPUFLANN in COLMAP 3.8's feature/sift.cc: the two
// approximate nearest neighbours of every descriptor in the other image, the
// ratio and distance tests on their angles, optionally the cross-check), on
// seeded kd-tree forests (descriptor_kd_forest.h), so that the same images and
// seed give the same matches. COLMAP's own function builds an unseeded forest
// per image pair inside its library; its exhaustive variant is deterministic
// but took 12.1 instead of 2.3 CPU s per rig image (2000 features, 10
// retrieved map images; rig_calibrator_lab benchmark_runtime).
#pragma once

#include <colmap/feature/sift.h>
#include <colmap/feature/types.h>

#include "colmap_ext/localization/descriptor_kd_forest.h"

namespace rig_calibrator {

// COLMAP's matcher: 4 trees, 128 leaf checks.
inline constexpr int kPairMatchingNumTrees = 4;
inline constexpr int kPairMatchingNumChecks = 128;

// Matches descriptors1 to descriptors2 (uses options.max_ratio,
// max_distance and cross_check); forest1 and forest2 index them. Matches are
// in the order of descriptors1's rows.
void MatchSiftDescriptors(const colmap::SiftMatchingOptions& options,
                          const colmap::FeatureDescriptors& descriptors1,
                          const DescriptorKdForest& forest1,
                          const colmap::FeatureDescriptors& descriptors2,
                          const DescriptorKdForest& forest2,
                          colmap::FeatureMatches* matches);

}  // namespace rig_calibrator
