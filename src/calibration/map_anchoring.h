// Fixing the gauge of a final bundle adjustment that refined every observed
// map point (final_bundle_adjuster.h, refine_points) or the whole map
// (refine_map).
//
// The reprojection errors are invariant under a similarity of the world
// (X -> s R X + t with the rig poses and the rig's translations changed to
// match), so a problem whose every observed point is free has a 7-dof
// family of equal solutions, and the solver stops at an arbitrary member of
// it. When some observed points stay fixed at their map positions (points
// without id, points seen once), they pin the world frame and scale, and the
// solver's optimum is the one wanted: moving it by a similarity afterwards
// would move it off those fixed points and raise their errors. So only the
// free-gauge solution is moved, onto the map, by the similarity that best
// aligns the refined points with their map positions or, when the map images
// were adjusted too, their camera centres with the input map's.
#pragma once

#include "src/rig/rig_dataset.h"

namespace rig_calibrator {

// Moves calibration->refined_points3D, rig_from_world and the translations of
// cam_from_rig by the least-squares similarity (Umeyama) X_map = s R X + t
// from the refined points to their map positions (the dataset's point3D of
// the same point3D_id):
//   X' = s R X + t,  Q' = (R_Q R^T, s t_Q - R_Q R^T t),  P' = (R_P, s t_P),
// for every rig_from_world Q and cam_from_rig P (and map_cam_from_world as
// Q, with P the identity), so that every projection of P' Q' X' equals that
// of P Q X. False (nothing changed) with fewer than 3 refined points, which
// do not determine a similarity, or with a refined point of no map position.
bool AnchorRefinedPointsToMap(const RigDataset& dataset,
                              RigCalibration* calibration);

// The same with the similarity c_map = s R c + t from the adjusted map camera
// centres c (calibration->map_cam_from_world) to the dataset's (the input
// map's). False (nothing changed) with fewer than 3 map images.
bool AnchorMapImagesToMap(const RigDataset& dataset,
                          RigCalibration* calibration);

}  // namespace rig_calibrator
