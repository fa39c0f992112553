#include "src/rig/intrinsics_refinement.h"

#include <algorithm>

namespace rig_calibrator {

std::vector<int> HeldParamIdxs(const colmap::Camera& camera,
                               const IntrinsicsRefinement& refinement) {
  std::vector<int> held;
  const auto hold = [&held](const std::vector<size_t>& idxs) {
    held.insert(held.end(), idxs.begin(), idxs.end());
  };
  if (!refinement.focal_length) hold(camera.FocalLengthIdxs());
  if (!refinement.principal_point) hold(camera.PrincipalPointIdxs());
  if (!refinement.extra_params) hold(camera.ExtraParamsIdxs());
  std::sort(held.begin(), held.end());
  return held;
}

void RestoreHeldParams(const colmap::Camera& given,
                       const IntrinsicsRefinement& refinement,
                       colmap::Camera* camera) {
  if (given.ModelId() != camera->ModelId()) return;
  for (const int i : HeldParamIdxs(*camera, refinement)) {
    camera->Params(i) = given.Params(i);
  }
}

}  // namespace rig_calibrator
