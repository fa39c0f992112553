#include "src/solvers/bundle_levenberg_marquardt.h"

#include <ceres/ceres.h>
#include <colmap/base/camera_models.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <memory>
#include <random>
#include <vector>

#include "src/geometry/rig_reprojection_cost.h"

namespace rig_calibrator {
namespace bundle_levenberg_marquardt_test {

using Pose = std::array<double, 7>;  // [qw, qx, qy, qz, tx, ty, tz]

// A two-camera rig (camera 0 the reference, identity cam_from_rig; camera 1
// looking sideways) in 8 framesets along a line, SIMPLE_RADIAL cameras,
// points in front of both. The first rig pose and 30 points are held: they
// fix the gauge (frame and scale).
struct Scene {
  static constexpr int kNumFramesets = 8;
  static constexpr int kNumPoints = 400;
  static constexpr int kNumFixedPoints = 30;
  std::vector<Pose> rig_from_world;
  std::array<Pose, 2> cam_from_rig;
  std::array<std::vector<double>, 2> intrinsics;
  std::vector<Eigen::Vector3d> points;
  struct Observation {
    int frameset, camera, point;
    Eigen::Vector2d pixel;
  };
  std::vector<Observation> observations;
};

Pose MakePose(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) {
  return {q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z()};
}

Eigen::Vector3d Transform(const Pose& pose, const Eigen::Vector3d& x) {
  return Eigen::Quaterniond(pose[0], pose[1], pose[2], pose[3]) * x +
         Eigen::Vector3d(pose[4], pose[5], pose[6]);
}

Scene MakeScene(double noise_px, double outlier_ratio, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::normal_distribution<double> normal(0, 1);
  Scene scene;
  for (int j = 0; j < Scene::kNumFramesets; ++j) {
    scene.rig_from_world.push_back(
        MakePose(Eigen::Quaterniond(
                     Eigen::AngleAxisd(0.05 * j, Eigen::Vector3d::UnitY())),
                 Eigen::Vector3d(-0.3 * j, 0.02 * j, 0)));
  }
  scene.cam_from_rig[0] =
      MakePose(Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  scene.cam_from_rig[1] = MakePose(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d(0.2, 0.01, -0.05));
  scene.intrinsics[0] = {500, 320, 240, -0.05};
  scene.intrinsics[1] = {450, 310, 250, 0.03};
  for (int p = 0; p < Scene::kNumPoints; ++p) {
    // In front of camera 0 or 1 of the middle frameset.
    const Eigen::Vector3d in_cam(3 * uniform(rng), 2 * uniform(rng),
                                 5 + 2 * uniform(rng));
    const Pose& rig = scene.rig_from_world[Scene::kNumFramesets / 2];
    const Pose& cam = scene.cam_from_rig[p % 2];
    const Eigen::Quaterniond q_rig(rig[0], rig[1], rig[2], rig[3]);
    const Eigen::Quaterniond q_cam(cam[0], cam[1], cam[2], cam[3]);
    const Eigen::Vector3d in_rig =
        q_cam.inverse() * (in_cam - Eigen::Vector3d(cam[4], cam[5], cam[6]));
    scene.points.push_back(q_rig.inverse() *
                           (in_rig - Eigen::Vector3d(rig[4], rig[5], rig[6])));
  }
  std::uniform_real_distribution<double> unit(0, 1);
  for (int j = 0; j < Scene::kNumFramesets; ++j) {
    for (int c = 0; c < 2; ++c) {
      for (int p = 0; p < Scene::kNumPoints; ++p) {
        const Eigen::Vector3d x =
            Transform(scene.cam_from_rig[c],
                      Transform(scene.rig_from_world[j], scene.points[p]));
        if (x.z() < 1) continue;
        Eigen::Vector2d pixel;
        colmap::SimpleRadialCameraModel::WorldToImage(
            scene.intrinsics[c].data(), x.x() / x.z(), x.y() / x.z(),
            &pixel.x(), &pixel.y());
        if (pixel.x() < 0 || pixel.x() > 640 || pixel.y() < 0 ||
            pixel.y() > 480) {
          continue;
        }
        pixel += noise_px * Eigen::Vector2d(normal(rng), normal(rng));
        if (unit(rng) < outlier_ratio) {
          pixel += Eigen::Vector2d(30 * uniform(rng), 30 * uniform(rng));
        }
        scene.observations.push_back({j, c, p, pixel});
      }
    }
  }
  // A point seen once has 3 unknowns for 2 residuals: not observed at all.
  std::vector<int> count(Scene::kNumPoints, 0);
  for (const Scene::Observation& observation : scene.observations) {
    ++count[observation.point];
  }
  std::vector<Scene::Observation> kept;
  for (const Scene::Observation& observation : scene.observations) {
    if (count[observation.point] >= 2) kept.push_back(observation);
  }
  scene.observations = kept;
  return scene;
}

// The scene's unknowns moved away from the truth.
Scene Perturbed(const Scene& truth, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0, 1);
  Scene start = truth;
  for (int j = 1; j < Scene::kNumFramesets; ++j) {
    const Eigen::Quaterniond q(
        start.rig_from_world[j][0], start.rig_from_world[j][1],
        start.rig_from_world[j][2], start.rig_from_world[j][3]);
    const Eigen::Quaterniond dq(Eigen::AngleAxisd(
        0.02,
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized()));
    const Eigen::Vector3d t =
        Eigen::Vector3d(start.rig_from_world[j].data() + 4) +
        0.03 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    start.rig_from_world[j] = MakePose(dq * q, t);
  }
  start.cam_from_rig[1][4] += 0.03;
  start.cam_from_rig[1][6] -= 0.02;
  start.intrinsics[0][0] *= 1.02;
  start.intrinsics[0][3] = 0;
  start.intrinsics[1][0] *= 0.98;
  start.intrinsics[1][3] = 0;
  for (int p = Scene::kNumFixedPoints; p < Scene::kNumPoints; ++p) {
    start.points[p] +=
        0.02 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
  }
  return start;
}

// The problem over `scene` (updated in place) for either solver: the first
// rig pose and camera 0's cam_from_rig held, camera 1's principal point
// held (subset manifold), the first kNumFixedPoints points fixed.
struct Problem {
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  std::vector<std::vector<double*>> parameters;
  ceres::ProductManifold<ceres::QuaternionManifold, ceres::EuclideanManifold<3>>
      pose_manifold;
  ceres::SubsetManifold principal_point_held{4, {1, 2}};
};

// A cost's Evaluate only: hides TangentJacobianCost from the solver, which
// then multiplies ambient Jacobians by PlusJacobians.
class AmbientOnlyCost final : public ceres::CostFunction {
 public:
  explicit AmbientOnlyCost(ceres::CostFunction* cost) : cost_(cost) {
    set_num_residuals(cost->num_residuals());
    *mutable_parameter_block_sizes() = cost->parameter_block_sizes();
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return cost_->Evaluate(parameters, residuals, jacobians);
  }

 private:
  std::unique_ptr<ceres::CostFunction> cost_;
};

void BuildProblem(Scene* scene, Problem* problem, bool ambient_only = false) {
  for (const Scene::Observation& observation : scene->observations) {
    const bool fixed = observation.point < Scene::kNumFixedPoints;
    ceres::CostFunction* cost = CreateRigReprojectionCost(
        colmap::SimpleRadialCameraModel::kModelId, observation.pixel,
        fixed ? &scene->points[observation.point] : nullptr);
    problem->costs.emplace_back(ambient_only ? new AmbientOnlyCost(cost)
                                             : cost);
    std::vector<double*> parameters = {
        scene->rig_from_world[observation.frameset].data(),
        scene->cam_from_rig[observation.camera].data(),
        scene->intrinsics[observation.camera].data()};
    if (!fixed) parameters.push_back(scene->points[observation.point].data());
    problem->parameters.push_back(parameters);
  }
}

// The problem over `scene` (BuildProblem) in `solver`, with `loss`: every
// rig pose but the first, camera 0's intrinsics, camera 1's cam_from_rig
// and intrinsics (principal point held) refined, and the points that are
// not fixed. `point_values` (per point, null: scene->points) puts the
// refined points' values elsewhere.
void AddToSolver(Scene* scene, Problem* problem,
                 const ceres::LossFunction* loss,
                 BundleLevenbergMarquardt* solver, bool ambient_only = false,
                 const std::vector<double*>* point_values = nullptr) {
  BuildProblem(scene, problem, ambient_only);
  const auto values_of = [&](int p) {
    return point_values != nullptr ? (*point_values)[p]
                                   : scene->points[p].data();
  };
  for (size_t k = 0; k < problem->parameters.size(); ++k) {
    const int p = scene->observations[k].point;
    if (p >= Scene::kNumFixedPoints) problem->parameters[k][3] = values_of(p);
  }
  int group = 0;
  for (int j = 1; j < Scene::kNumFramesets; ++j) {
    solver->AddParameterBlock(scene->rig_from_world[j].data(), 7,
                              &problem->pose_manifold, group++);
  }
  solver->AddParameterBlock(scene->intrinsics[0].data(), 4, nullptr, group++);
  solver->AddParameterBlock(scene->cam_from_rig[1].data(), 7,
                            &problem->pose_manifold, group);
  solver->AddParameterBlock(scene->intrinsics[1].data(), 4,
                            &problem->principal_point_held, group++);
  for (int p = Scene::kNumFixedPoints; p < Scene::kNumPoints; ++p) {
    solver->AddPoint(values_of(p));
  }
  for (size_t k = 0; k < problem->costs.size(); ++k) {
    solver->AddResidualBlock(problem->costs[k].get(), loss,
                             problem->parameters[k]);
  }
}

void SolveOurs(const ceres::LossFunction* loss, int num_threads, Scene* scene,
               BundleSolverSummary* summary,
               bool ambient_only = false) {
  Problem problem;
  BundleSolverOptions options;
  options.parameter_tolerance = 1e-12;
  options.function_tolerance = 1e-12;
  options.num_threads = num_threads;
  BundleLevenbergMarquardt solver(options);
  AddToSolver(scene, &problem, loss, &solver, ambient_only);
  solver.Solve(summary);
}

// The residual blocks of `problem` in a Ceres problem that owns none of
// them (nor `loss` or the manifolds set later).
std::unique_ptr<ceres::Problem> CeresProblemOf(const Problem& problem,
                                               ceres::LossFunction* loss) {
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  auto ceres_problem = std::make_unique<ceres::Problem>(problem_options);
  for (size_t k = 0; k < problem.costs.size(); ++k) {
    ceres_problem->AddResidualBlock(problem.costs[k].get(), loss,
                                    problem.parameters[k]);
  }
  return ceres_problem;
}

double SolveCeres(ceres::LossFunction* loss, Scene* scene) {
  Problem problem;
  BuildProblem(scene, &problem);
  const std::unique_ptr<ceres::Problem> ceres_problem_pointer =
      CeresProblemOf(problem, loss);
  ceres::Problem& ceres_problem = *ceres_problem_pointer;
  ceres_problem.SetParameterBlockConstant(scene->rig_from_world[0].data());
  ceres_problem.SetParameterBlockConstant(scene->cam_from_rig[0].data());
  for (int j = 1; j < Scene::kNumFramesets; ++j) {
    ceres_problem.SetManifold(scene->rig_from_world[j].data(),
                              &problem.pose_manifold);
  }
  ceres_problem.SetManifold(scene->cam_from_rig[1].data(),
                            &problem.pose_manifold);
  ceres_problem.SetManifold(scene->intrinsics[1].data(),
                            &problem.principal_point_held);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  options.max_num_iterations = 200;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &ceres_problem, &summary);
  EXPECT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  return summary.final_cost;
}

struct Errors {
  double rotation_rad = 0, translation = 0, point = 0, focal_relative = 0,
         extra = 0;
};

Errors Compare(const Scene& a, const Scene& b) {
  Errors errors;
  const auto pose_error = [&](const Pose& x, const Pose& y) {
    const Eigen::Quaterniond qx(x[0], x[1], x[2], x[3]);
    const Eigen::Quaterniond qy(y[0], y[1], y[2], y[3]);
    errors.rotation_rad = std::max(errors.rotation_rad, qx.angularDistance(qy));
    errors.translation = std::max(
        errors.translation,
        (Eigen::Vector3d(x.data() + 4) - Eigen::Vector3d(y.data() + 4)).norm());
  };
  for (int j = 0; j < Scene::kNumFramesets; ++j) {
    pose_error(a.rig_from_world[j], b.rig_from_world[j]);
  }
  pose_error(a.cam_from_rig[1], b.cam_from_rig[1]);
  for (int c = 0; c < 2; ++c) {
    errors.focal_relative =
        std::max(errors.focal_relative,
                 std::abs(a.intrinsics[c][0] / b.intrinsics[c][0] - 1));
    errors.extra = std::max(errors.extra,
                            std::abs(a.intrinsics[c][3] - b.intrinsics[c][3]));
  }
  for (const Scene::Observation& observation : a.observations) {
    const int p = observation.point;
    errors.point = std::max(errors.point, (a.points[p] - b.points[p]).norm());
  }
  return errors;
}

TEST(BundleLevenbergMarquardtTest, RecoversExactSceneFromPerturbedStart) {
  const Scene truth = MakeScene(0, 0, 1);
  Scene scene = Perturbed(truth, 2);
  const Errors start = Compare(scene, truth);
  ASSERT_GT(start.rotation_rad, 0.01);
  ASSERT_GT(start.focal_relative, 0.015);
  BundleSolverSummary summary;
  SolveOurs(nullptr, -1, &scene, &summary);
  ASSERT_EQ(summary.termination,
            BundleSolverSummary::Termination::kConvergence)
      << summary.BriefReport();
  EXPECT_GT(summary.initial_cost, 100);
  EXPECT_LT(summary.final_cost, 1e-16);
  EXPECT_EQ(summary.num_points, Scene::kNumPoints - Scene::kNumFixedPoints);
  // 7 rig poses, camera 0's intrinsics, camera 1's cam_from_rig + 2 free
  // intrinsics.
  EXPECT_EQ(summary.reduced_system_size, 7 * 6 + 4 + 6 + 2);
  const Errors errors = Compare(scene, truth);
  EXPECT_LT(errors.rotation_rad, 1e-9);
  EXPECT_LT(errors.translation, 1e-9);
  EXPECT_LT(errors.point, 1e-8);
  EXPECT_LT(errors.focal_relative, 1e-10);
  EXPECT_LT(errors.extra, 1e-10);
  // Held values stay bit-identical: the first rig pose, camera 0's
  // cam_from_rig, camera 1's principal point.
  EXPECT_EQ(scene.rig_from_world[0], truth.rig_from_world[0]);
  EXPECT_EQ(scene.cam_from_rig[0], truth.cam_from_rig[0]);
  EXPECT_EQ(scene.intrinsics[1][1], truth.intrinsics[1][1]);
  EXPECT_EQ(scene.intrinsics[1][2], truth.intrinsics[1][2]);
}

TEST(BundleLevenbergMarquardtTest, RobustSolveMatchesCeresAndIsAccurate) {
  const Scene truth = MakeScene(0.5, 0.1, 3);
  const Scene start = Perturbed(truth, 4);
  ceres::CauchyLoss loss(1.0);
  Scene ours = start;
  BundleSolverSummary summary;
  SolveOurs(&loss, 2, &ours, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  Scene ceres = start;
  const double ceres_cost = SolveCeres(&loss, &ceres);
  // The same minimum of the same objective.
  EXPECT_NEAR(summary.final_cost, ceres_cost, 1e-8 * ceres_cost);
  const Errors between = Compare(ours, ceres);
  EXPECT_LT(between.rotation_rad, 1e-7);
  EXPECT_LT(between.translation, 1e-6);
  EXPECT_LT(between.point, 1e-5);
  EXPECT_LT(between.focal_relative, 1e-7);
  // Against the truth, despite 10 % outliers of up to 30 px.
  const Errors errors = Compare(ours, truth);
  EXPECT_LT(errors.rotation_rad, 1e-3);
  EXPECT_LT(errors.translation, 5e-3);
  EXPECT_LT(errors.focal_relative, 2e-3);
  EXPECT_LT(errors.extra, 5e-3);
}

// The costs' own tangent Jacobians (RigReprojectionCost::EvaluateTangent)
// and the ambient ones times the manifolds' PlusJacobians: the same solve.
TEST(BundleLevenbergMarquardtTest, TangentJacobiansGiveTheAmbientPathsSolve) {
  const Scene truth = MakeScene(0.5, 0.1, 12);
  const Scene start = Perturbed(truth, 13);
  ceres::CauchyLoss loss(1.0);
  Scene tangent = start, ambient = start;
  BundleSolverSummary tangent_summary, ambient_summary;
  SolveOurs(&loss, 2, &tangent, &tangent_summary);
  SolveOurs(&loss, 2, &ambient, &ambient_summary, /*ambient_only=*/true);
  ASSERT_TRUE(tangent_summary.IsSolutionUsable());
  ASSERT_TRUE(ambient_summary.IsSolutionUsable());
  EXPECT_NEAR(tangent_summary.initial_cost, ambient_summary.initial_cost,
              1e-12 * ambient_summary.initial_cost);
  EXPECT_NEAR(tangent_summary.final_cost, ambient_summary.final_cost,
              1e-10 * ambient_summary.final_cost);
  EXPECT_EQ(tangent_summary.num_successful_steps,
            ambient_summary.num_successful_steps);
  const Errors between = Compare(tangent, ambient);
  EXPECT_LT(between.rotation_rad, 1e-9);
  EXPECT_LT(between.translation, 1e-9);
  EXPECT_LT(between.point, 1e-8);
  EXPECT_LT(between.focal_relative, 1e-10);
}

TEST(BundleLevenbergMarquardtTest, ResultDoesNotDependOnThreadCount) {
  const Scene truth = MakeScene(0.5, 0.1, 5);
  const Scene start = Perturbed(truth, 6);
  ceres::CauchyLoss loss(1.0);
  Scene one = start, two = start, three = start;
  BundleSolverSummary summary_one, summary_two, summary_three;
  SolveOurs(&loss, 1, &one, &summary_one);
  SolveOurs(&loss, 2, &two, &summary_two);
  SolveOurs(&loss, 3, &three, &summary_three);
  ASSERT_TRUE(summary_one.IsSolutionUsable());
  EXPECT_EQ(summary_one.final_cost, summary_two.final_cost);
  EXPECT_EQ(summary_one.final_cost, summary_three.final_cost);
  EXPECT_EQ(summary_one.num_successful_steps, summary_two.num_successful_steps);
  for (const Scene* other : {&two, &three}) {
    EXPECT_EQ(one.rig_from_world, other->rig_from_world);
    EXPECT_EQ(one.cam_from_rig, other->cam_from_rig);
    EXPECT_EQ(one.intrinsics, other->intrinsics);
    EXPECT_EQ(one.points, other->points);
  }
}

// The solver finds a point by its address by arithmetic while the points
// lie 3 doubles apart (a std::vector<Eigen::Vector3d>), else by hash from
// the first that does not: the same solve, bit for bit, with the refined
// points in one vector or their second half 4 doubles apart, and
// SetPointHeld finds a point of either half.
TEST(BundleLevenbergMarquardtTest, PointsAnywhereInMemoryGiveTheSameSolve) {
  const Scene truth = MakeScene(0.5, 0.1, 31);
  const Scene start = Perturbed(truth, 32);
  ceres::CauchyLoss loss(1.0);
  BundleSolverOptions options;
  options.parameter_tolerance = 1e-12;
  options.function_tolerance = 1e-12;
  const int middle = (Scene::kNumFixedPoints + Scene::kNumPoints) / 2;
  const std::array<int, 2> held = {Scene::kNumFixedPoints + 3,
                                   Scene::kNumPoints - 3};

  Scene in_one_vector = start;
  {
    Problem problem;
    BundleLevenbergMarquardt solver(options);
    AddToSolver(&in_one_vector, &problem, &loss, &solver);
    for (const int p : held) {
      solver.SetPointHeld(in_one_vector.points[p].data(), true);
    }
    BundleSolverSummary summary;
    solver.Solve(&summary);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  }

  Scene split = start;
  std::vector<Eigen::Vector3d> first_half;
  std::vector<std::array<double, 4>> second_half;
  for (int p = Scene::kNumFixedPoints; p < Scene::kNumPoints; ++p) {
    const Eigen::Vector3d& x = split.points[p];
    if (p < middle) {
      first_half.push_back(x);
    } else {
      second_half.push_back({x.x(), x.y(), x.z(), 0});
    }
  }
  std::vector<double*> point_values(Scene::kNumPoints, nullptr);
  for (int p = Scene::kNumFixedPoints; p < Scene::kNumPoints; ++p) {
    point_values[p] = p < middle ? first_half[p - Scene::kNumFixedPoints].data()
                                 : second_half[p - middle].data();
  }
  {
    Problem problem;
    BundleLevenbergMarquardt solver(options);
    AddToSolver(&split, &problem, &loss, &solver, /*ambient_only=*/false,
                &point_values);
    for (const int p : held) solver.SetPointHeld(point_values[p], true);
    BundleSolverSummary summary;
    solver.Solve(&summary);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  }
  for (int p = Scene::kNumFixedPoints; p < Scene::kNumPoints; ++p) {
    split.points[p] = Eigen::Vector3d(point_values[p]);
  }
  EXPECT_EQ(split.rig_from_world, in_one_vector.rig_from_world);
  EXPECT_EQ(split.cam_from_rig, in_one_vector.cam_from_rig);
  EXPECT_EQ(split.intrinsics, in_one_vector.intrinsics);
  EXPECT_EQ(split.points, in_one_vector.points);
  for (const int p : held) EXPECT_EQ(split.points[p], start.points[p]);
  EXPECT_NE(split.points[held[0] + 1], start.points[held[0] + 1]);
}

TEST(BundleLevenbergMarquardtTest, UnusableStartFailsAndLeavesValues) {
  const Scene truth = MakeScene(0, 0, 7);
  Scene scene = truth;
  // A refined point behind every camera: the residuals cannot be evaluated.
  scene.points.back() = Eigen::Vector3d(0, 0, -100);
  const Scene before = scene;
  BundleSolverSummary summary;
  SolveOurs(nullptr, 2, &scene, &summary);
  EXPECT_FALSE(summary.IsSolutionUsable());
  EXPECT_NE(summary.message.find("initial values"), std::string::npos);
  EXPECT_NE(summary.BriefReport().find("FAILURE"), std::string::npos);
  EXPECT_EQ(scene.points, before.points);
  EXPECT_EQ(scene.rig_from_world, before.rig_from_world);
}

// A least-squares problem without points over `problem`'s residuals (built
// by BuildProblem): camera 0's intrinsics and camera 1's cam_from_rig
// refined, everything else held.
void AddCameraSideProblem(Scene* scene, Problem* problem,
                          BundleLevenbergMarquardt* solver) {
  solver->AddParameterBlock(scene->intrinsics[0].data(), 4, nullptr, 0);
  solver->AddParameterBlock(scene->cam_from_rig[1].data(), 7,
                            &problem->pose_manifold, 1);
  for (size_t k = 0; k < problem->costs.size(); ++k) {
    solver->AddResidualBlock(problem->costs[k].get(), nullptr,
                             problem->parameters[k]);
  }
}

TEST(BundleLevenbergMarquardtTest, StopsAtTheIterationLimitAndContinues) {
  const Scene truth = MakeScene(0.5, 0, 8);
  Scene scene = Perturbed(truth, 9);
  Problem problem;
  BuildProblem(&scene, &problem);
  BundleSolverOptions options;
  options.max_num_iterations = 2;
  options.function_tolerance = 0;
  BundleLevenbergMarquardt solver(options);
  AddCameraSideProblem(&scene, &problem, &solver);
  BundleSolverSummary first, second;
  solver.Solve(&first);
  EXPECT_EQ(first.termination,
            BundleSolverSummary::Termination::kNoConvergence);
  EXPECT_EQ(first.num_successful_steps + first.num_unsuccessful_steps, 2);
  EXPECT_LT(first.final_cost, first.initial_cost);
  // Solving again continues from the result, on the same structure.
  solver.Solve(&second);
  ASSERT_TRUE(second.IsSolutionUsable()) << second.BriefReport();
  EXPECT_EQ(second.reduced_system_size, first.reduced_system_size);
  EXPECT_EQ(second.initial_cost, first.final_cost);
  EXPECT_LT(second.final_cost, first.final_cost);
}

// Counts the evaluations with Jacobians of the wrapped cost: one per
// linearization pass of the solver.
class CountingCost final : public ceres::CostFunction {
 public:
  CountingCost(const ceres::CostFunction* cost, std::atomic<int>* count)
      : cost_(cost), count_(count) {
    set_num_residuals(cost->num_residuals());
    *mutable_parameter_block_sizes() = cost->parameter_block_sizes();
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (jacobians != nullptr) ++*count_;
    return cost_->Evaluate(parameters, residuals, jacobians);
  }

 private:
  const ceres::CostFunction* cost_;
  std::atomic<int>* count_;
};

TEST(BundleLevenbergMarquardtTest, ConvergedStepIsKeptWithoutRelinearizing) {
  const Scene truth = MakeScene(0.5, 0, 10);
  Scene scene = Perturbed(truth, 11);
  Problem problem;
  BuildProblem(&scene, &problem);
  std::atomic<int> num_linearizations{0};
  const CountingCost counting(problem.costs[0].get(), &num_linearizations);
  BundleSolverOptions options;
  options.function_tolerance = 1e-3;
  BundleLevenbergMarquardt solver(options);
  solver.AddParameterBlock(scene.intrinsics[0].data(), 4, nullptr, 0);
  solver.AddParameterBlock(scene.cam_from_rig[1].data(), 7,
                           &problem.pose_manifold, 1);
  for (size_t k = 0; k < problem.costs.size(); ++k) {
    solver.AddResidualBlock(k == 0 ? &counting : problem.costs[k].get(),
                            nullptr, problem.parameters[k]);
  }
  BundleSolverSummary summary;
  solver.Solve(&summary);
  ASSERT_EQ(summary.termination,
            BundleSolverSummary::Termination::kConvergence)
      << summary.BriefReport();
  EXPECT_EQ(summary.message, "function tolerance reached");
  ASSERT_GE(summary.num_successful_steps, 1);
  // The start and every accepted step but the last, which ends the solve.
  EXPECT_EQ(num_linearizations.load(), summary.num_successful_steps);
  // The parameters are those of the last accepted step: its cost.
  double cost = 0;
  for (size_t k = 0; k < problem.costs.size(); ++k) {
    Eigen::Vector2d residual;
    ASSERT_TRUE(problem.costs[k]->Evaluate(problem.parameters[k].data(),
                                           residual.data(), nullptr));
    cost += 0.5 * residual.squaredNorm();
  }
  EXPECT_NEAR(cost, summary.final_cost, 1e-9 * cost);
  EXPECT_LT(summary.final_cost, summary.initial_cost);
}

// Inactive residual blocks and held points, on the structure of an earlier
// solve, give the solve of the problem without those blocks and with those
// points constant.
TEST(BundleLevenbergMarquardtTest, InactiveBlocksAndHeldPointsActAsRemoved) {
  const Scene truth = MakeScene(0.5, 0.1, 12);
  Scene scene = Perturbed(truth, 13);
  ceres::CauchyLoss loss(1.0);
  Problem problem;
  BuildProblem(&scene, &problem);
  const int held_point = Scene::kNumFixedPoints + 5;
  std::vector<char> removed(problem.costs.size(), 0);
  for (size_t k = 0; k < removed.size(); k += 7) removed[k] = 1;
  BundleSolverOptions options;
  options.parameter_tolerance = 1e-12;
  options.function_tolerance = 1e-12;
  BundleLevenbergMarquardt solver(options);
  int group = 0;
  for (int j = 1; j < Scene::kNumFramesets; ++j) {
    solver.AddParameterBlock(scene.rig_from_world[j].data(), 7,
                             &problem.pose_manifold, group++);
  }
  solver.AddParameterBlock(scene.intrinsics[0].data(), 4, nullptr, group++);
  solver.AddParameterBlock(scene.cam_from_rig[1].data(), 7,
                           &problem.pose_manifold, group);
  solver.AddParameterBlock(scene.intrinsics[1].data(), 4,
                           &problem.principal_point_held, group++);
  for (int p = Scene::kNumFixedPoints; p < Scene::kNumPoints; ++p) {
    solver.AddPoint(scene.points[p].data());
  }
  for (size_t k = 0; k < problem.costs.size(); ++k) {
    EXPECT_EQ(solver.AddResidualBlock(problem.costs[k].get(), &loss,
                                      problem.parameters[k]),
              k);
  }
  BundleSolverSummary first;
  solver.SetFunctionTolerance(1e-2);  // an early stop, as a pruning solve
  solver.Solve(&first);
  ASSERT_TRUE(first.IsSolutionUsable()) << first.BriefReport();
  // Then without every 7th block and with one point back at the truth, held.
  scene.points[held_point] = truth.points[held_point];
  Scene reference = scene;
  for (size_t k = 0; k < removed.size(); ++k) {
    if (removed[k]) solver.SetResidualBlockActive(k, false);
  }
  solver.SetPointHeld(scene.points[held_point].data(), true);
  solver.SetFunctionTolerance(1e-12);
  BundleSolverSummary second;
  solver.Solve(&second);
  ASSERT_TRUE(second.IsSolutionUsable()) << second.BriefReport();
  EXPECT_EQ(second.structure_seconds, 0);  // the structure was kept
  EXPECT_EQ(second.num_points, first.num_points - 1);

  // The reference: a new solver over the reduced problem, from the same
  // start.
  Problem reference_problem;
  BuildProblem(&reference, &reference_problem);
  BundleLevenbergMarquardt reference_solver(options);
  group = 0;
  for (int j = 1; j < Scene::kNumFramesets; ++j) {
    reference_solver.AddParameterBlock(reference.rig_from_world[j].data(), 7,
                                       &problem.pose_manifold, group++);
  }
  reference_solver.AddParameterBlock(reference.intrinsics[0].data(), 4, nullptr,
                                     group++);
  reference_solver.AddParameterBlock(reference.cam_from_rig[1].data(), 7,
                                     &problem.pose_manifold, group);
  reference_solver.AddParameterBlock(reference.intrinsics[1].data(), 4,
                                     &problem.principal_point_held, group++);
  for (int p = Scene::kNumFixedPoints; p < Scene::kNumPoints; ++p) {
    if (p != held_point) reference_solver.AddPoint(reference.points[p].data());
  }
  for (size_t k = 0; k < reference_problem.costs.size(); ++k) {
    if (!removed[k]) {
      reference_solver.AddResidualBlock(reference_problem.costs[k].get(), &loss,
                                        reference_problem.parameters[k]);
    }
  }
  BundleSolverSummary expected;
  reference_solver.Solve(&expected);
  ASSERT_TRUE(expected.IsSolutionUsable()) << expected.BriefReport();
  EXPECT_EQ(second.num_residual_blocks, expected.num_residual_blocks);
  EXPECT_NEAR(second.initial_cost, expected.initial_cost,
              1e-12 * expected.initial_cost);
  EXPECT_NEAR(second.final_cost, expected.final_cost,
              1e-9 * expected.final_cost);
  EXPECT_EQ(scene.points[held_point], truth.points[held_point]);
  const Errors between = Compare(scene, reference);
  EXPECT_LT(between.rotation_rad, 1e-8);
  EXPECT_LT(between.translation, 1e-7);
  EXPECT_LT(between.point, 1e-6);
  EXPECT_LT(between.focal_relative, 1e-9);
}

// LinearizeGaussNewton against the dense Schur complement of J^T J, J
// Ceres' Jacobian (no loss) in the same tangent spaces, columns in the
// solver's order (its groups, then the points): S, the residuals, the
// gradient and the point-side eliminations and back-substitutions; and the
// same bits on 1 and 2 threads.
TEST(BundleLevenbergMarquardtTest, GaussNewtonSystemIsTheSchurComplement) {
  const Scene truth = MakeScene(0.5, 0, 21);
  Scene scene = Perturbed(truth, 22);
  ceres::CauchyLoss loss(1.0);  // ignored by LinearizeGaussNewton
  Problem problem;
  BundleSolverOptions options;
  options.num_threads = 1;
  BundleLevenbergMarquardt solver(options);
  AddToSolver(&scene, &problem, &loss, &solver);
  std::string error;
  ASSERT_TRUE(solver.LinearizeGaussNewton(&error)) << error;

  // J from Ceres, columns: rig poses 1.., intrinsics 0, (cam_from_rig 1,
  // intrinsics 1), points.
  const std::unique_ptr<ceres::Problem> ceres_problem_pointer =
      CeresProblemOf(problem, nullptr);
  ceres::Problem& ceres_problem = *ceres_problem_pointer;
  std::vector<double*> columns;
  for (int j = 1; j < Scene::kNumFramesets; ++j) {
    ceres_problem.SetManifold(scene.rig_from_world[j].data(),
                              &problem.pose_manifold);
    columns.push_back(scene.rig_from_world[j].data());
  }
  columns.push_back(scene.intrinsics[0].data());
  ceres_problem.SetManifold(scene.cam_from_rig[1].data(),
                            &problem.pose_manifold);
  columns.push_back(scene.cam_from_rig[1].data());
  ceres_problem.SetManifold(scene.intrinsics[1].data(),
                            &problem.principal_point_held);
  columns.push_back(scene.intrinsics[1].data());
  const int num_camera = 6 * (Scene::kNumFramesets - 1) + 4 + 6 + 2;
  // The observed refined points: solver index -> J's point index (-1: none).
  std::vector<int> point_column(Scene::kNumPoints - Scene::kNumFixedPoints,
                                -1);
  for (const Scene::Observation& observation : scene.observations) {
    const int p = observation.point - Scene::kNumFixedPoints;
    if (p >= 0 && point_column[p] < 0) point_column[p] = 0;
  }
  int num_points = 0;
  for (size_t p = 0; p < point_column.size(); ++p) {
    if (point_column[p] < 0) continue;
    point_column[p] = num_points++;
    columns.push_back(scene.points[Scene::kNumFixedPoints + p].data());
  }
  ceres::Problem::EvaluateOptions evaluate_options;
  evaluate_options.parameter_blocks = columns;
  evaluate_options.num_threads = 1;
  std::vector<double> residuals;
  ceres::CRSMatrix crs;
  ASSERT_TRUE(ceres_problem.Evaluate(evaluate_options, nullptr, &residuals,
                                     nullptr, &crs));
  ASSERT_EQ(crs.num_cols, num_camera + 3 * num_points);
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) {
      j(row, crs.cols[k]) = crs.values[k];
    }
  }
  const Eigen::Map<const Eigen::VectorXd> r(residuals.data(),
                                            residuals.size());
  const Eigen::MatrixXd h = j.transpose() * j;
  const Eigen::MatrixXd u = h.topLeftCorner(num_camera, num_camera);
  const Eigen::MatrixXd w = h.bottomLeftCorner(3 * num_points, num_camera);
  const Eigen::MatrixXd v = h.bottomRightCorner(3 * num_points, 3 * num_points);
  const Eigen::LDLT<Eigen::MatrixXd> v_ldlt(v);
  const Eigen::MatrixXd s = u - w.transpose() * v_ldlt.solve(w);

  const Eigen::SparseMatrix<double> full =
      solver.ReducedMatrix().selfadjointView<Eigen::Upper>();
  const Eigen::MatrixXd reduced(full);
  ASSERT_EQ(reduced.rows(), num_camera);
  EXPECT_LT((reduced - s).cwiseAbs().maxCoeff(),
            1e-9 * s.cwiseAbs().maxCoeff());
  EXPECT_EQ(solver.GroupOffset(Scene::kNumFramesets), num_camera - 8);
  EXPECT_EQ(solver.NumDeterminedPointParameters(), 3 * num_points);

  // Residuals and the camera- and point-side gradient J^T r, weighted.
  Eigen::VectorXd camera_gradient = Eigen::VectorXd::Zero(num_camera);
  Eigen::VectorXd point_gradient = Eigen::VectorXd::Zero(3 * num_points);
  for (size_t k = 0; k < problem.costs.size(); ++k) {
    EXPECT_NEAR((solver.Residual(k) - r.segment<2>(2 * k)).norm(), 0, 1e-12);
    const Eigen::Vector3d point = solver.AddGradient(k, 0.5, &camera_gradient);
    const int p = scene.observations[k].point - Scene::kNumFixedPoints;
    if (p >= 0) point_gradient.segment<3>(3 * point_column[p]) += point;
  }
  const Eigen::VectorXd gradient = 0.5 * j.transpose() * r;
  EXPECT_LT((camera_gradient - gradient.head(num_camera)).norm(),
            1e-9 * gradient.norm());
  EXPECT_LT((point_gradient - gradient.tail(3 * num_points)).norm(),
            1e-9 * gradient.norm());

  // b_c - W^T V^-1 b_p and V^-1 (b_p - W x_c) for random b_p, x_c.
  std::mt19937 rng(23);
  std::normal_distribution<double> normal(0, 1);
  Eigen::VectorXd b_p(3 * num_points), x_c(num_camera);
  for (int i = 0; i < b_p.size(); ++i) b_p(i) = normal(rng);
  for (int i = 0; i < x_c.size(); ++i) x_c(i) = normal(rng);
  Eigen::VectorXd eliminated = Eigen::VectorXd::Zero(num_camera);
  Eigen::VectorXd solved(3 * num_points);
  for (size_t p = 0; p < point_column.size(); ++p) {
    const int column = point_column[p];
    if (column < 0) continue;
    solver.EliminatePointVector(static_cast<int>(p),
                                b_p.segment<3>(3 * column), &eliminated);
    solved.segment<3>(3 * column) = solver.BackSubstitutePoint(
        static_cast<int>(p), b_p.segment<3>(3 * column), x_c);
  }
  const Eigen::VectorXd expected_eliminated =
      -w.transpose() * v_ldlt.solve(b_p);
  EXPECT_LT((eliminated - expected_eliminated).norm(),
            1e-9 * expected_eliminated.norm());
  const Eigen::VectorXd expected_solved = v_ldlt.solve(b_p - w * x_c);
  EXPECT_LT((solved - expected_solved).norm(), 1e-9 * expected_solved.norm());

  // Bit-identical on two threads.
  Scene again = Perturbed(truth, 22);
  Problem again_problem;
  options.num_threads = 2;
  BundleLevenbergMarquardt two_threads(options);
  AddToSolver(&again, &again_problem, &loss, &two_threads);
  ASSERT_TRUE(two_threads.LinearizeGaussNewton(&error)) << error;
  EXPECT_EQ(Eigen::MatrixXd(two_threads.ReducedMatrix()),
            Eigen::MatrixXd(solver.ReducedMatrix()));
}

}  // namespace bundle_levenberg_marquardt_test
}  // namespace rig_calibrator
