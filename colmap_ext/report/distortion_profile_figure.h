// The radial profile of a camera model (report.html): the angle between a
// ray and the optical axis against the distance from the principal point at
// which the model images it, along the direction of the farthest image
// corner, next to a pinhole with the same focal length. The observed radius
// range and the corner are marked: a model is only determined where there
// were observations, and one that folds back (the radius shrinking as the
// angle grows) images two directions at one pixel.
#pragma once

#include <colmap/base/camera.h>

#include <string>

namespace rig_calibrator {

struct DistortionProfileOptions {
  std::string id;  // the <svg> element's id, unique within the page
  std::string title;
  // Observed distances of the inliers from the principal point, pixels.
  double min_observed_radius_px = 0, max_observed_radius_px = 0;
};

// The angle runs from 0 to 89.5 degrees in steps of 0.25 degrees (COLMAP's
// models project rays in front of the camera only), the radius axis to 1.15
// times the corner radius. Uses COLMAP's camera model (WorldToImage).
std::string DistortionProfileSvg(const DistortionProfileOptions& options,
                                 const colmap::Camera& camera);

// Distance from the principal point to the farthest image corner, pixels.
double CornerRadiusPx(const colmap::Camera& camera);

}  // namespace rig_calibrator
