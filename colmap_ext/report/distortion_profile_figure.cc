#include "colmap_ext/report/distortion_profile_figure.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "colmap_ext/report/svg_plot.h"

namespace rig_calibrator {
namespace {

Eigen::Vector2d PrincipalPoint(const colmap::Camera& camera) {
  return Eigen::Vector2d(camera.PrincipalPointX(), camera.PrincipalPointY());
}

// The image corner farthest from the principal point.
Eigen::Vector2d FarthestCorner(const colmap::Camera& camera) {
  const Eigen::Vector2d principal_point = PrincipalPoint(camera);
  Eigen::Vector2d farthest = Eigen::Vector2d::Zero();
  for (const double u : {0.0, static_cast<double>(camera.Width())}) {
    for (const double v : {0.0, static_cast<double>(camera.Height())}) {
      const Eigen::Vector2d corner(u, v);
      if ((corner - principal_point).norm() >
          (farthest - principal_point).norm()) {
        farthest = corner;
      }
    }
  }
  return farthest;
}

}  // namespace

double CornerRadiusPx(const colmap::Camera& camera) {
  return (FarthestCorner(camera) - PrincipalPoint(camera)).norm();
}

std::string DistortionProfileSvg(const DistortionProfileOptions& options,
                                 const colmap::Camera& camera) {
  constexpr double kDegree = M_PI / 180;
  const Eigen::Vector2d principal_point = PrincipalPoint(camera);
  const double corner_radius = CornerRadiusPx(camera);
  Eigen::Vector2d direction = FarthestCorner(camera) - principal_point;
  if (direction.norm() > 0) direction.normalize();
  // The same image direction in normalized coordinates (x / fx, y / fy).
  const std::vector<size_t>& focal_idxs = camera.FocalLengthIdxs();
  const double fx = camera.Params(focal_idxs.front());
  const double fy = camera.Params(focal_idxs.back());
  Eigen::Vector2d ray_direction(direction.x() / fx, direction.y() / fy);
  if (ray_direction.norm() > 0) ray_direction.normalize();
  const double focal = camera.MeanFocalLength();

  PlotSeries model{camera.ModelName(), {}, {}, false};
  PlotSeries pinhole{"pinhole, same focal", {}, {}, false};
  for (double angle = 0; angle <= 89.5; angle += 0.25) {
    const double tangent = std::tan(angle * kDegree);
    const Eigen::Vector2d image = camera.WorldToImage(tangent * ray_direction);
    model.x.push_back((image - principal_point).norm());
    model.y.push_back(angle);
    pinhole.x.push_back(focal * tangent);
    pinhole.y.push_back(angle);
  }
  PlotOptions plot;
  plot.inline_id = options.id;
  plot.title = options.title;
  plot.x_label = "distance from the principal point (px)";
  plot.y_label = "angle from the optical axis (deg)";
  plot.width = 560;
  plot.height = 300;
  plot.x_min = 0;
  plot.x_max = 1.15 * corner_radius;
  plot.y_min = 0;
  plot.y_max = 90;
  plot.x_markers = {options.min_observed_radius_px,
                    options.max_observed_radius_px, corner_radius};
  plot.x_marker_labels = {"observed min", "observed max", "corner"};
  return LinePlotSvg(plot, {model, pinhole});
}

}  // namespace rig_calibrator
