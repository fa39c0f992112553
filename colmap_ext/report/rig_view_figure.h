// The rig seen from above and from the side (report.html): each camera's
// position in the rig frame (the reference camera's frame: x right, y down,
// z forward) with its x, y and z axes, and its 1-sigma position uncertainty
// as an ellipse where it is at least a pixel at the figure's scale.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace rig_calibrator {

struct RigViewCamera {
  std::string name;
  Eigen::Vector3d center_in_rig = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rig_from_cam = Eigen::Matrix3d::Identity();  // axes columns
  std::optional<Eigen::Vector3d> center_stddev;  // per rig axis, map units
};

enum class RigView {
  kFromAbove,  // x to the right, z (forward) up the page
  kFromSide,   // z (forward) to the right, -y (up) up the page
};

struct RigViewFigure {
  std::string svg;
  // Cameras with an uncertainty whose ellipse is under a pixel here.
  std::vector<std::string> ellipses_too_small;
};

// `id`: the <svg> element's id, unique within the page; `units`: the map's
// units, for the scale bar.
RigViewFigure RigViewSvg(const std::string& id, RigView view,
                         const std::vector<RigViewCamera>& cameras,
                         const std::string& units);

}  // namespace rig_calibrator
