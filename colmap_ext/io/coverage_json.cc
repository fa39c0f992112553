#include "colmap_ext/io/coverage_json.h"

#include "colmap_ext/io/json_number.h"

namespace rig_calibrator {
namespace {

using Json = nlohmann::ordered_json;

}  // namespace

void AddCoverageJson(const CameraSummary& camera, Json* node) {
  if (camera.coverage) {
    const ImageCoverage& coverage = *camera.coverage;
    (*node)["coverage"] = {
        {"grid",
         {{"cols", coverage.grid_cols},
          {"rows", coverage.grid_rows},
          {"counts", coverage.counts}}},
        {"fraction_cells", JsonNumber(coverage.fraction_cells)},
        {"max_observed_radius_px", JsonNumber(coverage.max_observed_radius_px)},
        {"corner_radius_px", JsonNumber(coverage.corner_radius_px)},
        {"radius_ratio", JsonNumber(coverage.radius_ratio)}};
  }
  if (camera.refined) {
    (*node)["refined"] = {{"focal_length", camera.refined->focal_length},
                          {"principal_point", camera.refined->principal_point},
                          {"extra_params", camera.refined->extra_params}};
  }
}

}  // namespace rig_calibrator
