// The reprojection residuals of one camera over its image (report.html):
// per grid cell the mean residual vector as an arrow from the cell centre,
// and the cell's RMS as its colour. A systematic pattern (arrows that agree
// over a region) shows a model that does not fit; noise gives short arrows in
// random directions.
#pragma once

#include <string>

#include "colmap_ext/report/model_residuals.h"

namespace rig_calibrator {

// `id`: the <svg> element's id, unique within the page. Arrows are scaled so
// that the longest mean residual is 90 % of a cell; a scale arrow says how
// many pixels of residual its length is.
std::string ResidualFieldSvg(const std::string& id, const std::string& title,
                             const CameraResiduals& residuals);

}  // namespace rig_calibrator
