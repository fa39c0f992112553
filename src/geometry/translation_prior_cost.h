// The prior of the framesets' estimated translational velocities and
// accelerations e_f = [v_f, a_f] (the time model of the final bundle
// adjustment, final_bundle_adjuster.h; frameset_motion.h): their deviation
// d_f = e_f - [p1_f, p2_f] from the polynomial through the frameset poses,
// an autoregression from frameset to frameset (TranslationPrior):
//
//   TranslationPriorCost        r = W_d,k d_f                (first of a run)
//   TranslationInnovationCost   r = W_i,k (d_f - Phi d_(f-1))  (after it)
//
// in pixels, W_k rows k = first_row and k + 1 of the whitening (three
// costs, first_row 0, 2, 4, make one frameset's prior), so that a
// deviation of one standard deviation in any direction costs what one
// pixel of reprojection error costs. The images override the prior where
// they see the motion (different cameras' offsets, rolling-shutter rows);
// it holds what they do not see: a frameset seen at one instant, and the
// velocity error common to all framesets, which moves every camera by
// delta_c times it exactly as a change of its cam_from_rig centre would
// (with the RMS speed as the deviation instead, the synthetic ring at 5 Hz
// with offsets kept 2.3 mm of centre error; with the estimated one
// 0.56 mm). p1, p2 and the prior are read by pointer at every evaluation:
// the adjustment recomputes them between solves.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "src/geometry/frameset_motion.h"

namespace rig_calibrator {

// Parameters: e_f.
class TranslationPriorCost final : public ceres::SizedCostFunction<2, 6> {
 public:
  TranslationPriorCost(const FramesetMotion* motion,
                       const TranslationPrior* prior, int first_row)
      : motion_(motion), prior_(prior), first_row_(first_row) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const TranslationDerivatives> estimate(parameters[0]);
    const Eigen::Map<const TranslationDerivatives> polynomial(&(*motion_)[9]);
    const auto rows = prior_->whitening.middleRows<2>(first_row_);
    Eigen::Map<Eigen::Vector2d> residual(residuals);
    residual = rows * (estimate - polynomial);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 2, 6, Eigen::RowMajor>> jacobian(
          jacobians[0]);
      jacobian = rows;
    }
    return true;
  }

 private:
  const FramesetMotion* motion_;
  const TranslationPrior* prior_;
  const int first_row_;
};

// Parameters: e_f, e_(f-1).
class TranslationInnovationCost final
    : public ceres::SizedCostFunction<2, 6, 6> {
 public:
  TranslationInnovationCost(const FramesetMotion* motion,
                            const FramesetMotion* previous_motion,
                            const TranslationPrior* prior, int first_row)
      : motion_(motion),
        previous_motion_(previous_motion),
        prior_(prior),
        first_row_(first_row) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const TranslationDerivatives deviation =
        Eigen::Map<const TranslationDerivatives>(parameters[0]) -
        Eigen::Map<const TranslationDerivatives>(&(*motion_)[9]);
    const TranslationDerivatives previous_deviation =
        Eigen::Map<const TranslationDerivatives>(parameters[1]) -
        Eigen::Map<const TranslationDerivatives>(&(*previous_motion_)[9]);
    const auto rows = prior_->innovation_whitening.middleRows<2>(first_row_);
    Eigen::Map<Eigen::Vector2d> residual(residuals);
    residual =
        rows * (deviation - prior_->predecessor_gain * previous_deviation);
    if (jacobians == nullptr) return true;
    using Jacobian = Eigen::Matrix<double, 2, 6, Eigen::RowMajor>;
    if (jacobians[0] != nullptr) {
      Eigen::Map<Jacobian> jacobian(jacobians[0]);
      jacobian = rows;
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<Jacobian> jacobian(jacobians[1]);
      jacobian = -rows * prior_->predecessor_gain;
    }
    return true;
  }

 private:
  const FramesetMotion* motion_;
  const FramesetMotion* previous_motion_;
  const TranslationPrior* prior_;
  const int first_row_;
};

// Frameset f's prior: its three costs (first_row 0, 2, 4) with their
// parameter blocks, a TranslationInnovationCost where the previous frameset
// is in the problem too (`after_previous`), else a TranslationPriorCost.
// `motions` and `estimates` per frameset, read by pointer (see above).
struct TranslationPriorTerm {
  std::unique_ptr<ceres::CostFunction> cost;
  std::vector<double*> parameters;
};

inline std::vector<TranslationPriorTerm> MakeTranslationPriorTerms(
    const std::vector<FramesetMotion>& motions,
    std::vector<TranslationDerivatives>* estimates, size_t f,
    bool after_previous, const TranslationPrior* prior) {
  std::vector<TranslationPriorTerm> terms;
  for (const int first_row : {0, 2, 4}) {
    TranslationPriorTerm term;
    term.parameters.push_back((*estimates)[f].data());
    if (after_previous) {
      term.cost = std::make_unique<TranslationInnovationCost>(
          &motions[f], &motions[f - 1], prior, first_row);
      term.parameters.push_back((*estimates)[f - 1].data());
    } else {
      term.cost =
          std::make_unique<TranslationPriorCost>(&motions[f], prior, first_row);
    }
    terms.push_back(std::move(term));
  }
  return terms;
}

}  // namespace rig_calibrator
