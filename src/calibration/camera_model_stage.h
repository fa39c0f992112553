// The pipeline's steps about camera models (pipeline.h): the automatic
// choice of a camera's model where it was "auto" (RigCamera::choose_model;
// model_selection.h), in the camera upgrade of 1dr and, for the full-pose
// methods, after the rig initialization; and the validity check of every
// calibrated camera's final model (model_validity.h, with its final
// inliers' radial residual profile), an error diagnostic
// "invalid_camera_model" for a model that is not valid over the whole image
// or does not follow the lens where there are data.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "src/calibration/camera_model_report.h"
#include "src/calibration/pipeline.h"

namespace rig_calibrator {

// The camera upgrade of one camera (UpgradeCamera) or, when its model is to
// be chosen, SelectCameraModel over the same rows; `rows` gives the
// (image, correspondence) of every row, whose frameset are the folds.
bool UpgradeOrChooseCameraModel(const PipelineOptions& options,
                                const RigDataset& dataset, int camera_index,
                                const std::vector<Eigen::Vector2d>& points2D,
                                const std::vector<Eigen::Vector3d>& points_cam,
                                const std::vector<std::pair<int, int>>& rows,
                                colmap::Camera* camera,
                                CameraUpgradeResult* result,
                                std::optional<ModelChoice>* choice);

// Stores the choice in the report and prints the candidates' table.
void ReportModelChoice(const PipelineOptions& options,
                       const RigDataset& dataset, int camera_index,
                       const std::optional<ModelChoice>& choice,
                       PipelineReport* report);

// The full-pose methods: for every calibrated camera whose model is to be
// chosen, the candidates fitted to all its correspondences of posed
// framesets with the poses of the rig initialization (the forward offset
// that each fit estimates is left to the final bundle adjustment). A camera
// for which no candidate works is left uncalibrated.
void ChooseCameraModelsFromPoses(const PipelineOptions& options,
                                 const RigDataset& dataset,
                                 RigCalibration* calibration,
                                 PipelineReport* report);

// The model choice on the adjusted rig (model_choice_after_adjustment.h)
// for every calibrated camera whose model is "auto", after the final
// adjustment: the choice and its table replace the upgrade's in the report
// (its reason names the upgrade's choice). A camera whose chosen model
// differs gets the candidate's fit (intrinsics and cam_from_rig); returns
// true when some camera's model changed (the final adjustment is then run
// again). The choice is marked uncertain (warning
// "uncertain_model_choice") with fewer framesets than
// ModelSelectionOptions::min_num_framesets, or when the upgrade's was.
// When the capture-time model (report->capture_time_model) kept offsets or
// line delays, each observation's point is taken in the rig frame of its
// own capture instant, as in the adjustment; so is the check below.
bool ChooseCameraModelsOnAdjustedRig(const PipelineOptions& options,
                                     CalibrationMethod method,
                                     const RigDataset& dataset,
                                     RigCalibration* calibration,
                                     PipelineReport* report);

// The validity of every calibrated camera's model, into
// report->camera_models; an error diagnostic per invalid model (the camera
// stays calibrated and is written: the command exits non-zero).
//
// The data check (radial_residual_profile.h) is judged against the map's
// own systematic level where the final adjustment has map images: the same
// ring profile of the map images' observations of the refined points,
// through their own cameras (clustered by map image), and the largest
// |ring mean| among its significant rings is the floor a rig camera's bias
// must exceed significantly (systematic_floor_px). Why: a real map's residuals are not only noise. On the real
// 5-camera ring (a COLMAP map self-calibrated as OPENCV) the rig cameras'
// rings sit 0.3-0.8 px off consistently across images with the map's own
// model, and so do the map images' with theirs; a bias the map itself
// carries cannot be told from the rig camera's model. On an exact map the
// floor is 0 and the check is unchanged.
void CheckCameraModels(const PipelineOptions& options,
                       const RigDataset& dataset,
                       const RigCalibration& calibration,
                       PipelineReport* report);

}  // namespace rig_calibrator
