#include "src/experiments/paper_methods.h"

namespace rig_calibrator {

std::vector<CalibrationMethod> AccuracyTableMethods() {
  return {CalibrationMethod::kKnown, CalibrationMethod::kKnownRefine,
          CalibrationMethod::kRd, CalibrationMethod::kRdRa,
          CalibrationMethod::kRadial1D};
}

std::vector<CalibrationMethod> RobustnessTableMethods() {
  return {CalibrationMethod::kRd, CalibrationMethod::kRdRa,
          CalibrationMethod::kRadial1D};
}

}  // namespace rig_calibrator
