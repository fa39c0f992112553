#include "src/calibration/calibration_method.h"

#include <utility>
#include <vector>

namespace rig_calibrator {
namespace {

const std::vector<std::pair<CalibrationMethod, std::string>>& MethodNames() {
  static const std::vector<std::pair<CalibrationMethod, std::string>> names = {
      {CalibrationMethod::kKnown, "known"},
      {CalibrationMethod::kKnownRefine, "known_refine"},
      {CalibrationMethod::kKnownRa, "known_ra"},
      {CalibrationMethod::kRd, "rd"},
      {CalibrationMethod::kRdRa, "rd_ra"},
      {CalibrationMethod::kRadial1D, "1dr"}};
  return names;
}

}  // namespace

bool CalibrationMethodFromName(const std::string& name,
                               CalibrationMethod* method) {
  for (const auto& [value, value_name] : MethodNames()) {
    if (value_name == name) {
      *method = value;
      return true;
    }
  }
  return false;
}

std::string CalibrationMethodName(CalibrationMethod method) {
  for (const auto& [value, value_name] : MethodNames()) {
    if (value == method) return value_name;
  }
  return "unknown";
}

bool UsesKnownIntrinsics(CalibrationMethod method) {
  return method == CalibrationMethod::kKnown ||
         method == CalibrationMethod::kKnownRefine ||
         method == CalibrationMethod::kKnownRa;
}

bool UsesCompleteFramesetInitialization(CalibrationMethod method) {
  return method == CalibrationMethod::kKnown ||
         method == CalibrationMethod::kKnownRefine ||
         method == CalibrationMethod::kRd;
}

bool RefinesIntrinsics(CalibrationMethod method) {
  return method != CalibrationMethod::kKnown &&
         method != CalibrationMethod::kKnownRa;
}

InitialPoseModel InitialPoseModelOf(CalibrationMethod method) {
  if (method == CalibrationMethod::kRadial1D) return InitialPoseModel::kRadial;
  return UsesKnownIntrinsics(method) ? InitialPoseModel::kKnownIntrinsics
                                     : InitialPoseModel::kPoseAndIntrinsics;
}

}  // namespace rig_calibrator
