// The prior of the framesets' estimated translational velocities and
// accelerations e_f = [v_f, a_f] (the time model of the final bundle
// adjustment, final_bundle_adjuster.h; frameset_motion.h): their deviation
// d_f = e_f - [p1_f, p2_f] from the polynomial through the frameset poses,
// an autoregression from frameset to frameset (TranslationPrior):
//
//   TranslationPriorResidual       r = W_d,k d_f               (first of a run)
//   TranslationInnovationResidual  r = W_i,k (d_f - Phi d_(f-1)) (after it)
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
// 0.56 mm).
//
// [p1_f, p2_f] is the polynomial through the window's poses
// (TranslationStencil, frameset_motion.h), evaluated from the poses the
// solve is adjusting, not held at the values it started from: held, each
// solve pulled the velocities towards the previous solve's poses, and the
// result depended on how many solves ran (on the synthetic helmet at 15 Hz,
// seed 1, one camera's centre -1.59 mm after one solve, +0.66 mm after
// six, its sigma 0.35 mm; inside the solve +0.38, +0.40 and +0.39 mm after
// one, three and six); inside the solve one problem has the answer as its
// minimum, and its curvature, which the uncertainty step takes, sees the
// velocities' dependence on the poses. The weights and the prior are
// read by pointer at every evaluation: the adjustment recomputes them
// between solves.
#pragma once

#include <ceres/dynamic_autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <algorithm>
#include <memory>
#include <vector>

#include "src/geometry/frameset_motion.h"

namespace rig_calibrator {

// The polynomial's [p1, p2] at a frameset from its window's poses
// (`window_poses[j]` the PoseParams rig_from_world of stencil.window[j]):
// sum_j [w1_j; w2_j] p_j, p_j = R_f^T (c_j - c_f) = R(q_f) c_j + t_f with
// c_j = -R(q_j)^T t_j the knot's centre (p_f = 0: the own slot adds
// nothing, its pose enters through R(q_f) and t_f).
template <typename T>
void PolynomialTranslation(const TranslationStencil& stencil,
                           const T* const* window_poses, T* derivatives) {
  for (int k = 0; k < 6; ++k) derivatives[k] = T(0);
  const T* own = window_poses[stencil.own_slot];
  for (int j = 0; j < static_cast<int>(stencil.window.size()); ++j) {
    if (j == stencil.own_slot) continue;
    const T* knot = window_poses[j];
    const T conjugate[4] = {knot[0], -knot[1], -knot[2], -knot[3]};
    T centre[3];
    ceres::QuaternionRotatePoint(conjugate, knot + 4, centre);
    for (T& value : centre) value = -value;
    T position[3];
    ceres::QuaternionRotatePoint(own, centre, position);
    for (int axis = 0; axis < 3; ++axis) {
      position[axis] += own[4 + axis];
      derivatives[axis] += stencil.weights(0, j) * position[axis];
      derivatives[3 + axis] += stencil.weights(1, j) * position[axis];
    }
  }
}

// Rows first_row and first_row + 1 of W_d (e_f - [p1_f, p2_f]).
// Parameters: e_f, then the window's poses in its order.
class TranslationPriorResidual {
 public:
  TranslationPriorResidual(const TranslationStencil* stencil,
                           const TranslationPrior* prior, int first_row)
      : stencil_(stencil), prior_(prior), first_row_(first_row) {}

  template <typename T>
  bool operator()(T const* const* parameters, T* residuals) const {
    T polynomial[6];
    PolynomialTranslation(*stencil_, parameters + 1, polynomial);
    for (int row = 0; row < 2; ++row) {
      residuals[row] = T(0);
      for (int k = 0; k < 6; ++k) {
        residuals[row] += prior_->whitening(first_row_ + row, k) *
                          (parameters[0][k] - polynomial[k]);
      }
    }
    return true;
  }

 private:
  const TranslationStencil* stencil_;
  const TranslationPrior* prior_;
  const int first_row_;
};

// Rows first_row and first_row + 1 of W_i (d_f - Phi d_(f-1)), d = e -
// [p1, p2] of each frameset. Parameters: e_f, e_(f-1), then the poses of
// both windows, each once (`parameter_of_pose`: the parameter index of
// each window slot, frameset f's then f - 1's).
class TranslationInnovationResidual {
 public:
  TranslationInnovationResidual(const TranslationStencil* stencil,
                                const TranslationStencil* previous_stencil,
                                const TranslationPrior* prior, int first_row,
                                std::vector<int> parameter_of_pose)
      : stencil_(stencil),
        previous_stencil_(previous_stencil),
        prior_(prior),
        first_row_(first_row),
        parameter_of_pose_(std::move(parameter_of_pose)) {}

  template <typename T>
  bool operator()(T const* const* parameters, T* residuals) const {
    const size_t size = stencil_->window.size();
    std::vector<const T*> poses;
    for (const int index : parameter_of_pose_) {
      poses.push_back(parameters[index]);
    }
    T polynomial[6], previous_polynomial[6];
    PolynomialTranslation(*stencil_, poses.data(), polynomial);
    PolynomialTranslation(*previous_stencil_, poses.data() + size,
                          previous_polynomial);
    T innovation[6];
    for (int i = 0; i < 6; ++i) {
      innovation[i] = parameters[0][i] - polynomial[i];
      for (int k = 0; k < 6; ++k) {
        innovation[i] -= prior_->predecessor_gain(i, k) *
                         (parameters[1][k] - previous_polynomial[k]);
      }
    }
    for (int row = 0; row < 2; ++row) {
      residuals[row] = T(0);
      for (int k = 0; k < 6; ++k) {
        residuals[row] +=
            prior_->innovation_whitening(first_row_ + row, k) * innovation[k];
      }
    }
    return true;
  }

 private:
  const TranslationStencil* stencil_;
  const TranslationStencil* previous_stencil_;
  const TranslationPrior* prior_;
  const int first_row_;
  const std::vector<int> parameter_of_pose_;
};

// Frameset f's prior: its three costs (first_row 0, 2, 4) with their
// parameter blocks, the innovation where the previous frameset is in the
// problem too (`after_previous`), else the frameset's own. `stencils`,
// `rig_poses` (PoseParams per frameset, null without a pose) and
// `estimates` per frameset; the stencils' weights and the prior are read by
// pointer (see above), their windows at construction.
struct TranslationPriorTerm {
  std::unique_ptr<ceres::CostFunction> cost;
  std::vector<double*> parameters;
};

inline std::vector<TranslationPriorTerm> MakeTranslationPriorTerms(
    const std::vector<TranslationStencil>& stencils,
    const std::vector<double*>& rig_poses,
    std::vector<TranslationDerivatives>* estimates, size_t f,
    bool after_previous, const TranslationPrior* prior) {
  // Stride 4 of the automatic derivatives: a pose's 7 values in two passes.
  constexpr int kStride = 4;
  std::vector<TranslationPriorTerm> terms;
  for (const int first_row : {0, 2, 4}) {
    TranslationPriorTerm term;
    term.parameters.push_back((*estimates)[f].data());
    std::vector<int> blocks = {6};
    if (after_previous) {
      term.parameters.push_back((*estimates)[f - 1].data());
      blocks.push_back(6);
      std::vector<int> parameter_of_pose;
      std::vector<int> framesets;  // of the pose parameters, in their order
      for (const std::vector<int>* window :
           {&stencils[f].window, &stencils[f - 1].window}) {
        for (const int frameset : *window) {
          auto it = std::find(framesets.begin(), framesets.end(), frameset);
          if (it == framesets.end()) {
            framesets.push_back(frameset);
            term.parameters.push_back(rig_poses[frameset]);
            blocks.push_back(7);
            it = framesets.end() - 1;
          }
          parameter_of_pose.push_back(2 +
                                      static_cast<int>(it - framesets.begin()));
        }
      }
      auto* cost =
          new ceres::DynamicAutoDiffCostFunction<TranslationInnovationResidual,
                                                 kStride>(
              new TranslationInnovationResidual(&stencils[f], &stencils[f - 1],
                                                prior, first_row,
                                                std::move(parameter_of_pose)));
      for (const int size : blocks) cost->AddParameterBlock(size);
      cost->SetNumResiduals(2);
      term.cost.reset(cost);
    } else {
      for (const int frameset : stencils[f].window) {
        term.parameters.push_back(rig_poses[frameset]);
        blocks.push_back(7);
      }
      auto* cost =
          new ceres::DynamicAutoDiffCostFunction<TranslationPriorResidual,
                                                 kStride>(
              new TranslationPriorResidual(&stencils[f], prior, first_row));
      for (const int size : blocks) cost->AddParameterBlock(size);
      cost->SetNumResiduals(2);
      term.cost.reset(cost);
    }
    terms.push_back(std::move(term));
  }
  return terms;
}

}  // namespace rig_calibrator
