// The capture timing of the cameras (report.html): per camera its estimate
// (a dot, its value written next to it), a thick bar over +-1 sigma and a
// thin one over +-3 sigma, against a dashed zero line; one figure for the
// time offsets (ms), one for the line delays (us/row) when estimated
// (camera_timing.h says what the numbers are).
#pragma once

#include <string>
#include <vector>

namespace rig_calibrator {

struct TimingFigurePoint {
  std::string camera;
  double value = 0;  // in the figure's unit
  double sigma = 0;  // same unit; 0 for a value that is exact by definition
};

// `unit` is appended to the axis label and the values ("ms", "us/row").
std::string CaptureTimingSvg(const std::string& id, const std::string& title,
                             const std::string& unit,
                             const std::vector<TimingFigurePoint>& points);

}  // namespace rig_calibrator
