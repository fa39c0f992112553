#include "src/calibration/rig_init_translations.h"

#include <colmap/util/math.h>

#include <Eigen/Cholesky>

namespace rig_calibrator {
namespace rig_init {
namespace {

// Iteratively reweighted least squares of the translations: iterations and
// the Cauchy scale in robust standard deviations of the residuals.
constexpr int kNumReweightings = 5;
constexpr double kTranslationCauchyScale = 3.0;

// The known rows of T X - A R_Q X at the image's scene center X: the
// right-hand side b_ij of eq. 3's translation rows once R_Q is known.
Eigen::VectorXd ObservedRows(const LocalizedImage& image,
                             const Eigen::MatrixXd& known_rows,
                             const Eigen::Quaterniond& rig_rotation) {
  return (image.cam_from_world * image.scene_center).head(known_rows.rows()) -
         known_rows * (rig_rotation * image.scene_center);
}

// Adds frameset j's images to the system: H_j and its right-hand side, then
// the reduced blocks and right-hand sides of its non-anchor cameras.
void AddFrameset(const InitProblem& problem,
                 const Eigen::Quaterniond& rig_rotation,
                 const DeterminedParts& parts,
                 const std::vector<double>& weights, int j,
                 ReducedTranslationSystem* system) {
  const int rows = problem.num_rows;
  std::vector<int> used;
  std::vector<Eigen::VectorXd> observed;
  for (const int index : problem.images_of_frameset[j]) {
    if (!parts.images[index]) continue;
    const LocalizedImage& image = problem.images[index];
    const Eigen::MatrixXd& a = system->known_rows[image.camera];
    observed.push_back(ObservedRows(image, a, rig_rotation));
    system->frameset_normal[j] += weights[index] * a.transpose() * a;
    system->frameset_rhs[j] += weights[index] * a.transpose() * observed.back();
    used.push_back(index);
  }
  const Eigen::Matrix3d inverse = system->frameset_normal[j].inverse();
  for (size_t n = 0; n < used.size(); ++n) {
    const int index = used[n];
    const LocalizedImage& image = problem.images[index];
    const int u = system->unknown_of_camera[image.camera];
    if (u < 0) continue;
    const Eigen::MatrixXd a_inverse =
        weights[index] * system->known_rows[image.camera] * inverse;
    system->reduced_rhs.segment(u, rows) +=
        weights[index] * observed[n] - a_inverse * system->frameset_rhs[j];
    system->reduced.block(u, u, rows, rows) +=
        weights[index] * Eigen::MatrixXd::Identity(rows, rows);
    for (const int other : used) {
      const int camera = problem.images[other].camera;
      const int v = system->unknown_of_camera[camera];
      if (v >= 0) {
        system->reduced.block(u, v, rows, rows) -=
            weights[other] * a_inverse * system->known_rows[camera].transpose();
      }
    }
  }
}

// Solves a reduced system: camera translations, then the framesets' t_Q.
Hypothesis SolveReducedSystem(const InitProblem& problem,
                              const Rotations& rotations,
                              const DeterminedParts& parts,
                              const std::vector<double>& weights,
                              const ReducedTranslationSystem& system) {
  Hypothesis hypothesis = EmptyHypothesis(problem);
  const int rows = problem.num_rows;
  const Eigen::VectorXd translations =
      system.reduced.ldlt().solve(system.reduced_rhs);
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (!parts.cameras[i]) continue;
    Eigen::Vector3d translation = Eigen::Vector3d::Zero();
    const int u = system.unknown_of_camera[i];
    if (u >= 0) translation.head(rows) = translations.segment(u, rows);
    hypothesis.cam_from_rig[i] =
        Rigid3d(*rotations.cam_from_rig[i], translation);
  }
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (!parts.framesets[j]) continue;
    Eigen::Vector3d rhs = system.frameset_rhs[j];
    for (const int index : problem.images_of_frameset[j]) {
      const int camera = problem.images[index].camera;
      if (parts.images[index]) {
        rhs -= weights[index] * system.known_rows[camera].transpose() *
               hypothesis.cam_from_rig[camera]->translation.head(rows);
      }
    }
    hypothesis.rig_from_world[j] =
        Rigid3d(*rotations.rig_from_world[j],
                system.frameset_normal[j].ldlt().solve(rhs));
  }
  return hypothesis;
}

// The Cauchy weights of the next reweighting (see SolveTranslations) from
// the residuals of the images of `parts` under the hypothesis. False if the
// residuals' scale is not positive (an exact fit: nothing to reweight).
bool UpdateWeights(const InitProblem& problem, const DeterminedParts& parts,
                   const Hypothesis& hypothesis, std::vector<double>* weights) {
  std::vector<double> residuals(problem.images.size(), 0);
  std::vector<double> used_residuals;
  for (size_t k = 0; k < problem.images.size(); ++k) {
    if (!parts.images[k]) continue;
    const LocalizedImage& image = problem.images[k];
    const Rigid3d composed = *hypothesis.cam_from_rig[image.camera] *
                             *hypothesis.rig_from_world[image.frameset];
    Eigen::Vector3d difference = composed * image.scene_center -
                                 image.cam_from_world * image.scene_center;
    if (problem.num_rows == 2) difference.z() = 0;
    residuals[k] = difference.norm();
    used_residuals.push_back(residuals[k]);
  }
  const double scale =
      kTranslationCauchyScale * 1.4826 * colmap::Median(used_residuals);
  if (!(scale > 0)) return false;
  for (size_t k = 0; k < problem.images.size(); ++k) {
    const double ratio = residuals[k] / scale;
    (*weights)[k] = 1.0 / (1.0 + ratio * ratio);
  }
  return true;
}

}  // namespace

ReducedTranslationSystem BuildReducedTranslationSystem(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_rotations,
    const std::vector<std::optional<Eigen::Quaterniond>>& rig_rotations,
    const DeterminedParts& parts, const std::vector<double>& weights,
    int anchor_camera) {
  const int rows = problem.num_rows;
  ReducedTranslationSystem system;
  system.unknown_of_camera.assign(problem.num_cameras, -1);
  system.known_rows.resize(problem.num_cameras);
  int num_unknowns = 0;
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (!parts.cameras[i]) continue;
    system.known_rows[i] = cam_rotations[i]->toRotationMatrix().topRows(rows);
    if (i != anchor_camera) {
      system.unknown_of_camera[i] = num_unknowns;
      num_unknowns += rows;
    }
  }
  system.reduced = Eigen::MatrixXd::Zero(num_unknowns, num_unknowns);
  system.reduced_rhs = Eigen::VectorXd::Zero(num_unknowns);
  system.frameset_normal.assign(problem.num_framesets, Eigen::Matrix3d::Zero());
  system.frameset_rhs.assign(problem.num_framesets, Eigen::Vector3d::Zero());
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (parts.framesets[j]) {
      AddFrameset(problem, *rig_rotations[j], parts, weights, j, &system);
    }
  }
  if (rows == 2 && num_unknowns > 0) {
    const Eigen::Vector3d anchor_axis =
        cam_rotations[anchor_camera]->toRotationMatrix().row(2);
    Eigen::VectorXd slide = Eigen::VectorXd::Zero(num_unknowns);
    for (int i = 0; i < problem.num_cameras; ++i) {
      const int u = system.unknown_of_camera[i];
      if (u >= 0) slide.segment<2>(u) = system.known_rows[i] * anchor_axis;
    }
    system.reduced += slide * slide.transpose();
  }
  return system;
}

Hypothesis SolveTranslations(const InitProblem& problem,
                             const Rotations& rotations,
                             const std::vector<char>& usable_images,
                             int preferred_anchor) {
  std::vector<char> usable = usable_images;
  for (size_t k = 0; k < problem.images.size(); ++k) {
    usable[k] =
        usable[k] &&
        rotations.rig_from_world[problem.images[k].frameset].has_value();
  }
  int anchor = 0;
  const DeterminedParts parts = FindTranslationDeterminedParts(
      problem, rotations.cam_from_rig, rotations.rig_from_world, usable, 1,
      preferred_anchor, &anchor);
  if (anchor == problem.num_cameras) return EmptyHypothesis(problem);
  std::vector<double> weights(problem.images.size(), 1.0);
  Hypothesis hypothesis =
      SolveReducedSystem(problem, rotations, parts, weights,
                         BuildReducedTranslationSystem(
                             problem, rotations.cam_from_rig,
                             rotations.rig_from_world, parts, weights, anchor));
  for (int iteration = 0; iteration < kNumReweightings; ++iteration) {
    if (!UpdateWeights(problem, parts, hypothesis, &weights)) break;
    hypothesis = SolveReducedSystem(
        problem, rotations, parts, weights,
        BuildReducedTranslationSystem(problem, rotations.cam_from_rig,
                                      rotations.rig_from_world, parts, weights,
                                      anchor));
  }
  return hypothesis;
}

}  // namespace rig_init
}  // namespace rig_calibrator
