#include "colmap_ext/lab_commands/synthetic_data_options.h"

#include "colmap_ext/commands/command_options.h"

namespace rig_calibrator {

void AddSyntheticDataOptions(
    boost::program_options::options_description* description,
    SyntheticRigOptions* options) {
  AddOption(description, "points_per_image", &options->points_per_image,
            "correspondences per image");
  AddOption(description, "noise_px", &options->noise_px,
            "pixel noise (standard deviation)");
  AddOption(description, "outlier_ratio", &options->outlier_ratio,
            "share of wrong 2D-3D matches");
  AddOption(description, "missing_image_ratio", &options->missing_image_ratio,
            "share of images dropped");
}

}  // namespace rig_calibrator
