#include "src/calibration/rig_initializer.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <colmap/util/threading.h>
#include <glog/logging.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <utility>
#include <vector>

#include "src/geometry/radial_error.h"

namespace rig_calibrator {
namespace {

// Scoring never needs every correspondence: an evenly spread subset of each
// image's inliers is enough to tell a right rig from a wrong one.
constexpr int kMaxScoredCorrespondences = 64;
// An image agrees with a rig hypothesis if its own pose and the rig's pose
// P_i Q_j each put at least this many of its scored inliers within the
// truncation, and neither explains less than kMinAgreementRatio of what the
// other explains. Both poses explaining the same >= 5 correspondences makes
// them the same radial pose; the ratio (rather than an absolute share) keeps
// the test meaningful when the principal point is still off.
constexpr int kMinAgreeingInliers = 5;
constexpr double kMinAgreementRatio = 0.5;
// Consensus rotations compare every candidate with every other: an evenly
// spread subset bounds the quadratic cost.
constexpr int kMaxRotationCandidates = 50;
// Scoring a hypothesis runs on several threads from this many images per
// thread on: below, starting threads costs more than it saves.
constexpr size_t kMinImagesPerThread = 256;
// Sweeps re-estimating every rotation after the greedy assignment.
constexpr int kNumRotationSweeps = 2;
// Iteratively reweighted least squares of the translations: iterations and
// the Cauchy scale in robust standard deviations of the residuals.
constexpr int kNumReweightings = 5;
constexpr double kTranslationCauchyScale = 3.0;
// A kept camera needs this many agreeing images: a wrong per-image pose
// always agrees with the camera pose made from it.
constexpr int kMinAgreeingImagesPerCamera = 2;

// A localized image with what the initializer scores it on.
struct LocalizedImage {
  int camera = -1;
  int frameset = -1;
  Rigid3d cam_from_world;                 // radial: translation.z() = 0
  std::vector<Eigen::Vector2d> points2D;  // centered, scored inlier subset
  std::vector<Eigen::Vector3d> points3D;
  int num_own_inliers = 0;  // scored inliers within the truncation
  // Centroid of the scored map points. Translations are compared there
  // (eq. 3, eq. 4) rather than at the map's origin, whose distance would
  // scale every rotation error into the translations.
  Eigen::Vector3d scene_center = Eigen::Vector3d::Zero();
};

struct InitProblem {
  RigInitializerOptions options;
  int num_cameras = 0;
  int num_framesets = 0;
  int reference_camera = 0;
  int num_rows = 2;  // known rows of each pose: 2 radial, 3 full
  // Smallest eigenvalue of sum_k (I - z_k z_k^T) over the cameras' axes z_k
  // that determines a rig translation in eq. 3: 1 - cos(minimum angle).
  double min_axis_eigenvalue = 0;
  double max_rotation_deviation = 0;  // radians
  int num_threads = 1;
  std::vector<LocalizedImage> images;
  std::vector<std::vector<int>> images_of_frameset;
  std::vector<std::vector<int>> images_of_camera;
};

struct Hypothesis {
  std::vector<std::optional<Rigid3d>> cam_from_rig;    // P_i
  std::vector<std::optional<Rigid3d>> rig_from_world;  // Q_j
};

struct ImageFit {
  double truncated_sq_sum = 0;  // sum of min(e, tau)^2, pixels^2
  int num_within = 0;           // e < tau on the correct half-line
};

ImageFit FitImage(const Rigid3d& cam_from_world, const LocalizedImage& image,
                  double max_error) {
  ImageFit fit;
  for (size_t k = 0; k < image.points2D.size(); ++k) {
    const double error = RadialReprojectionError(
        cam_from_world, image.points2D[k], image.points3D[k]);
    if (error < max_error) {
      fit.truncated_sq_sum += error * error;
      ++fit.num_within;
    } else {
      fit.truncated_sq_sum += max_error * max_error;
    }
  }
  return fit;
}

bool Agree(int num_own_inliers, int num_rig_inliers) {
  const int fewer = std::min(num_own_inliers, num_rig_inliers);
  const int more = std::max(num_own_inliers, num_rig_inliers);
  return fewer >= kMinAgreeingInliers && fewer >= kMinAgreementRatio * more;
}

Eigen::Vector3d PrincipalAxis(const Rigid3d& cam_from_x) {
  return cam_from_x.RotationMatrix().row(2).transpose();
}

// sum_k (I - z_k z_k^T): the normal matrix of the translation in eq. 3 with
// radial poses; singular iff all axes z_k are parallel.
double SmallestAxisEigenvalue(const std::vector<Eigen::Vector3d>& axes) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& axis : axes) {
    normal += Eigen::Matrix3d::Identity() - axis * axis.transpose();
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(normal,
                                                        Eigen::EigenvaluesOnly)
      .eigenvalues()(0);
}

// Per localized image: its fit under the hypothesis, or nullopt if its camera
// or frameset is unassigned.
std::vector<std::optional<ImageFit>> FitHypothesis(
    const InitProblem& problem, const Hypothesis& hypothesis) {
  std::vector<std::optional<ImageFit>> fits(problem.images.size());
#pragma omp parallel for schedule(dynamic) num_threads( \
    problem.num_threads) if (problem.images.size() >= kMinImagesPerThread * 2)
  for (size_t k = 0; k < problem.images.size(); ++k) {
    const LocalizedImage& image = problem.images[k];
    if (hypothesis.cam_from_rig[image.camera] &&
        hypothesis.rig_from_world[image.frameset]) {
      fits[k] = FitImage(*hypothesis.cam_from_rig[image.camera] *
                             *hypothesis.rig_from_world[image.frameset],
                         image, problem.options.max_radial_error_px);
    }
  }
  return fits;
}

// Sum of min(e, tau)^2 over all scored correspondences; tau^2 for those of
// images the hypothesis does not cover. Summed in image order, so the result
// does not depend on the number of threads.
double TruncatedScore(const InitProblem& problem,
                      const std::vector<std::optional<ImageFit>>& fits) {
  const double max_error_sq =
      problem.options.max_radial_error_px * problem.options.max_radial_error_px;
  double score = 0;
  for (size_t k = 0; k < fits.size(); ++k) {
    score += fits[k] ? fits[k]->truncated_sq_sum
                     : max_error_sq * problem.images[k].points2D.size();
  }
  return score;
}

std::vector<char> AgreeingImages(
    const InitProblem& problem,
    const std::vector<std::optional<ImageFit>>& fits) {
  std::vector<char> agree(problem.images.size(), 0);
  for (size_t k = 0; k < fits.size(); ++k) {
    agree[k] = fits[k] &&
               Agree(problem.images[k].num_own_inliers, fits[k]->num_within);
  }
  return agree;
}

// Rotation part of a hypothesis: R_P per camera, R_Q per frameset.
struct Rotations {
  std::vector<std::optional<Eigen::Quaterniond>> cam_from_rig;
  std::vector<std::optional<Eigen::Quaterniond>> rig_from_world;
};

double AngleRad(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return 2 * std::acos(std::min(1.0, std::abs(a.dot(b))));
}

struct RotationEstimate {
  Eigen::Quaterniond rotation;
  int support = 0;  // candidates within the rotation tolerance of it
};

// The candidate most others agree with (within max_angle; ties: the smaller
// sum of angles), refined as the chordal mean of the agreeing ones,
// NearestRotation(sum_k R_k). An evenly spread subset bounds the cost.
std::optional<RotationEstimate> ConsensusRotation(
    std::vector<Eigen::Quaterniond> candidates, double max_angle) {
  if (candidates.empty()) return std::nullopt;
  if (candidates.size() > kMaxRotationCandidates) {
    std::vector<Eigen::Quaterniond> subset;
    for (int k = 0; k < kMaxRotationCandidates; ++k) {
      subset.push_back(
          candidates[k * candidates.size() / kMaxRotationCandidates]);
    }
    candidates.swap(subset);
  }
  int best = 0, best_support = -1;
  double best_angle_sum = 0;
  for (size_t m = 0; m < candidates.size(); ++m) {
    int support = 0;
    double angle_sum = 0;
    for (const Eigen::Quaterniond& other : candidates) {
      const double angle = AngleRad(candidates[m], other);
      if (angle < max_angle) {
        ++support;
        angle_sum += angle;
      }
    }
    if (support > best_support ||
        (support == best_support && angle_sum < best_angle_sum)) {
      best = m;
      best_support = support;
      best_angle_sum = angle_sum;
    }
  }
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const Eigen::Quaterniond& other : candidates) {
    if (AngleRad(candidates[best], other) < max_angle) {
      sum += other.toRotationMatrix();
    }
  }
  RotationEstimate estimate;
  estimate.rotation = Eigen::Quaterniond(NearestRotation(sum));
  estimate.support = best_support;
  return estimate;
}

// R_Q of a frameset from its images of cameras with a rotation:
// R_Q = R_P^T R_T per image.
std::optional<RotationEstimate> FramesetRotation(const InitProblem& problem,
                                                 const Rotations& rotations,
                                                 int frameset) {
  std::vector<Eigen::Quaterniond> candidates;
  for (const int index : problem.images_of_frameset[frameset]) {
    const LocalizedImage& image = problem.images[index];
    if (rotations.cam_from_rig[image.camera]) {
      candidates.push_back(rotations.cam_from_rig[image.camera]->conjugate() *
                           image.cam_from_world.rotation);
    }
  }
  return ConsensusRotation(candidates, problem.max_rotation_deviation);
}

// R_P of a camera from its images in framesets with a rotation:
// R_P = R_T R_Q^T per image.
std::optional<RotationEstimate> CameraRotation(const InitProblem& problem,
                                               const Rotations& rotations,
                                               int camera) {
  std::vector<Eigen::Quaterniond> candidates;
  for (const int index : problem.images_of_camera[camera]) {
    const LocalizedImage& image = problem.images[index];
    if (rotations.rig_from_world[image.frameset]) {
      candidates.push_back(
          image.cam_from_world.rotation *
          rotations.rig_from_world[image.frameset]->conjugate());
    }
  }
  return ConsensusRotation(candidates, problem.max_rotation_deviation);
}

// Assigns the pending estimates with at least min_support. Returns whether
// anything was assigned.
bool AssignSupported(
    const std::vector<std::optional<RotationEstimate>>& pending,
    int min_support,
    std::vector<std::optional<Eigen::Quaterniond>>* rotations) {
  bool assigned = false;
  for (size_t k = 0; k < pending.size(); ++k) {
    if (pending[k] && pending[k]->support >= min_support) {
      (*rotations)[k] = pending[k]->rotation;
      assigned = true;
    }
  }
  return assigned;
}

// The greedy back-and-forth assignment of one RANSAC trial, on rotations.
// With radial poses every image's rotation is complete (its third row is the
// cross product of the first two), so one camera with a rotation places a
// frameset's rotation and one frameset places a camera's: framesets of 2-3
// cameras still connect the whole rig. The seed frameset places its cameras
// relative to a base camera (the reference camera if there), whose frame is
// the hypothesis' rig frame. After the greedy pass, sweeps re-estimate every
// rotation but the base camera's from all the others, which repairs early
// choices made on little support.
Rotations AssignRotationsGreedily(const InitProblem& problem, int seed_frameset,
                                  int* base_camera) {
  Rotations rotations;
  rotations.cam_from_rig.resize(problem.num_cameras);
  rotations.rig_from_world.resize(problem.num_framesets);
  const std::vector<int>& seed_images =
      problem.images_of_frameset[seed_frameset];
  int base = seed_images.front();
  for (const int index : seed_images) {
    if (problem.images[index].camera == problem.reference_camera) base = index;
  }
  *base_camera = problem.images[base].camera;
  const Eigen::Quaterniond seed_rotation =
      problem.images[base].cam_from_world.rotation;
  rotations.rig_from_world[seed_frameset] = seed_rotation;
  for (const int index : seed_images) {
    const LocalizedImage& image = problem.images[index];
    rotations.cam_from_rig[image.camera] =
        image.cam_from_world.rotation * seed_rotation.conjugate();
  }

  std::vector<std::optional<RotationEstimate>> pending_framesets(
      problem.num_framesets);
  std::vector<std::optional<RotationEstimate>> pending_cameras(
      problem.num_cameras);
  while (true) {
    for (int j = 0; j < problem.num_framesets; ++j) {
      pending_framesets[j] = rotations.rig_from_world[j]
                                 ? std::nullopt
                                 : FramesetRotation(problem, rotations, j);
    }
    for (int i = 0; i < problem.num_cameras; ++i) {
      pending_cameras[i] = rotations.cam_from_rig[i]
                               ? std::nullopt
                               : CameraRotation(problem, rotations, i);
    }
    // Estimates confirmed by two images first (framesets and cameras: `|`
    // does not short-circuit). Then framesets resting on one image (a wrong
    // one spoils that frameset only), and cameras resting on one image last
    // (a wrong one spoils all that is placed through it).
    const bool assigned_confirmed =
        AssignSupported(pending_framesets, 2, &rotations.rig_from_world) |
        AssignSupported(pending_cameras, 2, &rotations.cam_from_rig);
    if (assigned_confirmed ||
        AssignSupported(pending_framesets, 1, &rotations.rig_from_world) ||
        AssignSupported(pending_cameras, 1, &rotations.cam_from_rig)) {
      continue;
    }
    break;
  }

  for (int sweep = 0; sweep < kNumRotationSweeps; ++sweep) {
    for (int j = 0; j < problem.num_framesets; ++j) {
      if (rotations.rig_from_world[j]) {
        pending_framesets[j] = FramesetRotation(problem, rotations, j);
      }
    }
    for (int j = 0; j < problem.num_framesets; ++j) {
      if (rotations.rig_from_world[j] && pending_framesets[j]) {
        rotations.rig_from_world[j] = pending_framesets[j]->rotation;
      }
    }
    for (int i = 0; i < problem.num_cameras; ++i) {
      if (rotations.cam_from_rig[i] && i != *base_camera) {
        pending_cameras[i] = CameraRotation(problem, rotations, i);
      }
    }
    for (int i = 0; i < problem.num_cameras; ++i) {
      if (rotations.cam_from_rig[i] && i != *base_camera &&
          pending_cameras[i]) {
        rotations.cam_from_rig[i] = pending_cameras[i]->rotation;
      }
    }
  }
  return rotations;
}

// Images, framesets and cameras whose poses the given images determine:
// framesets with two of them from cameras with non-parallel axes when
// radial (one when full), cameras with min_images_per_camera of them in
// such framesets; repeated until stable, because dropping a camera can
// undetermine a frameset.
struct DeterminedParts {
  std::vector<char> images;
  std::vector<char> framesets;
  std::vector<char> cameras;
};

DeterminedParts FindDeterminedParts(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_from_rig,
    const std::vector<char>& usable_images, int min_images_per_camera) {
  DeterminedParts parts;
  parts.images = usable_images;
  for (size_t k = 0; k < problem.images.size(); ++k) {
    parts.images[k] = parts.images[k] && cam_from_rig[problem.images[k].camera];
  }
  bool changed = true;
  while (changed) {
    changed = false;
    parts.framesets.assign(problem.num_framesets, 0);
    for (int j = 0; j < problem.num_framesets; ++j) {
      std::vector<Eigen::Vector3d> axes;
      for (const int index : problem.images_of_frameset[j]) {
        if (parts.images[index]) {
          axes.push_back(cam_from_rig[problem.images[index].camera]
                             ->toRotationMatrix()
                             .row(2)
                             .transpose());
        }
      }
      parts.framesets[j] =
          problem.num_rows == 2
              ? axes.size() >= 2 &&
                    SmallestAxisEigenvalue(axes) >= problem.min_axis_eigenvalue
              : !axes.empty();
    }
    std::vector<int> num_camera_images(problem.num_cameras, 0);
    for (size_t k = 0; k < problem.images.size(); ++k) {
      if (parts.images[k] && parts.framesets[problem.images[k].frameset]) {
        ++num_camera_images[problem.images[k].camera];
      }
    }
    parts.cameras.assign(problem.num_cameras, 0);
    for (int i = 0; i < problem.num_cameras; ++i) {
      parts.cameras[i] = num_camera_images[i] >= min_images_per_camera;
    }
    for (size_t k = 0; k < problem.images.size(); ++k) {
      const LocalizedImage& image = problem.images[k];
      if (parts.images[k] &&
          !(parts.framesets[image.frameset] && parts.cameras[image.camera])) {
        parts.images[k] = 0;
        changed = true;
      }
    }
  }
  return parts;
}

// The translations' weighted least-squares problem after eliminating the
// framesets' t_Q: reduced * t_P = reduced_rhs over the t_P of the
// non-anchor cameras.
struct ReducedTranslationSystem {
  std::vector<int> unknown_of_camera;  // offset into t_P, -1: anchor/unused
  std::vector<Eigen::MatrixXd> known_rows;  // per camera, rows of R_P
  Eigen::MatrixXd reduced;
  Eigen::VectorXd reduced_rhs;
  // Per frameset: H_j = sum_i w_i A_i^T A_i and sum_i w_i A_i^T b_ij.
  std::vector<Eigen::Matrix3d> frameset_normal;
  std::vector<Eigen::Vector3d> frameset_rhs;
};

// The known rows of T X - A R_Q X at the image's scene center X: the
// right-hand side b_ij of eq. 3's translation rows once R_Q is known.
Eigen::VectorXd ObservedRows(const LocalizedImage& image,
                             const Eigen::MatrixXd& known_rows,
                             const Eigen::Quaterniond& rig_rotation) {
  return (image.cam_from_world * image.scene_center).head(known_rows.rows()) -
         known_rows * (rig_rotation * image.scene_center);
}

// Given the rotations, the known translation rows are linear in the
// unknowns: per used image (camera i, frameset j), with A_i the known rows of
// R_P, comparing the camera-frame positions of the image's scene center X,
//   A_i (R_Q,j X + t_Q,j) + t_P,i = rows of T_ij X, i.e.
//   A_i t_Q,j + t_P,i = b_ij   (t_P,i: the known rows of camera i's t),
// weighted by w_ij. Eliminating t_Q,j = H_j^-1 (sum_i w_i A_i^T (b_ij -
// t_P,i)) leaves, per pair of images (i, k) of a frameset,
// w_i delta_ik I - w_i w_k A_i H_j^-1 A_k^T, and right-hand side
// w_i (b_ij - A_i H_j^-1 sum_k w_k A_k^T b_kj). Gauge: the anchor camera's
// t_P = 0 and, when radial, the slide of the rig origin along the anchor's
// axis z (t_P,i += d (R_P,i z)_xy for all i) is fixed by
// sum_i v_i^T t_P,i = 0 with v_i = (R_P,i z)_xy.
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
    if (!parts.framesets[j]) continue;
    std::vector<int> used;
    std::vector<Eigen::VectorXd> observed;
    for (const int index : problem.images_of_frameset[j]) {
      if (!parts.images[index]) continue;
      const LocalizedImage& image = problem.images[index];
      const Eigen::MatrixXd& a = system.known_rows[image.camera];
      observed.push_back(ObservedRows(image, a, *rig_rotations[j]));
      system.frameset_normal[j] += weights[index] * a.transpose() * a;
      system.frameset_rhs[j] +=
          weights[index] * a.transpose() * observed.back();
      used.push_back(index);
    }
    const Eigen::Matrix3d inverse = system.frameset_normal[j].inverse();
    for (size_t n = 0; n < used.size(); ++n) {
      const int index = used[n];
      const LocalizedImage& image = problem.images[index];
      const int u = system.unknown_of_camera[image.camera];
      if (u < 0) continue;
      const Eigen::MatrixXd a_inverse =
          weights[index] * system.known_rows[image.camera] * inverse;
      system.reduced_rhs.segment(u, rows) +=
          weights[index] * observed[n] - a_inverse * system.frameset_rhs[j];
      system.reduced.block(u, u, rows, rows) +=
          weights[index] * Eigen::MatrixXd::Identity(rows, rows);
      for (const int other : used) {
        const int camera = problem.images[other].camera;
        const int v = system.unknown_of_camera[camera];
        if (v >= 0) {
          system.reduced.block(u, v, rows, rows) -=
              weights[other] * a_inverse *
              system.known_rows[camera].transpose();
        }
      }
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

// Whether the images of `parts` determine all camera translations relative
// to the anchor: no eigenvalue of the unweighted reduced matrix (gauge
// fixed) below min_axis_eigenvalue / 2. The matrix is dimensionless; one
// frameset with two cameras at the minimum angle contributes about
// min_axis_eigenvalue.
bool TranslationsDetermined(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_rotations,
    const std::vector<std::optional<Eigen::Quaterniond>>& rig_rotations,
    const DeterminedParts& parts, int anchor) {
  const ReducedTranslationSystem system = BuildReducedTranslationSystem(
      problem, cam_rotations, rig_rotations, parts,
      std::vector<double>(problem.images.size(), 1.0), anchor);
  return system.reduced.rows() == 0 ||
         Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(system.reduced,
                                                        Eigen::EigenvaluesOnly)
                 .eigenvalues()(0) >= 0.5 * problem.min_axis_eigenvalue;
}

// FindDeterminedParts, restricted further to the cameras whose translations
// the images determine. Every frameset being determined is not enough: e.g.
// a radial camera only ever seen with one other camera can slide along that
// camera's axis. An undetermined direction of the whole system mixes with
// the gauge and cannot say which cameras it moves, so the determined set is
// grown from the anchor instead: a camera joins if the images of the joined
// cameras and its own determine all their translations. The anchor camera,
// whose t_P is held, is preferred_anchor if kept, else the first kept
// camera; *anchor = num_cameras if none is kept.
DeterminedParts FindTranslationDeterminedParts(
    const InitProblem& problem,
    const std::vector<std::optional<Eigen::Quaterniond>>& cam_rotations,
    const std::vector<std::optional<Eigen::Quaterniond>>& rig_rotations,
    std::vector<char> usable_images, int min_images_per_camera,
    int preferred_anchor, int* anchor) {
  while (true) {
    const DeterminedParts parts = FindDeterminedParts(
        problem, cam_rotations, usable_images, min_images_per_camera);
    *anchor = parts.cameras[preferred_anchor]
                  ? preferred_anchor
                  : std::find(parts.cameras.begin(), parts.cameras.end(), 1) -
                        parts.cameras.begin();
    if (*anchor == problem.num_cameras) return parts;

    std::vector<char> joined(problem.num_cameras, 0);
    joined[*anchor] = 1;
    bool grown = true;
    while (grown) {
      grown = false;
      for (int i = 0; i < problem.num_cameras; ++i) {
        if (joined[i] || !parts.cameras[i]) continue;
        std::vector<char> subset_images = parts.images;
        for (size_t k = 0; k < problem.images.size(); ++k) {
          const int camera = problem.images[k].camera;
          subset_images[k] =
              subset_images[k] && (joined[camera] || camera == i);
        }
        const DeterminedParts subset =
            FindDeterminedParts(problem, cam_rotations, subset_images, 1);
        if (subset.cameras[i] && subset.cameras[*anchor] &&
            TranslationsDetermined(problem, cam_rotations, rig_rotations,
                                   subset, *anchor)) {
          joined[i] = 1;
          grown = true;
        }
      }
    }
    if (joined == parts.cameras) return parts;
    for (size_t k = 0; k < problem.images.size(); ++k) {
      if (!joined[problem.images[k].camera]) usable_images[k] = 0;
    }
  }
}

// Solves a reduced system: camera translations, then the framesets' t_Q.
Hypothesis SolveReducedSystem(const InitProblem& problem,
                              const Rotations& rotations,
                              const DeterminedParts& parts,
                              const std::vector<double>& weights,
                              const ReducedTranslationSystem& system) {
  Hypothesis hypothesis;
  hypothesis.cam_from_rig.resize(problem.num_cameras);
  hypothesis.rig_from_world.resize(problem.num_framesets);
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

// Translations by least squares over the usable images jointly (see
// BuildReducedTranslationSystem), so that each camera draws on every
// frameset it shares with any other camera. Cameras in undetermined
// directions are dropped first. A per-image pose with a right rotation and
// a wrong translation (a wrong place that looks alike) would pull the
// solution, so it is iteratively reweighted: Cauchy weights
// 1 / (1 + (r / (c sigma))^2) on the norm r of each image's residual
// A_i t_Q + t_P,i - b_ij, with sigma = 1.4826 median(r) (no absolute scale:
// the map's units are unknown).
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
  if (anchor == problem.num_cameras) {
    Hypothesis empty;
    empty.cam_from_rig.resize(problem.num_cameras);
    empty.rig_from_world.resize(problem.num_framesets);
    return empty;
  }
  std::vector<double> weights(problem.images.size(), 1.0);
  ReducedTranslationSystem system = BuildReducedTranslationSystem(
      problem, rotations.cam_from_rig, rotations.rig_from_world, parts, weights,
      anchor);
  Hypothesis hypothesis =
      SolveReducedSystem(problem, rotations, parts, weights, system);
  for (int iteration = 0; iteration < kNumReweightings; ++iteration) {
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
    std::nth_element(used_residuals.begin(),
                     used_residuals.begin() + used_residuals.size() / 2,
                     used_residuals.end());
    const double scale = kTranslationCauchyScale * 1.4826 *
                         used_residuals[used_residuals.size() / 2];
    if (!(scale > 0)) break;
    for (size_t k = 0; k < problem.images.size(); ++k) {
      const double ratio = residuals[k] / scale;
      weights[k] = 1.0 / (1.0 + ratio * ratio);
    }
    system = BuildReducedTranslationSystem(problem, rotations.cam_from_rig,
                                           rotations.rig_from_world, parts,
                                           weights, anchor);
    hypothesis = SolveReducedSystem(problem, rotations, parts, weights, system);
  }
  return hypothesis;
}

// One RANSAC hypothesis: rotations by greedy assignment, then translations
// by least squares over the images whose rotation agrees with the rig, then
// again over those of them whose correspondences agree with the rig too (a
// per-image pose with a right rotation and a wrong translation).
Hypothesis MakeHypothesis(const InitProblem& problem, int seed_frameset) {
  int base_camera = 0;
  const Rotations rotations =
      AssignRotationsGreedily(problem, seed_frameset, &base_camera);
  std::vector<char> usable(problem.images.size(), 0);
  for (size_t k = 0; k < problem.images.size(); ++k) {
    const LocalizedImage& image = problem.images[k];
    usable[k] = rotations.cam_from_rig[image.camera] &&
                rotations.rig_from_world[image.frameset] &&
                AngleRad(*rotations.cam_from_rig[image.camera] *
                             *rotations.rig_from_world[image.frameset],
                         image.cam_from_world.rotation) <
                    problem.max_rotation_deviation;
  }
  Hypothesis hypothesis =
      SolveTranslations(problem, rotations, usable, base_camera);
  const std::vector<char> agree =
      AgreeingImages(problem, FitHypothesis(problem, hypothesis));
  std::vector<char> agreeing_usable(problem.images.size(), 0);
  for (size_t k = 0; k < problem.images.size(); ++k) {
    agreeing_usable[k] = usable[k] && agree[k];
  }
  if (agreeing_usable != usable) {
    hypothesis =
        SolveTranslations(problem, rotations, agreeing_usable, base_camera);
  }
  return hypothesis;
}

// d(T, P Q) of eq. 4 as a residual vector: the angle-axis vector of
// R_T^T R_P R_Q (3, radians), then translation_weight times the difference
// of the camera-frame positions of the image's scene center X,
// P Q X - T X, over the kRows known rows (map units; at X rather than at the
// map's origin, see LocalizedImage). Parameters: P and Q as (angle-axis, t).
template <int kRows>
class PoseDeviationCost {
 public:
  PoseDeviationCost(const LocalizedImage& image, double translation_weight)
      : inverse_rotation_{image.cam_from_world.rotation.w(),
                          -image.cam_from_world.rotation.x(),
                          -image.cam_from_world.rotation.y(),
                          -image.cam_from_world.rotation.z()},
        scene_center_(image.scene_center),
        observed_center_(image.cam_from_world * image.scene_center),
        translation_weight_(translation_weight) {}

  static ceres::CostFunction* Create(const LocalizedImage& image,
                                     double translation_weight) {
    return new ceres::AutoDiffCostFunction<PoseDeviationCost, 3 + kRows, 6, 6>(
        new PoseDeviationCost(image, translation_weight));
  }

  template <typename T>
  bool operator()(const T* cam_from_rig, const T* rig_from_world,
                  T* residuals) const {
    T cam_quaternion[4], rig_quaternion[4], composed[4], difference[4];
    ceres::AngleAxisToQuaternion(cam_from_rig, cam_quaternion);
    ceres::AngleAxisToQuaternion(rig_from_world, rig_quaternion);
    ceres::QuaternionProduct(cam_quaternion, rig_quaternion, composed);
    const T inverse_rotation[4] = {
        T(inverse_rotation_[0]), T(inverse_rotation_[1]),
        T(inverse_rotation_[2]), T(inverse_rotation_[3])};
    ceres::QuaternionProduct(inverse_rotation, composed, difference);
    ceres::QuaternionToAngleAxis(difference, residuals);
    const T scene_center[3] = {T(scene_center_(0)), T(scene_center_(1)),
                               T(scene_center_(2))};
    T in_rig[3], in_cam[3];
    ceres::AngleAxisRotatePoint(rig_from_world, scene_center, in_rig);
    for (int r = 0; r < 3; ++r) in_rig[r] += rig_from_world[3 + r];
    ceres::AngleAxisRotatePoint(cam_from_rig, in_rig, in_cam);
    for (int r = 0; r < kRows; ++r) {
      residuals[3 + r] =
          T(translation_weight_) *
          (in_cam[r] + cam_from_rig[3 + r] - T(observed_center_(r)));
    }
    return true;
  }

 private:
  const std::array<double, 4> inverse_rotation_;
  const Eigen::Vector3d scene_center_;
  const Eigen::Vector3d observed_center_;
  const double translation_weight_;
};

// Local optimization of eq. 4 over the hypothesis' kept cameras and rig poses
// with the agreeing images as observations. The reference camera's pose is
// held at the identity; with radial poses each camera's tz is held at 0 and
// the slide of the rig origin along the reference axis (see the header) is
// held by one rig pose's t_z.
void MinimizePoseDeviation(const InitProblem& problem,
                           const std::vector<char>& used,
                           Hypothesis* hypothesis) {
  const bool radial = problem.num_rows == 2;
  std::vector<std::array<double, 6>> cam_parameters(problem.num_cameras);
  std::vector<std::array<double, 6>> rig_parameters(problem.num_framesets);
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (hypothesis->cam_from_rig[i]) {
      cam_parameters[i] = ToAngleAxisTranslation(*hypothesis->cam_from_rig[i]);
    }
  }
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (hypothesis->rig_from_world[j]) {
      rig_parameters[j] =
          ToAngleAxisTranslation(*hypothesis->rig_from_world[j]);
    }
  }

  ceres::Problem ceres_problem;
  ceres::LossFunction* loss = new ceres::CauchyLoss(problem.options.loss_scale);
  std::vector<char> cam_added(problem.num_cameras, 0);
  std::vector<char> rig_added(problem.num_framesets, 0);
  for (size_t k = 0; k < problem.images.size(); ++k) {
    if (!used[k]) continue;
    const LocalizedImage& image = problem.images[k];
    ceres::CostFunction* cost =
        radial ? PoseDeviationCost<2>::Create(
                     image, problem.options.translation_weight)
               : PoseDeviationCost<3>::Create(
                     image, problem.options.translation_weight);
    ceres_problem.AddResidualBlock(cost, loss,
                                   cam_parameters[image.camera].data(),
                                   rig_parameters[image.frameset].data());
    cam_added[image.camera] = 1;
    rig_added[image.frameset] = 1;
  }
  if (ceres_problem.NumResidualBlocks() == 0) return;

  auto* ordering = new ceres::ParameterBlockOrdering;
  bool tz_gauge_held = false;
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (!rig_added[j]) continue;
    ordering->AddElementToGroup(rig_parameters[j].data(), 0);
    if (radial && !tz_gauge_held) {
      ceres_problem.SetManifold(rig_parameters[j].data(),
                                new ceres::SubsetManifold(6, {5}));
      tz_gauge_held = true;
    }
  }
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (!cam_added[i]) continue;
    ordering->AddElementToGroup(cam_parameters[i].data(), 1);
    if (i == problem.reference_camera) {
      ceres_problem.SetParameterBlockConstant(cam_parameters[i].data());
    } else if (radial) {
      ceres_problem.SetManifold(cam_parameters[i].data(),
                                new ceres::SubsetManifold(6, {5}));
    }
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.linear_solver_ordering.reset(ordering);
  solver_options.max_num_iterations = 100;
  // One thread: the Schur elimination accumulates in thread order, which
  // would make the result vary in the last bits; the problem is small.
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary solver_summary;
  ceres::Solve(solver_options, &ceres_problem, &solver_summary);
  if (!solver_summary.IsSolutionUsable()) {
    LOG(WARNING) << "InitializeRig: the refinement of eq. 4 failed ("
                 << solver_summary.message << "); keeping the RANSAC rig";
    return;
  }
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (cam_added[i]) {
      hypothesis->cam_from_rig[i] = FromAngleAxisTranslation(cam_parameters[i]);
    }
  }
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (rig_added[j]) {
      hypothesis->rig_from_world[j] =
          FromAngleAxisTranslation(rig_parameters[j]);
    }
  }
}

// Re-expresses a hypothesis in the reference camera's frame (with its tz = 0
// when radial): Q_j <- P_ref Q_j, P_i <- P_i P_ref^-1.
void ExpressInReferenceFrame(const InitProblem& problem,
                             Hypothesis* hypothesis) {
  const Rigid3d ref_from_rig =
      *hypothesis->cam_from_rig[problem.reference_camera];
  const Rigid3d rig_from_ref = ref_from_rig.Inverse();
  for (std::optional<Rigid3d>& cam_from_rig : hypothesis->cam_from_rig) {
    if (!cam_from_rig) continue;
    *cam_from_rig = *cam_from_rig * rig_from_ref;
    if (problem.num_rows == 2) cam_from_rig->translation.z() = 0;
  }
  hypothesis->cam_from_rig[problem.reference_camera] = Rigid3d();
  for (std::optional<Rigid3d>& rig_from_world : hypothesis->rig_from_world) {
    if (rig_from_world) *rig_from_world = ref_from_rig * *rig_from_world;
  }
}

// Which images, cameras and rig poses the final rig keeps: the images that
// agree with the hypothesis, the framesets they determine, the cameras with
// two of them in such framesets and no undetermined translation direction
// (FindTranslationDeterminedParts). The others are unassigned in the
// hypothesis.
std::vector<char> KeepDeterminedParts(const InitProblem& problem,
                                      const std::vector<char>& agree,
                                      Hypothesis* hypothesis) {
  std::vector<std::optional<Eigen::Quaterniond>> cam_rotations(
      problem.num_cameras);
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (hypothesis->cam_from_rig[i]) {
      cam_rotations[i] = hypothesis->cam_from_rig[i]->rotation;
    }
  }
  std::vector<std::optional<Eigen::Quaterniond>> rig_rotations(
      problem.num_framesets);
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (hypothesis->rig_from_world[j]) {
      rig_rotations[j] = hypothesis->rig_from_world[j]->rotation;
    }
  }
  int anchor = 0;
  const DeterminedParts parts = FindTranslationDeterminedParts(
      problem, cam_rotations, rig_rotations, agree, kMinAgreeingImagesPerCamera,
      problem.reference_camera, &anchor);
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (!parts.framesets[j]) hypothesis->rig_from_world[j].reset();
  }
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (!parts.cameras[i]) hypothesis->cam_from_rig[i].reset();
  }
  return parts.images;
}

bool Fail(const std::string& message, RigInitializerSummary* summary) {
  LOG(ERROR) << "InitializeRig: " << message;
  if (summary) summary->message = message;
  return false;
}

// Validates the input and gathers the localized images. Returns an error
// message, empty on success.
std::string BuildProblem(const RigInitializerOptions& options,
                         const RigDataset& dataset,
                         const RigCalibration& calibration,
                         InitProblem* problem) {
  problem->options = options;
  problem->num_cameras = dataset.cameras.size();
  problem->num_framesets = dataset.frameset_names.size();
  problem->reference_camera = dataset.reference_camera;
  problem->num_rows = options.radial ? 2 : 3;
  problem->min_axis_eigenvalue =
      1.0 - std::cos(options.min_principal_axis_angle_deg * M_PI / 180.0);
  problem->max_rotation_deviation =
      options.max_rotation_deviation_deg * M_PI / 180.0;
  problem->num_threads = colmap::GetEffectiveNumThreads(options.num_threads);
  problem->images_of_frameset.assign(problem->num_framesets, {});
  problem->images_of_camera.assign(problem->num_cameras, {});

  std::ostringstream error;
  if (problem->num_cameras == 0) return "the dataset has no cameras";
  if (dataset.reference_camera < 0 ||
      dataset.reference_camera >= problem->num_cameras) {
    error << "reference camera index " << dataset.reference_camera
          << " is not one of the " << problem->num_cameras << " cameras";
    return error.str();
  }
  if (!(options.max_radial_error_px > 0) || !(options.loss_scale > 0) ||
      !(options.max_rotation_deviation_deg > 0) ||
      !(options.translation_weight >= 0) || !(options.confidence > 0) ||
      !(options.confidence < 1) || options.max_num_trials < 1) {
    return "invalid options: max_radial_error_px, loss_scale and "
           "max_rotation_deviation_deg must be positive, translation_weight "
           "non-negative, confidence in (0, 1), "
           "max_num_trials >= 1";
  }
  if (calibration.images.size() != dataset.images.size()) {
    error << "calibration has " << calibration.images.size()
          << " image results for " << dataset.images.size() << " images";
    return error.str();
  }
  for (const RigCamera& camera : dataset.cameras) {
    if (!camera.camera.VerifyParams()) {
      return "camera " + camera.name + " has no valid model parameters";
    }
  }

  std::map<std::pair<int, int>, int> image_of_slot;
  for (size_t k = 0; k < dataset.images.size(); ++k) {
    const RigImage& rig_image = dataset.images[k];
    const ImageResult& result = calibration.images[k];
    if (rig_image.camera_index < 0 ||
        rig_image.camera_index >= problem->num_cameras ||
        rig_image.frameset_index < 0 ||
        rig_image.frameset_index >= problem->num_framesets) {
      error << "image " << rig_image.name << " has camera index "
            << rig_image.camera_index << " and frameset index "
            << rig_image.frameset_index << ", out of range";
      return error.str();
    }
    if (!result.inlier_mask.empty() &&
        result.inlier_mask.size() != rig_image.correspondences.size()) {
      error << "image " << rig_image.name << " has an inlier mask of size "
            << result.inlier_mask.size() << " for "
            << rig_image.correspondences.size() << " correspondences";
      return error.str();
    }
    if (!result.single_image_cam_from_world) continue;
    const auto [slot, inserted] = image_of_slot.emplace(
        std::make_pair(rig_image.camera_index, rig_image.frameset_index), k);
    if (!inserted) {
      error << "images " << dataset.images[slot->second].name << " and "
            << rig_image.name << " are both localized images of camera "
            << dataset.cameras[rig_image.camera_index].name << " in frameset "
            << rig_image.frameset_index;
      return error.str();
    }

    LocalizedImage image;
    image.camera = rig_image.camera_index;
    image.frameset = rig_image.frameset_index;
    image.cam_from_world = *result.single_image_cam_from_world;
    if (!image.cam_from_world.rotation.coeffs().allFinite() ||
        !image.cam_from_world.translation.head(problem->num_rows).allFinite()) {
      return "image " + rig_image.name + " has a non-finite pose";
    }
    if (options.radial) image.cam_from_world.translation.z() = 0;

    std::vector<int> inliers;
    for (size_t c = 0; c < result.inlier_mask.size(); ++c) {
      if (result.inlier_mask[c]) inliers.push_back(c);
    }
    const int num_scored =
        std::min<int>(inliers.size(), kMaxScoredCorrespondences);
    const colmap::Camera& camera =
        dataset.cameras[rig_image.camera_index].camera;
    const Eigen::Vector2d principal_point(camera.PrincipalPointX(),
                                          camera.PrincipalPointY());
    for (int s = 0; s < num_scored; ++s) {
      const Correspondence& correspondence =
          rig_image.correspondences[inliers[s * inliers.size() / num_scored]];
      image.points2D.push_back(correspondence.point2D - principal_point);
      image.points3D.push_back(correspondence.point3D);
    }
    image.num_own_inliers =
        FitImage(image.cam_from_world, image, options.max_radial_error_px)
            .num_within;
    // A pose that does not explain its own inliers can agree with nothing.
    if (image.num_own_inliers < kMinAgreeingInliers) continue;
    for (const Eigen::Vector3d& point : image.points3D) {
      image.scene_center += point / image.points3D.size();
    }
    problem->images_of_frameset[image.frameset].push_back(
        problem->images.size());
    problem->images_of_camera[image.camera].push_back(problem->images.size());
    problem->images.push_back(std::move(image));
  }
  return "";
}

}  // namespace

bool InitializeRig(const RigInitializerOptions& options,
                   const RigDataset& dataset, RigCalibration* calibration,
                   RigInitializerSummary* summary) {
  if (summary) *summary = RigInitializerSummary();
  if (calibration == nullptr) return Fail("no calibration given", summary);
  InitProblem problem;
  const std::string error =
      BuildProblem(options, dataset, *calibration, &problem);
  if (!error.empty()) return Fail(error, summary);
  if (summary) summary->num_images_localized = problem.images.size();

  if (options.radial) {
    std::string explanation;
    if (PrincipalAxesAreParallel(dataset, *calibration,
                                 options.min_principal_axis_angle_deg,
                                 &explanation)) {
      return Fail(explanation +
                      "; 1D radial poses cannot determine the rig poses of "
                      "a rig with parallel principal axes: use full "
                      "per-image poses (the rd_ra method)",
                  summary);
    }
  }

  std::vector<int> seeds;
  for (int j = 0; j < problem.num_framesets; ++j) {
    if (problem.images_of_frameset[j].size() >= 2) seeds.push_back(j);
  }
  if (seeds.empty()) {
    return Fail("no frameset has two localized images", summary);
  }
  std::mt19937 random_engine(options.seed);
  std::shuffle(seeds.begin(), seeds.end(), random_engine);

  // RANSAC over seed framesets. A seed is good if all its localized images
  // agree with the best hypothesis; with a share w of good seeds, the
  // probability that k trials all miss one is (1 - w)^k.
  Hypothesis best;
  double best_score = std::numeric_limits<double>::infinity();
  int num_trials = 0;
  double required_trials = std::numeric_limits<double>::infinity();
  const int max_trials =
      std::min<int>(options.max_num_trials, static_cast<int>(seeds.size()));
  while (num_trials < max_trials && num_trials < required_trials) {
    Hypothesis hypothesis = MakeHypothesis(problem, seeds[num_trials]);
    ++num_trials;
    const std::vector<std::optional<ImageFit>> fits =
        FitHypothesis(problem, hypothesis);
    const double score = TruncatedScore(problem, fits);
    if (score >= best_score) continue;
    best = std::move(hypothesis);
    best_score = score;
    const std::vector<char> agree = AgreeingImages(problem, fits);
    int num_good_seeds = 0;
    for (const int seed : seeds) {
      bool good = true;
      for (const int index : problem.images_of_frameset[seed]) {
        good = good && agree[index];
      }
      num_good_seeds += good;
    }
    const double good_share =
        static_cast<double>(num_good_seeds) / seeds.size();
    if (good_share >= 1) {
      required_trials = 1;
    } else if (good_share > 0) {
      required_trials = std::ceil(std::log(1 - options.confidence) /
                                  std::log(1 - good_share));
    }
  }

  int num_scored = 0;
  for (const LocalizedImage& image : problem.images) {
    num_scored += image.points2D.size();
  }
  if (summary) {
    summary->num_trials = num_trials;
    summary->best_score =
        num_scored > 0 ? std::sqrt(best_score / num_scored) : 0;
  }

  const std::string reference_name =
      dataset.cameras[problem.reference_camera].name;
  const int num_reference_images =
      problem.images_of_camera[problem.reference_camera].size();
  if (!best.cam_from_rig[problem.reference_camera]) {
    std::ostringstream message;
    message << "the reference camera " << reference_name
            << " could not be placed in the rig (" << num_reference_images
            << " of its images localized); choose another reference camera";
    return Fail(message.str(), summary);
  }
  ExpressInReferenceFrame(problem, &best);
  const std::vector<char> used = KeepDeterminedParts(
      problem, AgreeingImages(problem, FitHypothesis(problem, best)), &best);
  if (!best.cam_from_rig[problem.reference_camera]) {
    std::ostringstream message;
    message << "the reference camera " << reference_name
            << " cannot be placed in the rig: fewer than two of its "
            << num_reference_images
            << " localized images agree with the best rig hypothesis, or "
               "they do not determine its position; choose another "
               "reference camera";
    return Fail(message.str(), summary);
  }
  MinimizePoseDeviation(problem, used, &best);

  calibration->cam_from_rig.assign(problem.num_cameras, Rigid3d());
  calibration->camera_calibrated.assign(problem.num_cameras, false);
  calibration->rig_from_world.assign(problem.num_framesets, std::nullopt);
  for (int i = 0; i < problem.num_cameras; ++i) {
    if (best.cam_from_rig[i]) {
      calibration->cam_from_rig[i] = *best.cam_from_rig[i];
      calibration->camera_calibrated[i] = true;
    } else if (!problem.images_of_camera[i].empty()) {
      LOG(WARNING) << "InitializeRig: camera " << dataset.cameras[i].name
                   << " is left out of the rig although "
                   << problem.images_of_camera[i].size()
                   << " of its images are localized: fewer than two agree "
                      "with the rig, or they do not determine its position"
                   << (options.radial
                           ? " (a radial camera seen only in framesets of two "
                             "cameras whose axes are (nearly) coplanar with "
                             "its own cannot be placed within that plane; it "
                             "needs framesets with two other cameras)"
                           : "");
    }
  }
  calibration->cam_from_rig[problem.reference_camera] = Rigid3d();
  calibration->rig_from_world = best.rig_from_world;
  if (options.radial) {
    NormalizeRadialRigOrigin(problem.reference_camera, calibration);
  }

  if (summary) {
    summary->num_cameras_assigned =
        std::count(calibration->camera_calibrated.begin(),
                   calibration->camera_calibrated.end(), true);
    summary->num_framesets_assigned = std::count_if(
        calibration->rig_from_world.begin(), calibration->rig_from_world.end(),
        [](const std::optional<Rigid3d>& pose) { return pose.has_value(); });
    summary->num_images_consistent = std::count(used.begin(), used.end(), 1);
  }
  return true;
}

bool PrincipalAxesAreParallel(const RigDataset& dataset,
                              const RigCalibration& calibration,
                              double max_angle_deg, std::string* explanation) {
  // Per frameset, the world principal axes of its localized images.
  std::map<int, std::vector<std::pair<int, Eigen::Vector3d>>> axes_of_frameset;
  const size_t num_images =
      std::min(dataset.images.size(), calibration.images.size());
  for (size_t k = 0; k < num_images; ++k) {
    const std::optional<Rigid3d>& pose =
        calibration.images[k].single_image_cam_from_world;
    if (!pose || !pose->rotation.coeffs().allFinite()) continue;
    axes_of_frameset[dataset.images[k].frameset_index].emplace_back(
        dataset.images[k].camera_index, PrincipalAxis(*pose));
  }
  std::map<std::pair<int, int>, std::vector<double>> angles_of_pair;
  for (const auto& [frameset, axes] : axes_of_frameset) {
    for (size_t a = 0; a < axes.size(); ++a) {
      for (size_t b = a + 1; b < axes.size(); ++b) {
        if (axes[a].first == axes[b].first) continue;
        const double cosine =
            std::clamp(axes[a].second.dot(axes[b].second), -1.0, 1.0);
        angles_of_pair[std::minmax(axes[a].first, axes[b].first)].push_back(
            std::acos(cosine) * 180.0 / M_PI);
      }
    }
  }

  auto camera_name = [&](int index) {
    return index >= 0 && index < static_cast<int>(dataset.cameras.size())
               ? dataset.cameras[index].name
               : "#" + std::to_string(index);
  };
  std::ostringstream message;
  if (angles_of_pair.empty()) {
    message << "no frameset has two localized images of different cameras: "
               "the principal axes cannot be compared";
    if (explanation) *explanation = message.str();
    return false;
  }
  double widest_angle = -1;
  std::pair<int, int> widest_pair;
  int widest_count = 0;
  for (auto& [pair, angles] : angles_of_pair) {
    std::nth_element(angles.begin(), angles.begin() + angles.size() / 2,
                     angles.end());
    const double median = angles[angles.size() / 2];
    if (median > widest_angle) {
      widest_angle = median;
      widest_pair = pair;
      widest_count = angles.size();
    }
  }
  const bool parallel = widest_angle <= max_angle_deg;
  if (parallel) {
    message << "all principal axes are within " << max_angle_deg
            << " degrees of parallel";
  } else {
    message << "the principal axes are not parallel";
  }
  message << " (largest median angle " << widest_angle << " degrees, between "
          << camera_name(widest_pair.first) << " and "
          << camera_name(widest_pair.second) << " over " << widest_count
          << " framesets)";
  if (explanation) *explanation = message.str();
  return parallel;
}

void NormalizeRadialRigOrigin(int reference_camera,
                              RigCalibration* calibration) {
  double numerator = 0;
  double denominator = 0;
  for (size_t i = 0; i < calibration->cam_from_rig.size(); ++i) {
    if (static_cast<int>(i) == reference_camera ||
        i >= calibration->camera_calibrated.size() ||
        !calibration->camera_calibrated[i]) {
      continue;
    }
    const Rigid3d& cam_from_rig = calibration->cam_from_rig[i];
    const Eigen::Vector2d axis_xy =
        cam_from_rig.RotationMatrix().col(2).head<2>();
    numerator += axis_xy.dot(cam_from_rig.translation.head<2>());
    denominator += axis_xy.squaredNorm();
  }
  // All parallel: the slide is undetermined and changes nothing.
  const double slide = denominator > 1e-12 ? -numerator / denominator : 0.0;
  for (Rigid3d& cam_from_rig : calibration->cam_from_rig) {
    cam_from_rig.translation += slide * cam_from_rig.RotationMatrix().col(2);
    cam_from_rig.translation.z() = 0;
  }
  for (std::optional<Rigid3d>& rig_from_world : calibration->rig_from_world) {
    if (rig_from_world) rig_from_world->translation.z() -= slide;
  }
}

}  // namespace rig_calibrator
