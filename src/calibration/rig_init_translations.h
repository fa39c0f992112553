// Internal to the rig initialization (rig_init_problem.h): the translation
// part of one RANSAC hypothesis, given its rotations (paper eq. 3).
//
// Given the rotations, the known translation rows are linear in the
// unknowns: per used image (camera i, frameset j), with A_i the known rows of
// R_P (2 radial, 3 full), comparing the camera-frame positions of the
// image's scene center X,
//   A_i (R_Q,j X + t_Q,j) + t_P,i = rows of T_ij X, i.e.
//   A_i t_Q,j + t_P,i = b_ij   (t_P,i: the known rows of camera i's t),
// weighted by w_ij. Eliminating t_Q,j = H_j^-1 (sum_i w_i A_i^T (b_ij -
// t_P,i)), H_j = sum_i w_i A_i^T A_i, leaves, per pair of images (i, k) of a
// frameset, the block w_i delta_ik I - w_i w_k A_i H_j^-1 A_k^T, and the
// right-hand side w_i (b_ij - A_i H_j^-1 sum_k w_k A_k^T b_kj). Gauge: the
// anchor camera's t_P = 0 and, when radial, the slide of the rig origin
// along the anchor's axis z (t_P,i += d (R_P,i z)_xy for all i) is fixed by
// sum_i v_i^T t_P,i = 0 with v_i = (R_P,i z)_xy.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "src/calibration/rig_init_determinedness.h"
#include "src/calibration/rig_init_problem.h"
#include "src/calibration/rig_init_rotations.h"

namespace rig_calibrator {
namespace rig_init {

// The translations' weighted least-squares problem after eliminating the
// framesets' t_Q: reduced * t_P = reduced_rhs over the t_P of the
// non-anchor cameras (gauge included).
struct ReducedTranslationSystem {
  std::vector<int> unknown_of_camera;  // offset into t_P, -1: anchor/unused
  std::vector<Eigen::MatrixXd> known_rows;  // per camera, rows of R_P
  Eigen::MatrixXd reduced;
  Eigen::VectorXd reduced_rhs;
  // Per frameset: H_j = sum_i w_i A_i^T A_i and sum_i w_i A_i^T b_ij.
  std::vector<Eigen::Matrix3d> frameset_normal;
  std::vector<Eigen::Vector3d> frameset_rhs;
};

// The reduced system over the images, framesets and cameras of `parts`
// (weights per localized image).
ReducedTranslationSystem BuildReducedTranslationSystem(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_rotations,
    const std::vector<std::optional<Eigen::Quaterniond>>& rig_rotations,
    const DeterminedParts& parts, const std::vector<double>& weights,
    int anchor_camera);

// Translations by least squares over the usable images jointly, so that each
// camera draws on every frameset it shares with any other camera. Cameras in
// undetermined directions are dropped first (FindTranslationDeterminedParts,
// anchor preferred_anchor). A per-image pose with a right rotation and a
// wrong translation (a wrong place that looks alike) would pull the
// solution, so it is iteratively reweighted: Cauchy weights
// 1 / (1 + (r / (c sigma))^2) on the norm r of each image's residual
// A_i t_Q + t_P,i - b_ij, with sigma = 1.4826 median(r) (no absolute scale:
// the map's units are unknown). Returns the hypothesis with the rotations
// and translations of the determined cameras and framesets; empty if none.
Hypothesis SolveTranslations(const InitProblem& problem,
                             const Rotations& rotations,
                             const std::vector<char>& usable_images,
                             int preferred_anchor);

}  // namespace rig_init
}  // namespace rig_calibrator
