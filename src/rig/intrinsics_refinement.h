// Which intrinsic parameters of a camera are estimated: COLMAP's
// BundleAdjustmentOptions::refine_focal_length, refine_principal_point and
// refine_extra_params (colmap/optim/bundle_adjustment.h), per camera. A
// parameter that is not refined is held at its given value (the dataset
// camera's) by every stage that would otherwise estimate it: the per-image
// upgrade of rd / rd_ra and their median, the radial bundle adjustment
// (principal point), the camera upgrade and the final bundle adjustment. As
// in COLMAP, holding is done with ceres::SubsetManifold over the held
// indices, or a constant block when every parameter is held.
#pragma once

#include <colmap/base/camera.h>

#include <vector>

namespace rig_calibrator {

struct IntrinsicsRefinement {
  bool focal_length = true;
  bool principal_point = true;
  bool extra_params = true;  // distortion

  // Both refine the parameter (e.g. the method's and the user's switches).
  IntrinsicsRefinement And(const IntrinsicsRefinement& other) const {
    return {focal_length && other.focal_length,
            principal_point && other.principal_point,
            extra_params && other.extra_params};
  }
};

// The indices into camera.Params() that `refinement` holds, ascending (the
// argument of ceres::SubsetManifold).
std::vector<int> HeldParamIdxs(const colmap::Camera& camera,
                               const IntrinsicsRefinement& refinement);

// Copies the held parameters of `given` into *camera (no-op for another
// model), for a stage that computes the parameters outside Ceres.
void RestoreHeldParams(const colmap::Camera& given,
                       const IntrinsicsRefinement& refinement,
                       colmap::Camera* camera);

}  // namespace rig_calibrator
