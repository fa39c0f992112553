// The reprojection error per frameset (report.html): the RMS of every
// camera's image in each frameset and of the whole frameset, against the
// frameset's index, so that framesets that fit worse than the rest stand out.
#pragma once

#include <string>
#include <vector>

#include "colmap_ext/report/model_residuals.h"

namespace rig_calibrator {

// `id`: the <svg> element's id, unique within the page; `camera_names` in the
// order of FramesetError::camera_rms_px.
std::string FramesetErrorsSvg(const std::string& id,
                              const std::vector<FramesetError>& framesets,
                              const std::vector<std::string>& camera_names);

// Indices of the framesets whose RMS is above `factor` times the median of
// all framesets' RMS, worst first.
std::vector<int> OutlyingFramesets(const std::vector<FramesetError>& framesets,
                                   double factor);

}  // namespace rig_calibrator
