#include "colmap_ext/io/model_validity_json.h"

#include <cmath>

namespace rig_calibrator {
namespace {

using Json = nlohmann::ordered_json;

// Finite numbers as they are, anything else as null.
Json FiniteOrNull(double value) {
  return std::isfinite(value) ? Json(value) : Json(nullptr);
}

Json ValidityJson(const ModelValidity& validity) {
  Json node;
  node["valid"] = validity.valid;
  node["monotonic"] = validity.monotonic;
  node["max_roundtrip_error_px"] =
      FiniteOrNull(validity.max_roundtrip_error_px);
  node["fold_radius_px"] = validity.fold_radius_px
                               ? FiniteOrNull(*validity.fold_radius_px)
                               : Json(nullptr);
  node["fold_angle_deg"] = validity.fold_angle_deg
                               ? FiniteOrNull(*validity.fold_angle_deg)
                               : Json(nullptr);
  node["corner_radius_px"] = FiniteOrNull(validity.corner_radius_px);
  node["fits_data"] = validity.fits_data;
  if (validity.residual_profile && validity.residual_profile->evaluated) {
    Json rings = Json::array();
    for (const RadialResidualRing& ring : validity.residual_profile->rings) {
      rings.push_back({{"min_radius_px", FiniteOrNull(ring.min_radius_px)},
                       {"max_radius_px", FiniteOrNull(ring.max_radius_px)},
                       {"num_points", ring.num_points},
                       {"num_images", ring.num_groups},
                       {"mean_radial_px", FiniteOrNull(ring.mean_radial_px)},
                       {"standard_error_px",
                        FiniteOrNull(ring.standard_error_px)},
                       {"z", FiniteOrNull(ring.z)},
                       {"z_threshold", FiniteOrNull(ring.z_threshold)}});
    }
    node["radial_residual_rings"] = rings;
    node["systematic_floor_px"] =
        FiniteOrNull(validity.residual_profile->systematic_floor_px);
  }
  node["suggested_model"] = validity.suggested_model.empty()
                                ? Json(nullptr)
                                : Json(validity.suggested_model);
  node["message"] = validity.message;
  return node;
}

Json ChoiceJson(const ModelChoice& choice) {
  Json node;
  node["chosen"] = choice.chosen.empty() ? Json(nullptr) : Json(choice.chosen);
  node["reason"] = choice.reason;
  node["uncertain"] = choice.uncertain;
  node["candidates"] = Json::array();
  for (const ModelCandidate& candidate : choice.candidates) {
    node["candidates"].push_back(
        {{"model", candidate.model},
         {"valid", candidate.valid},
         {"heldout_rms_px", candidate.valid
                                ? FiniteOrNull(candidate.heldout_rms_px)
                                : Json(nullptr)},
         {"train_rms_px", candidate.fitted
                              ? FiniteOrNull(candidate.train_rms_px)
                              : Json(nullptr)},
         {"num_params", candidate.num_params},
         {"num_inliers", candidate.num_inliers},
         {"chosen", candidate.chosen},
         {"as_good_as_best", candidate.as_good_as_best},
         {"note", candidate.note}});
  }
  return node;
}

}  // namespace

void AttachCameraModelReports(const PipelineReport& report,
                              CalibrationSummary* summary) {
  for (size_t c = 0;
       c < report.camera_models.size() && c < summary->cameras.size(); ++c) {
    summary->cameras[c].camera_model = report.camera_models[c];
  }
}

void AddCameraModelJson(const CameraModelReport& report, Json* node) {
  if (report.validity) (*node)["validity"] = ValidityJson(*report.validity);
  if (report.choice) (*node)["model_choice"] = ChoiceJson(*report.choice);
}

}  // namespace rig_calibrator
