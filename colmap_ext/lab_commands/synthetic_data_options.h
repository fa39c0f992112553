// The option declarations of the synthetic data, which more than one lab
// sub-command has.
#pragma once

#include <boost/program_options.hpp>

#include "src/synthetic/synthetic_rig.h"

namespace rig_calibrator {

// The synthetic data of `rig_calibrator_lab synthetic`, `benchmark_runtime`
// and `benchmark_colmap_rig_ba`: --points_per_image, --noise_px,
// --outlier_ratio, --missing_image_ratio.
void AddSyntheticDataOptions(
    boost::program_options::options_description* description,
    SyntheticRigOptions* options);

}  // namespace rig_calibrator
