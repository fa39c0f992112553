#include "src/calibration/model_choice_spread.h"

#include <algorithm>
#include <cmath>

namespace rig_calibrator {
namespace {

// The focal length along axis 0 (x) or 1 (y): a model's single f for both.
double FocalLengthAlong(const colmap::Camera& camera, int axis) {
  const std::vector<size_t>& idxs = camera.FocalLengthIdxs();
  return camera.Params()[idxs.size() == 1 ? idxs[0] : idxs[axis]];
}

// A quantity that every model has, read from any model (the chosen model's
// focal lengths decide between the mean and one per axis).
enum class Quantity { kMeanFocal, kFocalX, kFocalY, kPrincipalX, kPrincipalY };

double ValueOf(const colmap::Camera& camera, Quantity quantity) {
  switch (quantity) {
    case Quantity::kMeanFocal:
      return camera.MeanFocalLength();
    case Quantity::kFocalX:
      return FocalLengthAlong(camera, 0);
    case Quantity::kFocalY:
      return FocalLengthAlong(camera, 1);
    case Quantity::kPrincipalX:
      return camera.PrincipalPointX();
    case Quantity::kPrincipalY:
      return camera.PrincipalPointY();
  }
  return 0;
}

// The grouped jackknife's standard deviation of the quantity over the fold
// fits (0 with fewer than two).
double JackknifeStddev(const std::vector<colmap::Camera>& folds,
                       Quantity quantity) {
  const size_t k = folds.size();
  if (k < 2) return 0;
  double mean = 0;
  for (const colmap::Camera& fold : folds) mean += ValueOf(fold, quantity);
  mean /= k;
  double sum_squares = 0;
  for (const colmap::Camera& fold : folds) {
    sum_squares += std::pow(ValueOf(fold, quantity) - mean, 2);
  }
  return std::sqrt((k - 1.0) / k * sum_squares);
}

}  // namespace

std::vector<double> SharedParameterSpread(
    const colmap::Camera& chosen,
    const std::vector<AlternativeModelFit>& others) {
  std::vector<double> spread(chosen.NumParams(), 0.0);
  std::vector<std::pair<size_t, Quantity>> quantities;
  const std::vector<size_t>& focal_idxs = chosen.FocalLengthIdxs();
  if (focal_idxs.size() == 1) {
    quantities.emplace_back(focal_idxs[0], Quantity::kMeanFocal);
  } else {
    quantities.emplace_back(focal_idxs[0], Quantity::kFocalX);
    quantities.emplace_back(focal_idxs[1], Quantity::kFocalY);
  }
  const std::vector<size_t>& principal_idxs = chosen.PrincipalPointIdxs();
  quantities.emplace_back(principal_idxs[0], Quantity::kPrincipalX);
  quantities.emplace_back(principal_idxs[1], Quantity::kPrincipalY);
  for (const AlternativeModelFit& other : others) {
    for (const auto& [idx, quantity] : quantities) {
      const double difference =
          chosen.Params()[idx] - ValueOf(other.camera, quantity);
      spread[idx] =
          std::max(spread[idx], std::hypot(difference, JackknifeStddev(
                                                           other.folds,
                                                           quantity)));
    }
  }
  return spread;
}

void AddModelChoiceSpread(const std::vector<double>& spread,
                          CameraUncertainty* uncertainty) {
  if (spread.empty() || spread.size() != uncertainty->params_stddev.size()) {
    return;
  }
  uncertainty->model_choice_stddev.assign(spread.size(), 0.0);
  for (size_t k = 0; k < spread.size(); ++k) {
    double& stddev = uncertainty->params_stddev[k];
    // Held (0) and undetermined (NaN) parameters stay so.
    if (stddev > 0 && std::isfinite(stddev) && spread[k] > stddev) {
      stddev = spread[k];
      uncertainty->model_choice_stddev[k] = spread[k];
    }
  }
  if (std::all_of(uncertainty->model_choice_stddev.begin(),
                  uncertainty->model_choice_stddev.end(),
                  [](double s) { return s == 0; })) {
    uncertainty->model_choice_stddev.clear();
  }
}

}  // namespace rig_calibrator
