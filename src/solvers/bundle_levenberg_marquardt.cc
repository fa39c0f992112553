#include "src/solvers/bundle_levenberg_marquardt.h"

#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <Eigen/CholmodSupport>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <thread>
#include <unordered_map>

#include "src/solvers/huge_page_allocator.h"

namespace rig_calibrator {
namespace {

// The work is cut into this many chunks whatever the thread count, so that
// sums over chunks (added in chunk order) do not depend on it.
constexpr int kMaxNumChunks = 16;
// A residual's blocks: a pose, a cam_from_rig, intrinsics, with the final
// adjustment's time model a capture-time offset, a line delay and the
// frameset's velocity, and a point; the time model's velocity prior takes
// the most, two framesets' velocities and the six poses of their windows
// (translation_prior_cost.h).
constexpr int kMaxParametersPerResidual = 8;
// Ceres' defaults (LevenbergMarquardtStrategy, TrustRegionMinimizer).
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr double kMaxTrustRegionRadius = 1e16;
constexpr double kMinTrustRegionRadius = 1e-32;

using RowMajorMap = Eigen::Map<
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;
using ConstRowMajorMap =
    Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic,
                                   Eigen::RowMajor>>;

// The small dense products of the loops below, on row-major blocks with
// run-time sizes (a group has 6 to ~20 columns), written out: Eigen's
// dynamic-size products allocate temporaries and take its large-matrix path.
// c (m x n, row stride ldc) += sign * a^T b, a: k x m, b: k x n.
inline void AddATransposeB(const double* a, const double* b, int k, int m,
                           int n, double sign, double* c, int ldc) {
  for (int i = 0; i < m; ++i) {
    double* row = c + i * ldc;
    for (int l = 0; l < k; ++l) {
      const double factor = sign * a[l * m + i];
      const double* b_row = b + l * n;
      for (int j = 0; j < n; ++j) row[j] += factor * b_row[j];
    }
  }
}
// The upper triangle of c (m x m) += sign * a^T b, a and b: k x m.
inline void AddATransposeBUpper(const double* a, const double* b, int k, int m,
                                double sign, double* c) {
  for (int i = 0; i < m; ++i) {
    double* row = c + i * m;
    for (int l = 0; l < k; ++l) {
      const double factor = sign * a[l * m + i];
      const double* b_row = b + l * m;
      for (int j = i; j < m; ++j) row[j] += factor * b_row[j];
    }
  }
}
// c (m x n, row stride ldc) += a b, a: m x k, b: k x n.
inline void AddAB(const double* a, const double* b, int m, int k, int n,
                  double* c, int ldc) {
  for (int i = 0; i < m; ++i) {
    double* row = c + i * ldc;
    for (int l = 0; l < k; ++l) {
      const double factor = a[i * k + l];
      const double* b_row = b + l * n;
      for (int j = 0; j < n; ++j) row[j] += factor * b_row[j];
    }
  }
}

// Sorts `items` stably by key(item) in [0, range): a counting sort, O(n +
// range). The structure's sorts run over ~10^5-10^7 items whose keys are
// group indices (a few hundred to a few thousand), where std::sort's
// n log n comparisons were a third of the structure's time (perf, 100
// framesets x 10 cameras).
template <typename Vector, typename Key>
void CountingSort(int range, Key key, Vector* items, Vector* buffer) {
  std::vector<size_t> begin(static_cast<size_t>(range) + 1, 0);
  for (const auto& item : *items) ++begin[key(item) + 1];
  for (int k = 0; k < range; ++k) begin[k + 1] += begin[k];
  buffer->resize(items->size());
  for (const auto& item : *items) (*buffer)[begin[key(item)]++] = item;
  items->swap(*buffer);
}

// An array that is not zeroed when sized: the Jacobians and the points' W
// (hundreds of MB at 10^6 residuals) are written in full by the first
// (parallel) evaluation of every solve, so zeroing them first would touch
// every page once more, on one thread (500 framesets x 10 cameras: the
// structure of the first solve 3.1 -> 1.2 s). In huge pages
// (huge_page_allocator.h): the first touch of each 4 KB page was most of a
// single linearization (LinearizeGaussNewton, 360 000 residuals: its
// evaluation 0.37 -> 0.15 s).
class UninitializedArray {
 public:
  void Resize(size_t size) {
    if (size != size_ || values_ == nullptr) {
      values_.reset(static_cast<double*>(
          AllocateLarge(std::max<size_t>(1, size) * sizeof(double))));
      CHECK(values_ != nullptr) << "out of memory";
      size_ = size;
    }
  }
  double* data() { return values_.get(); }
  const double* data() const { return values_.get(); }
  double& operator[](size_t i) { return values_[i]; }
  const double& operator[](size_t i) const { return values_[i]; }

 private:
  struct Free {
    void operator()(double* p) const { FreeLarge(p); }
  };
  std::unique_ptr<double[], Free> values_;
  size_t size_ = 0;
};

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

// One line of print_progress, in Ceres' columns.
void PrintIteration(int iteration, double cost, double cost_change,
                    double gradient_max_norm, double step_norm, double ratio,
                    double radius, double iteration_seconds,
                    double total_seconds) {
  std::printf(
      "%4d % 8e   % 3.2e   % 3.2e   % 3.2e   % 3.2e  % 3.2e  %8.2e   %8.2e\n",
      iteration, cost, cost_change, gradient_max_norm, step_norm, ratio, radius,
      iteration_seconds, total_seconds);
}

// The pseudo-inverse of a point's V_p (symmetric positive semi-definite)
// and its rank: eigenvalues below 1e-12 of the largest count as 0.
Eigen::Matrix3d PointPseudoInverse(const Eigen::Matrix3d& v, int* rank) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(v);
  const double max_eigenvalue = eigen.eigenvalues().maxCoeff();
  Eigen::Matrix3d inverse = Eigen::Matrix3d::Zero();
  *rank = 0;
  for (int k = 0; k < 3; ++k) {
    if (eigen.eigenvalues()(k) > 1e-12 * max_eigenvalue) {
      const Eigen::Vector3d direction = eigen.eigenvectors().col(k);
      inverse += direction * direction.transpose() / eigen.eigenvalues()(k);
      ++*rank;
    }
  }
  return inverse;
}

}  // namespace

struct BundleLevenbergMarquardt::Impl {
  struct Block {
    double* values = nullptr;
    int size = 0;
    const ceres::Manifold* manifold = nullptr;
    int tangent_size = 0;
    int group = 0;
    int column = 0;  // first column inside its group
  };
  struct Group {
    int size = 0;
    int offset = 0;  // first row in the reduced system
  };
  struct Residual {
    const ceres::CostFunction* cost = nullptr;
    // Non-null: evaluated by EvaluateTangent, with jacobian_columns[k] the
    // columns of block k's Jacobian (its tangent size where tangent[k]).
    const TangentJacobianCost* tangent_cost = nullptr;
    std::array<int, kMaxParametersPerResidual> jacobian_columns{};
    std::array<bool, kMaxParametersPerResidual> tangent{};
    const ceres::LossFunction* loss = nullptr;
    std::array<double*, kMaxParametersPerResidual> parameters{};
    std::array<int, kMaxParametersPerResidual> block{};  // -1: constant
    int num_parameters = 0;
    int point = -1;            // refined point, or -1
    int point_parameter = -1;  // its position in `parameters`
    bool active = true;        // SetResidualBlockActive
    // The distinct groups of its blocks (ascending), where their corrected
    // 2 x group-size Jacobians are in `jacobians` (rows of its batch's
    // stacked ones) and where the point's 2 x 3 is.
    std::array<int, kMaxParametersPerResidual> groups{};
    std::array<size_t, kMaxParametersPerResidual> group_jacobian{};
    int num_groups = 0;
    size_t point_jacobian = 0;
  };
  // Residuals over the same groups, batch_residuals[first, end).
  struct Batch {
    std::array<int, kMaxParametersPerResidual> groups{};
    int num_groups = 0;
    size_t first = 0, end = 0;
    // Where each group's stacked Jacobian starts in `jacobians`.
    std::array<size_t, kMaxParametersPerResidual> jacobian{};
    // Reduced-system blocks (g, h), g <= h, of its group pairs, in the
    // order (0,0), (0,1), ..., (1,1), ...
    std::vector<int> pairs;
  };
  // A point's distinct groups (ascending), where its W_pg (3 x group size)
  // lie in point_w, and the reduced-system block of each pair (g_i, g_j),
  // i <= j, row by row: views of the flat arrays point_groups,
  // point_w_offsets and point_pairs.
  struct PointStructure {
    const int* groups = nullptr;
    const size_t* w_offset = nullptr;
    const int* pairs = nullptr;
    int num_groups = 0;
  };
  // Consecutive points.
  struct Chunk {
    int first_point = 0, end_point = 0;
  };
  struct PairBlock {
    int row_group = 0, col_group = 0;
    size_t offset = 0;  // row-major rows x cols in the value arrays
  };

  explicit Impl(const BundleSolverOptions& o) : options(o) {
    // Not positive definite is an answer (the step is rejected), not a
    // message on stderr.
    cholesky.cholmod().print = 0;
  }

  BundleSolverOptions options;
  std::vector<Block> blocks;
  std::vector<Group> groups;
  std::unordered_map<const double*, int> block_index;
  // Per parameter position, the last pointer looked up and its block (-1:
  // none).
  std::array<std::pair<const double*, int>, kMaxParametersPerResidual>
      last_block{};
  std::vector<double*> points;
  std::vector<char> point_held;  // SetPointHeld
  // A point's index by its address: by arithmetic while every point lies 3
  // doubles after the previous one (a std::vector<Eigen::Vector3d>'s
  // layout; a hash look-up per residual otherwise, 10^6 at every
  // registration), else by point_index.
  bool points_contiguous = true;
  std::unordered_map<const double*, int> point_index;
  int PointIndex(const double* values) const;  // -1: not a point
  LargeVector<Residual> residuals;

  // Structure (Solve), built at the first Solve after a block, point or
  // residual was added.
  bool structure_valid = false;
  // The arrays below that grow with the residuals or the points are
  // LargeVectors (huge_page_allocator.h).
  LargeVector<size_t> residual_order;  // by point, pointless ones last
  std::vector<size_t> point_residuals_begin;
  std::vector<size_t> point_groups_begin, point_pairs_begin;
  LargeVector<int> point_groups, point_pairs;
  LargeVector<size_t> point_w_offsets;
  PointStructure StructureOf(int p) const {
    PointStructure structure;
    structure.groups = point_groups.data() + point_groups_begin[p];
    structure.w_offset = point_w_offsets.data() + point_groups_begin[p];
    structure.pairs = point_pairs.data() + point_pairs_begin[p];
    structure.num_groups =
        static_cast<int>(point_groups_begin[p + 1] - point_groups_begin[p]);
    return structure;
  }
  std::vector<Chunk> chunks;
  std::vector<Batch> batches;
  LargeVector<size_t> batch_residuals;
  // Consecutive batches of about equal residual counts (they share the
  // per-chunk copies with `chunks`).
  std::vector<std::pair<size_t, size_t>> batch_chunks;
  // kMaxNumChunks equal ranges of the residuals in their order.
  std::vector<std::pair<size_t, size_t>> residual_chunks;
  std::vector<PairBlock> pair_blocks;
  std::vector<size_t> diagonal_pair_offset;  // of (g, g), per group g
  size_t pair_values_size = 0;
  int reduced_size = 0;
  Eigen::SparseMatrix<double> reduced;
  LargeVector<size_t> reduced_value_source;  // CSC entry -> pair value
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Upper>
      cholesky;
  // Its symbolic factorization of `reduced`'s pattern is done (by Solve:
  // LinearizeGaussNewton factorizes nothing).
  bool pattern_analyzed = false;

  // Linearization at the current estimate.
  LargeVector<double> residual_values;  // corrected, 2 per residual
  UninitializedArray jacobians;
  std::vector<double> plus_jacobians;  // per block, size x tangent
  std::vector<size_t> plus_jacobian_offset;
  LargeVector<double> u_raw;     // camera-side block of J^T J (pairs)
  std::vector<double> b_camera;  // J^T r, camera side
  std::vector<double> d_camera;  // diag(J^T J), camera side
  LargeVector<double> point_v;   // 3 x 3 per point, J_p^T J_p
  LargeVector<double> point_b;   // 3 per point
  UninitializedArray point_w;    // W_pg per point and group
  // Step at the current radius.
  LargeVector<double> point_v_inverse;  // (V_p + D_p / mu)^-1
  LargeVector<double> point_step;
  Eigen::VectorXd camera_step;
  // Per chunk: its copy of the reduced system and right-hand side. A copy
  // is written, zeroed and summed only over the pair values its chunk's
  // terms reach (intervals of offsets, merged): a chunk of consecutive
  // points or images reaches a few rig poses' rows and the cameras', a small
  // part of the whole (500 framesets x 10 cameras: 16 full copies were
  // ~130 MB to zero and add at every step).
  using Intervals = std::vector<std::pair<size_t, size_t>>;
  std::vector<UninitializedArray> chunk_pairs;
  std::vector<std::vector<double>> chunk_vectors;
  std::vector<Intervals> point_chunk_intervals, batch_chunk_intervals;
  // The value intervals of the pair blocks marked in `used` (per pair
  // block), adjacent blocks merged.
  Intervals IntervalsOfPairs(const std::vector<char>& used) const;
  // out = base (null: 0) + the first num_chunks copies, each over its
  // intervals, added in chunk order; in parallel over ranges of values (the
  // order of the additions into each value does not depend on the threads).
  void SumChunkCopies(const double* base,
                      const std::vector<Intervals>& intervals, int num_chunks,
                      double* out) const;
  LargeVector<double> reduced_values;  // S, pair values, at each step
  // False while LinearizeGaussNewton evaluates: rho(s) = s for every
  // residual.
  bool robust_loss = true;
  // LinearizeGaussNewton: per point, the rank of V_p.
  std::vector<int> point_rank;

  int NumThreads() const {
    return options.num_threads > 0
               ? options.num_threads
               : std::max(
                     1, static_cast<int>(std::thread::hardware_concurrency()));
  }

  bool BuildStructure(std::string* error);
  // Evaluates every residual at the current values: the cost and, with
  // `linearize`, the corrected residuals and Jacobians, U, b, D and the
  // points' V, b and W. False if a cost function fails (or is not finite).
  bool Evaluate(bool linearize, double* cost);
  // U = the camera-side block of J^T J and b_c = J_c^T r, by batches.
  void AccumulateU();
  bool EvaluateResidual(const Residual& residual, bool linearize,
                        std::vector<double>* scratch, double* cost,
                        double* residual_out, double* jacobian_base) const;
  // Eliminates the points (the Schur complement of the step and of
  // LinearizeGaussNewton): with V~_p^-1 = invert(p, V_p) (kept in
  // point_v_inverse), the pair values of
  //   S = U - sum_p W_p^T V~_p^-1 W_p   into reduced_values,
  //   rhs = -b_c + sum_p W_p^T V~_p^-1 b_p,
  // chunk by chunk into the chunks' copies, added in chunk order.
  template <typename Invert>
  void EliminatePoints(Invert invert, Eigen::VectorXd* rhs);
  // reduced's CSC values from reduced_values.
  void CopyReducedValues();
  // V~_p^-1 (right - W_p x_c), x_c the camera-side vector at `camera`.
  Eigen::Vector3d SolvePoint(int p, Eigen::Vector3d right,
                             const double* camera) const;
  // Forms and factorizes the reduced system at radius mu, solves for the
  // camera-side step and back-substitutes the points'. False if the
  // factorization fails.
  bool ComputeStep(double mu, double* factorization_seconds,
                   double* schur_seconds);
  // 1/2 |r|^2 - 1/2 |r + J delta|^2 at the current linearization.
  double ModelCostChange() const;
  double StepNorm() const;
  double ParameterNorm() const;
  double GradientMaxNorm() const;
  // Moves the estimate by the step (saving the current values), or back.
  void ApplyStep(std::vector<double>* saved);
  void Restore(const std::vector<double>& saved);
};

int BundleLevenbergMarquardt::Impl::PointIndex(const double* values) const {
  if (!points_contiguous) {
    const auto point = point_index.find(values);
    return point != point_index.end() ? point->second : -1;
  }
  if (points.empty()) return -1;
  // Addresses as integers: comparing pointers into different arrays is
  // undefined.
  const uintptr_t first = reinterpret_cast<uintptr_t>(points.front());
  const uintptr_t address = reinterpret_cast<uintptr_t>(values);
  constexpr uintptr_t kPointBytes = 3 * sizeof(double);
  if (address < first || (address - first) % kPointBytes != 0) return -1;
  const uintptr_t index = (address - first) / kPointBytes;
  return index < points.size() ? static_cast<int>(index) : -1;
}

void BundleLevenbergMarquardt::Impl::Restore(const std::vector<double>& saved) {
  size_t k = 0;
  for (Block& block : blocks) {
    std::copy(saved.begin() + k, saved.begin() + k + block.size, block.values);
    k += block.size;
  }
  for (double* point : points) {
    std::copy(saved.begin() + k, saved.begin() + k + 3, point);
    k += 3;
  }
}

void BundleLevenbergMarquardt::Impl::ApplyStep(std::vector<double>* saved) {
  saved->clear();
  std::vector<double> plus;
  for (Block& block : blocks) {
    saved->insert(saved->end(), block.values, block.values + block.size);
    const double* delta =
        camera_step.data() + groups[block.group].offset + block.column;
    if (block.manifold == nullptr) {
      for (int k = 0; k < block.size; ++k) block.values[k] += delta[k];
    } else {
      plus.resize(block.size);
      block.manifold->Plus(block.values, delta, plus.data());
      std::copy(plus.begin(), plus.end(), block.values);
    }
  }
  for (size_t p = 0; p < points.size(); ++p) {
    saved->insert(saved->end(), points[p], points[p] + 3);
    for (int k = 0; k < 3; ++k) points[p][k] += point_step[3 * p + k];
  }
}

bool BundleLevenbergMarquardt::Impl::BuildStructure(std::string* error) {
  // Groups: sizes and offsets from their blocks' tangent sizes (anew, so
  // that Solve may be called again).
  groups.clear();
  for (Block& block : blocks) {
    if (block.group < 0) {
      *error = "a negative parameter group";
      return false;
    }
    if (block.group >= static_cast<int>(groups.size())) {
      groups.resize(block.group + 1);
    }
    block.column = groups[block.group].size;
    groups[block.group].size += block.tangent_size;
  }
  reduced_size = 0;
  for (Group& group : groups) {
    if (group.size == 0) {
      *error = "a parameter group without free parameters";
      return false;
    }
    group.offset = reduced_size;
    reduced_size += group.size;
  }
  plus_jacobian_offset.assign(blocks.size(), 0);
  size_t plus_size = 0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    plus_jacobian_offset[b] = plus_size;
    plus_size += static_cast<size_t>(blocks[b].size) * blocks[b].tangent_size;
  }
  plus_jacobians.assign(plus_size, 0);

  // Residuals by point (a counting sort: stable, so the order is the order
  // of addition within a point), pointless ones last.
  const int num_points = static_cast<int>(points.size());
  std::vector<size_t> count(num_points + 2, 0);
  for (const Residual& residual : residuals) {
    ++count[(residual.point < 0 ? num_points : residual.point) + 1];
  }
  for (int p = 0; p <= num_points; ++p) count[p + 1] += count[p];
  point_residuals_begin.assign(count.begin(), count.end() - 1);
  residual_order.assign(residuals.size(), 0);
  std::vector<size_t> next(count.begin(), count.end() - 1);
  for (size_t r = 0; r < residuals.size(); ++r) {
    const int p = residuals[r].point < 0 ? num_points : residuals[r].point;
    residual_order[next[p]++] = r;
  }

  // Pair blocks of the reduced system: every pair of groups that a residual
  // or a point couples.
  // Keys g << 32 | h of (g, h), g <= h (the group lists are ascending).
  LargeVector<uint64_t> pair_keys;
  const auto key_of = [](int g, int h) {
    return static_cast<uint64_t>(g) << 32 | static_cast<uint32_t>(h);
  };
  auto add_pairs = [&](const int* group_list, int n) {
    for (int i = 0; i < n; ++i) {
      for (int j = i; j < n; ++j) {
        pair_keys.push_back(key_of(group_list[i], group_list[j]));
      }
    }
  };
  size_t jacobian_size = 0;
  for (Residual& residual : residuals) {
    residual.num_groups = 0;
    for (int k = 0; k < residual.num_parameters; ++k) {
      if (residual.block[k] < 0) continue;
      const int group = blocks[residual.block[k]].group;
      if (std::find(residual.groups.begin(),
                    residual.groups.begin() + residual.num_groups,
                    group) == residual.groups.begin() + residual.num_groups) {
        residual.groups[residual.num_groups++] = group;
      }
    }
    std::sort(residual.groups.begin(),
              residual.groups.begin() + residual.num_groups);
  }
  // Batches: the residuals over the same groups (e.g. one image's). A
  // batch's Jacobians are stored group by group, the rows of its residuals
  // stacked (2n x group size, row-major), so that its part of U is one
  // matrix product per group pair; the points' 2 x 3 Jacobians follow.
  // Sorted by (groups, index): the unused group slots are -1.
  using BatchKey =
      std::pair<std::array<int, kMaxParametersPerResidual>, size_t>;
  LargeVector<BatchKey> batch_keys(residuals.size());
  for (size_t r = 0; r < residuals.size(); ++r) {
    batch_keys[r].first.fill(-1);
    std::copy(residuals[r].groups.begin(),
              residuals[r].groups.begin() + residuals[r].num_groups,
              batch_keys[r].first.begin());
    batch_keys[r].second = r;
  }
  // Lexicographic by (groups, index): stable passes from the last group
  // slot to the first, starting in index order.
  const int num_groups = static_cast<int>(groups.size());
  LargeVector<BatchKey> sort_buffer;
  for (int slot = kMaxParametersPerResidual - 1; slot >= 0; --slot) {
    CountingSort(
        num_groups + 1,
        [slot](const BatchKey& key) { return key.first[slot] + 1; },
        &batch_keys, &sort_buffer);
  }
  sort_buffer = LargeVector<BatchKey>();
  LargeVector<size_t> by_groups(residuals.size());
  for (size_t r = 0; r < residuals.size(); ++r) {
    by_groups[r] = batch_keys[r].second;
  }
  const auto same_groups = [&](size_t a, size_t b) {
    return batch_keys[a].first == batch_keys[b].first;
  };
  batches.clear();
  batch_residuals = by_groups;
  for (size_t k = 0; k < by_groups.size();) {
    size_t end = k + 1;
    while (end < by_groups.size() && same_groups(k, end)) ++end;
    const Residual& first_residual = residuals[by_groups[k]];
    Batch batch;
    batch.num_groups = first_residual.num_groups;
    batch.groups = first_residual.groups;
    batch.first = k;
    batch.end = end;
    const size_t n = end - k;
    for (int g = 0; g < batch.num_groups; ++g) {
      const size_t size = groups[batch.groups[g]].size;
      batch.jacobian[g] = jacobian_size;
      for (size_t i = 0; i < n; ++i) {
        residuals[by_groups[k + i]].group_jacobian[g] =
            jacobian_size + 2 * i * size;
      }
      jacobian_size += 2 * n * size;
    }
    add_pairs(batch.groups.data(), batch.num_groups);
    batches.push_back(batch);
    k = end;
  }
  for (Residual& residual : residuals) {
    residual.point_jacobian = jacobian_size;
    if (residual.point >= 0) jacobian_size += 6;
  }
  point_groups_begin.assign(1, 0);
  point_groups.clear();
  point_w_offsets.clear();
  size_t w_size = 0;
  for (int p = 0; p < num_points; ++p) {
    const size_t begin = point_groups.size();
    for (size_t k = point_residuals_begin[p]; k < point_residuals_begin[p + 1];
         ++k) {
      const Residual& residual = residuals[residual_order[k]];
      point_groups.insert(point_groups.end(), residual.groups.begin(),
                          residual.groups.begin() + residual.num_groups);
    }
    std::sort(point_groups.begin() + begin, point_groups.end());
    point_groups.erase(
        std::unique(point_groups.begin() + begin, point_groups.end()),
        point_groups.end());
    for (size_t k = begin; k < point_groups.size(); ++k) {
      point_w_offsets.push_back(w_size);
      w_size += 3 * groups[point_groups[k]].size;
    }
    add_pairs(point_groups.data() + begin,
              static_cast<int>(point_groups.size() - begin));
    point_groups_begin.push_back(point_groups.size());
  }
  for (int g = 0; g < static_cast<int>(groups.size()); ++g) {
    pair_keys.push_back(key_of(g, g));  // the LM diagonal of every group
  }
  LargeVector<uint64_t> key_buffer;
  CountingSort(
      num_groups,
      [](uint64_t key) { return static_cast<int>(key & 0xffffffffu); },
      &pair_keys, &key_buffer);
  CountingSort(
      num_groups, [](uint64_t key) { return static_cast<int>(key >> 32); },
      &pair_keys, &key_buffer);
  pair_keys.erase(std::unique(pair_keys.begin(), pair_keys.end()),
                  pair_keys.end());
  pair_blocks.clear();
  pair_values_size = 0;
  for (const uint64_t key : pair_keys) {
    const int row = static_cast<int>(key >> 32);
    const int col = static_cast<int>(key & 0xffffffffu);
    pair_blocks.push_back({row, col, pair_values_size});
    pair_values_size +=
        static_cast<size_t>(groups[row].size) * groups[col].size;
  }
  // The pair block (g, h): searched among row g's, a few hundred of the
  // 10^5 blocks.
  std::vector<size_t> row_pairs_begin(num_groups + 1, 0);
  for (const PairBlock& pair : pair_blocks) {
    ++row_pairs_begin[pair.row_group + 1];
  }
  for (int g = 0; g < num_groups; ++g) {
    row_pairs_begin[g + 1] += row_pairs_begin[g];
  }
  const auto pair_of = [&](int g, int h) {
    return static_cast<int>(
        std::lower_bound(pair_keys.begin() + row_pairs_begin[g],
                         pair_keys.begin() + row_pairs_begin[g + 1],
                         key_of(g, h)) -
        pair_keys.begin());
  };
  const auto list_pairs = [&](const int* group_list, int n,
                              std::vector<int>* pairs) {
    pairs->clear();
    for (int i = 0; i < n; ++i) {
      for (int j = i; j < n; ++j) {
        pairs->push_back(pair_of(group_list[i], group_list[j]));
      }
    }
  };
  diagonal_pair_offset.clear();
  for (int g = 0; g < static_cast<int>(groups.size()); ++g) {
    diagonal_pair_offset.push_back(pair_blocks[pair_of(g, g)].offset);
  }
  for (Batch& batch : batches) {
    list_pairs(batch.groups.data(), batch.num_groups, &batch.pairs);
  }
  // Per point, the pairs of its n groups: n (n + 1) / 2 of them, looked up
  // on all threads.
  point_pairs_begin.assign(num_points + 1, 0);
  for (int p = 0; p < num_points; ++p) {
    const size_t n = point_groups_begin[p + 1] - point_groups_begin[p];
    point_pairs_begin[p + 1] = point_pairs_begin[p] + n * (n + 1) / 2;
  }
  point_pairs.resize(point_pairs_begin[num_points]);
#pragma omp parallel for schedule(static) num_threads(NumThreads())
  for (int p = 0; p < num_points; ++p) {
    const int* group_list = point_groups.data() + point_groups_begin[p];
    const int n =
        static_cast<int>(point_groups_begin[p + 1] - point_groups_begin[p]);
    int* pairs = point_pairs.data() + point_pairs_begin[p];
    for (int i = 0; i < n; ++i) {
      for (int j = i; j < n; ++j) {
        *pairs++ = pair_of(group_list[i], group_list[j]);
      }
    }
  }
  // The upper triangle of the reduced system in CSC form, with the pair
  // value behind each entry. Column j of group h holds the rows of the pair
  // blocks (g, h), g < h, in increasing g (their group offsets increase with
  // g), then rows 0..j of (h, h): pair_blocks are sorted by (g, h), and a
  // stable pass by h lists each column group's blocks in that order. Built
  // directly, on all threads over the column groups (Eigen's
  // setFromTriplets sorted 10^6 triplets on one thread, to the same
  // matrix). The values are the source indices until CopyReducedValues.
  std::vector<size_t> column_blocks_begin(num_groups + 1, 0);
  for (const PairBlock& pair : pair_blocks) {
    ++column_blocks_begin[pair.col_group + 1];
  }
  for (int h = 0; h < num_groups; ++h) {
    column_blocks_begin[h + 1] += column_blocks_begin[h];
  }
  std::vector<int> column_blocks(pair_blocks.size());
  {
    std::vector<size_t> next_block(column_blocks_begin.begin(),
                                   column_blocks_begin.end() - 1);
    for (size_t b = 0; b < pair_blocks.size(); ++b) {
      column_blocks[next_block[pair_blocks[b].col_group]++] =
          static_cast<int>(b);
    }
  }
  // Entries before each column group's first column, and per column of
  // group h the rows of its off-diagonal blocks.
  std::vector<int64_t> group_entries_begin(num_groups + 1, 0);
  std::vector<int64_t> off_diagonal_rows(num_groups, 0);
  for (int h = 0; h < num_groups; ++h) {
    for (size_t k = column_blocks_begin[h]; k < column_blocks_begin[h + 1];
         ++k) {
      const PairBlock& pair = pair_blocks[column_blocks[k]];
      if (pair.row_group != h) {
        off_diagonal_rows[h] += groups[pair.row_group].size;
      }
    }
    const int64_t size = groups[h].size;
    group_entries_begin[h + 1] = group_entries_begin[h] +
                                 size * off_diagonal_rows[h] +
                                 size * (size + 1) / 2;
  }
  reduced.resize(reduced_size, reduced_size);
  reduced.resizeNonZeros(
      static_cast<Eigen::Index>(group_entries_begin[num_groups]));
  reduced_value_source.resize(group_entries_begin[num_groups]);
  int* outer = reduced.outerIndexPtr();
  int* inner = reduced.innerIndexPtr();
  double* values = reduced.valuePtr();
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int h = 0; h < num_groups; ++h) {
    const Group& column_group = groups[h];
    int64_t entry = group_entries_begin[h];
    for (int j = 0; j < column_group.size; ++j) {
      outer[column_group.offset + j] = static_cast<int>(entry);
      for (size_t k = column_blocks_begin[h]; k < column_blocks_begin[h + 1];
           ++k) {
        const PairBlock& pair = pair_blocks[column_blocks[k]];
        const Group& row_group = groups[pair.row_group];
        const int num_rows = pair.row_group == h ? j + 1 : row_group.size;
        for (int i = 0; i < num_rows; ++i, ++entry) {
          inner[entry] = row_group.offset + i;
          reduced_value_source[entry] =
              pair.offset + static_cast<size_t>(i) * column_group.size + j;
          values[entry] = static_cast<double>(reduced_value_source[entry]);
        }
      }
    }
  }
  outer[reduced_size] = static_cast<int>(group_entries_begin[num_groups]);
  pattern_analyzed = false;

  // Point chunks: consecutive points of about equal residual counts.
  chunks.clear();
  const size_t num_point_residuals = point_residuals_begin[num_points];
  const size_t target = std::max<size_t>(
      1, (num_point_residuals + kMaxNumChunks - 1) / kMaxNumChunks);
  int first = 0;
  while (first < num_points) {
    int end = first + 1;
    while (end < num_points &&
           point_residuals_begin[end] - point_residuals_begin[first] < target) {
      ++end;
    }
    chunks.push_back({first, end});
    first = end;
  }
  residual_chunks.clear();
  const size_t residual_target = std::max<size_t>(
      1, (residuals.size() + kMaxNumChunks - 1) / kMaxNumChunks);
  for (size_t first_residual = 0; first_residual < residuals.size();
       first_residual += residual_target) {
    residual_chunks.emplace_back(
        first_residual,
        std::min(residuals.size(), first_residual + residual_target));
  }
  batch_chunks.clear();
  const size_t batch_target = residual_target;
  for (size_t first_batch = 0; first_batch < batches.size();) {
    size_t end = first_batch + 1;
    while (end < batches.size() &&
           batches[end].first - batches[first_batch].first < batch_target) {
      ++end;
    }
    batch_chunks.emplace_back(first_batch, end);
    first_batch = end;
  }
  chunk_pairs.resize(std::max(chunks.size(), batch_chunks.size()));
  for (UninitializedArray& copy : chunk_pairs) copy.Resize(pair_values_size);
  reduced_values.assign(pair_values_size, 0);
  // Marking, not sorting, the pairs a chunk reaches: there are few pair
  // blocks and many references to them.
  std::vector<char> used;
  point_chunk_intervals.clear();
  for (const Chunk& chunk : chunks) {
    used.assign(pair_blocks.size(), 0);
    for (size_t k = point_pairs_begin[chunk.first_point];
         k < point_pairs_begin[chunk.end_point]; ++k) {
      used[point_pairs[k]] = 1;
    }
    point_chunk_intervals.push_back(IntervalsOfPairs(used));
  }
  batch_chunk_intervals.clear();
  for (const auto& [first_batch, end_batch] : batch_chunks) {
    used.assign(pair_blocks.size(), 0);
    for (size_t b = first_batch; b < end_batch; ++b) {
      for (const int pair : batches[b].pairs) used[pair] = 1;
    }
    batch_chunk_intervals.push_back(IntervalsOfPairs(used));
  }
  chunk_vectors.assign(chunk_pairs.size(),
                       std::vector<double>(reduced_size, 0));

  residual_values.assign(2 * residuals.size(), 0);
  jacobians.Resize(jacobian_size);
  u_raw.assign(pair_values_size, 0);
  b_camera.assign(reduced_size, 0);
  d_camera.assign(reduced_size, 0);
  point_v.assign(9 * num_points, 0);
  point_b.assign(3 * num_points, 0);
  point_w.Resize(w_size);
  point_v_inverse.assign(9 * num_points, 0);
  point_step.assign(3 * num_points, 0);
  camera_step = Eigen::VectorXd::Zero(reduced_size);
  return true;
}

BundleLevenbergMarquardt::Impl::Intervals
BundleLevenbergMarquardt::Impl::IntervalsOfPairs(
    const std::vector<char>& used) const {
  Intervals intervals;
  for (size_t pair = 0; pair < pair_blocks.size(); ++pair) {
    if (!used[pair]) continue;
    const PairBlock& block = pair_blocks[pair];
    const size_t begin = block.offset;
    const size_t end =
        begin + static_cast<size_t>(groups[block.row_group].size) *
                    groups[block.col_group].size;
    // Pair blocks lie in index order, so sorted pairs give sorted offsets.
    if (!intervals.empty() && intervals.back().second == begin) {
      intervals.back().second = end;
    } else {
      intervals.emplace_back(begin, end);
    }
  }
  return intervals;
}

bool BundleLevenbergMarquardt::Impl::EvaluateResidual(
    const Residual& residual, bool linearize, std::vector<double>* scratch,
    double* cost, double* residual_out, double* jacobian_base) const {
  // Inactive: zero residuals and Jacobians, as if it were not there.
  if (!residual.active) {
    if (linearize) {
      residual_out[0] = residual_out[1] = 0;
      for (int g = 0; g < residual.num_groups; ++g) {
        double* out = jacobian_base + residual.group_jacobian[g];
        std::fill(out, out + 2 * groups[residual.groups[g]].size, 0.0);
      }
      if (residual.point >= 0) {
        std::fill(jacobian_base + residual.point_jacobian,
                  jacobian_base + residual.point_jacobian + 6, 0.0);
      }
    }
    return true;
  }
  // Ambient Jacobians of the refined parameters, in `scratch`.
  std::array<double*, kMaxParametersPerResidual> ambient{};
  if (linearize) {
    size_t size = 0;
    for (int k = 0; k < residual.num_parameters; ++k) {
      if (residual.block[k] >= 0 || k == residual.point_parameter) {
        size += 2 * residual.jacobian_columns[k];
      }
    }
    if (scratch->size() < size) scratch->resize(size);
    size = 0;
    for (int k = 0; k < residual.num_parameters; ++k) {
      if (residual.block[k] >= 0 || k == residual.point_parameter) {
        ambient[k] = scratch->data() + size;
        size += 2 * residual.jacobian_columns[k];
      }
    }
  }
  double r[2];
  const bool evaluated =
      residual.tangent_cost != nullptr
          ? residual.tangent_cost->EvaluateTangent(
                residual.parameters.data(), r,
                linearize ? ambient.data() : nullptr)
          : residual.cost->Evaluate(residual.parameters.data(), r,
                                    linearize ? ambient.data() : nullptr);
  if (!evaluated || !std::isfinite(r[0]) || !std::isfinite(r[1])) {
    return false;
  }
  const double sq_norm = r[0] * r[0] + r[1] * r[1];
  double rho[3] = {sq_norm, 1, 0};
  if (residual.loss != nullptr && robust_loss) {
    residual.loss->Evaluate(sq_norm, rho);
  }
  *cost += 0.5 * rho[0];
  if (!linearize) return true;

  // Triggs' correction (ceres/corrector.h): r~ = s r, J~ = sqrt(rho')
  // (I - a r r^T / |r|^2) J; a = 1 - sqrt(1 + 2 |r|^2 rho'' / rho') when
  // rho'' > 0, else 0 (the Cauchy loss: plain sqrt(rho') weighting).
  const double sqrt_rho1 = std::sqrt(rho[1]);
  double residual_scaling = sqrt_rho1;
  double alpha_sq_norm = 0;
  if (sq_norm > 0 && rho[2] > 0) {
    const double alpha = 1 - std::sqrt(1 + 2 * sq_norm * rho[2] / rho[1]);
    residual_scaling = sqrt_rho1 / (1 - alpha);
    alpha_sq_norm = alpha / sq_norm;
  }
  residual_out[0] = residual_scaling * r[0];
  residual_out[1] = residual_scaling * r[1];
  const auto correct = [&](double* jacobian, int cols) {
    for (int c = 0; c < cols; ++c) {
      const double j0 = jacobian[c], j1 = jacobian[cols + c];
      const double rtj = r[0] * j0 + r[1] * j1;
      jacobian[c] = sqrt_rho1 * (j0 - alpha_sq_norm * r[0] * rtj);
      jacobian[cols + c] = sqrt_rho1 * (j1 - alpha_sq_norm * r[1] * rtj);
    }
  };
  // Tangent Jacobians, by group: the cost's, or J_ambient (2 x size) * plus
  // Jacobian.
  for (int g = 0; g < residual.num_groups; ++g) {
    const int group = residual.groups[g];
    double* out = jacobian_base + residual.group_jacobian[g];
    const int group_size = groups[group].size;
    std::fill(out, out + 2 * group_size, 0.0);
    for (int k = 0; k < residual.num_parameters; ++k) {
      const int b = residual.block[k];
      if (b < 0 || blocks[b].group != group) continue;
      const Block& block = blocks[b];
      if (block.manifold == nullptr || residual.tangent[k]) {
        for (int i = 0; i < block.tangent_size; ++i) {
          out[block.column + i] = ambient[k][i];
          out[group_size + block.column + i] =
              ambient[k][block.tangent_size + i];
        }
      } else {
        AddAB(ambient[k], plus_jacobians.data() + plus_jacobian_offset[b], 2,
              block.size, block.tangent_size, out + block.column, group_size);
      }
    }
    correct(out, groups[group].size);
  }
  if (residual.point >= 0) {
    double* out = jacobian_base + residual.point_jacobian;
    if (point_held[residual.point]) {
      std::fill(out, out + 6, 0.0);  // a constant of this residual
    } else {
      std::copy(ambient[residual.point_parameter],
                ambient[residual.point_parameter] + 6, out);
      correct(out, 3);
    }
  }
  return true;
}

bool BundleLevenbergMarquardt::Impl::Evaluate(bool linearize, double* cost) {
  if (linearize) {
    for (size_t b = 0; b < blocks.size(); ++b) {
      if (blocks[b].manifold != nullptr) {
        blocks[b].manifold->PlusJacobian(
            blocks[b].values, plus_jacobians.data() + plus_jacobian_offset[b]);
      }
    }
  }
  // The residuals in the order they were added (their cost functions lie
  // in memory in that order: in point order, every one is a cache miss).
  const int num_residual_chunks = static_cast<int>(residual_chunks.size());
  std::vector<double> chunk_cost(num_residual_chunks, 0);
  std::vector<char> chunk_ok(num_residual_chunks, 1);
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int c = 0; c < num_residual_chunks; ++c) {
    std::vector<double> scratch;
    // Summed in a local: chunk_cost[c] and [c + 1] share a cache line, which
    // two threads would otherwise pass back and forth at every residual.
    double cost_sum = 0;
    for (size_t index = residual_chunks[c].first;
         index < residual_chunks[c].second; ++index) {
      if (!EvaluateResidual(residuals[index], linearize, &scratch, &cost_sum,
                            &residual_values[2 * index], jacobians.data())) {
        chunk_ok[c] = 0;
        break;
      }
    }
    chunk_cost[c] = cost_sum;
  }
  *cost = 0;
  for (int c = 0; c < num_residual_chunks; ++c) {
    if (!chunk_ok[c]) return false;
    *cost += chunk_cost[c];
  }
  if (!std::isfinite(*cost)) return false;
  if (!linearize) return true;
  const int num_chunks = static_cast<int>(chunks.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int c = 0; c < num_chunks; ++c) {
    const Chunk& chunk = chunks[c];
    // Per point: V_p = sum J_p^T J_p, b_p = sum J_p^T r, W_pg = sum J_p^T
    // J_g.
    for (int p = chunk.first_point; p < chunk.end_point; ++p) {
      const PointStructure structure = StructureOf(p);
      Eigen::Map<Eigen::Matrix3d> v(&point_v[9 * p]);
      Eigen::Map<Eigen::Vector3d> b(&point_b[3 * p]);
      v.setZero();
      b.setZero();
      for (int g = 0; g < structure.num_groups; ++g) {
        double* w = &point_w[structure.w_offset[g]];
        std::fill(w, w + 3 * groups[structure.groups[g]].size, 0.0);
      }
      for (size_t k = point_residuals_begin[p];
           k < point_residuals_begin[p + 1]; ++k) {
        const size_t index = residual_order[k];
        const Residual& residual = residuals[index];
        const Eigen::Map<const Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> jp(
            &jacobians[residual.point_jacobian]);
        v += jp.transpose() * jp;
        b += jp.transpose() * Eigen::Vector2d(residual_values[2 * index],
                                              residual_values[2 * index + 1]);
        for (int i = 0; i < residual.num_groups; ++i) {
          const int slot = static_cast<int>(
              std::lower_bound(structure.groups,
                               structure.groups + structure.num_groups,
                               residual.groups[i]) -
              structure.groups);
          const int size = groups[residual.groups[i]].size;
          AddATransposeB(jp.data(), &jacobians[residual.group_jacobian[i]], 2,
                         3, size, 1, &point_w[structure.w_offset[slot]], size);
        }
      }
    }
  }
  AccumulateU();
  for (int g = 0; g < static_cast<int>(groups.size()); ++g) {
    const int size = groups[g].size;
    for (int i = 0; i < size; ++i) {
      d_camera[groups[g].offset + i] =
          std::clamp(u_raw[diagonal_pair_offset[g] + i * size + i],
                     kMinDiagonal, kMaxDiagonal);
    }
  }
  return true;
}

void BundleLevenbergMarquardt::Impl::AccumulateU() {
  const int num_chunks = static_cast<int>(batch_chunks.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int c = 0; c < num_chunks; ++c) {
    double* pairs = chunk_pairs[c].data();
    std::vector<double>& vector = chunk_vectors[c];
    for (const auto& [begin, end] : batch_chunk_intervals[c]) {
      std::fill(pairs + begin, pairs + end, 0.0);
    }
    std::fill(vector.begin(), vector.end(), 0);
    for (size_t b = batch_chunks[c].first; b < batch_chunks[c].second; ++b) {
      const Batch& batch = batches[b];
      const Eigen::Index rows =
          2 * static_cast<Eigen::Index>(batch.end - batch.first);
      int pair = 0;
      for (int i = 0; i < batch.num_groups; ++i) {
        const Group& gi = groups[batch.groups[i]];
        const ConstRowMajorMap ji(&jacobians[batch.jacobian[i]], rows, gi.size);
        // b_c += J_g^T r, residual by residual.
        for (size_t k = batch.first; k < batch.end; ++k) {
          const size_t index = batch_residuals[k];
          AddATransposeB(&jacobians[residuals[index].group_jacobian[i]],
                         &residual_values[2 * index], 2, gi.size, 1, 1,
                         vector.data() + gi.offset, 1);
        }
        for (int j = i; j < batch.num_groups; ++j, ++pair) {
          const Group& gj = groups[batch.groups[j]];
          RowMajorMap block(&pairs[pair_blocks[batch.pairs[pair]].offset],
                            gi.size, gj.size);
          if (i == j) {
            // The diagonal blocks' upper triangles (all the reduced system
            // uses).
            block.selfadjointView<Eigen::Upper>().rankUpdate(ji.transpose());
          } else {
            block.noalias() +=
                ji.transpose() *
                ConstRowMajorMap(&jacobians[batch.jacobian[j]], rows, gj.size);
          }
        }
      }
    }
  }
  SumChunkCopies(nullptr, batch_chunk_intervals, num_chunks, u_raw.data());
  std::fill(b_camera.begin(), b_camera.end(), 0);
  for (int c = 0; c < num_chunks; ++c) {
    for (int k = 0; k < reduced_size; ++k) b_camera[k] += chunk_vectors[c][k];
  }
}

void BundleLevenbergMarquardt::Impl::SumChunkCopies(
    const double* base, const std::vector<Intervals>& intervals, int num_chunks,
    double* out) const {
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int r = 0; r < kMaxNumChunks; ++r) {
    const size_t range_begin = pair_values_size * r / kMaxNumChunks;
    const size_t range_end = pair_values_size * (r + 1) / kMaxNumChunks;
    if (base != nullptr) {
      std::copy(base + range_begin, base + range_end, out + range_begin);
    } else {
      std::fill(out + range_begin, out + range_end, 0.0);
    }
    for (int c = 0; c < num_chunks; ++c) {
      const double* copy = chunk_pairs[c].data();
      for (const auto& [begin, end] : intervals[c]) {
        const size_t first = std::max(begin, range_begin);
        const size_t last = std::min(end, range_end);
        for (size_t k = first; k < last; ++k) out[k] += copy[k];
      }
    }
  }
}

template <typename Invert>
void BundleLevenbergMarquardt::Impl::EliminatePoints(Invert invert,
                                                     Eigen::VectorXd* rhs) {
  const int num_chunks = static_cast<int>(chunks.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int c = 0; c < num_chunks; ++c) {
    const Chunk& chunk = chunks[c];
    double* pairs = chunk_pairs[c].data();
    std::vector<double>& vector = chunk_vectors[c];
    for (const auto& [begin, end] : point_chunk_intervals[c]) {
      std::fill(pairs + begin, pairs + end, 0.0);
    }
    std::fill(vector.begin(), vector.end(), 0);
    std::vector<double> y;  // V~^-1 W_pg, 3 x group size, per group
    std::vector<size_t> y_offset;
    for (int p = chunk.first_point; p < chunk.end_point; ++p) {
      if (point_held[p]) continue;  // V_p, W_p and b_p are zero: no term
      const PointStructure structure = StructureOf(p);
      Eigen::Map<Eigen::Matrix3d> v_inverse(&point_v_inverse[9 * p]);
      v_inverse =
          invert(p, Eigen::Map<const Eigen::Matrix3d>(&point_v[9 * p]));
      const Eigen::Vector3d vb =
          v_inverse * Eigen::Map<const Eigen::Vector3d>(&point_b[3 * p]);
      const int n = structure.num_groups;
      y_offset.assign(n + 1, 0);
      for (int i = 0; i < n; ++i) {
        y_offset[i + 1] = y_offset[i] + 3 * groups[structure.groups[i]].size;
      }
      if (y.size() < y_offset[n]) y.resize(y_offset[n]);
      std::fill(y.begin(), y.begin() + y_offset[n], 0.0);
      const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> v_inverse_rows =
          v_inverse;
      for (int i = 0; i < n; ++i) {
        const int size = groups[structure.groups[i]].size;
        AddAB(v_inverse_rows.data(), &point_w[structure.w_offset[i]], 3, 3,
              size, y.data() + y_offset[i], size);
      }
      int pair = 0;
      for (int i = 0; i < n; ++i) {
        const Group& gi = groups[structure.groups[i]];
        const double* wi = &point_w[structure.w_offset[i]];
        // rhs_g += W_pg^T V~^-1 b_p;  S_gh -= W_pg^T V~^-1 W_ph.
        AddATransposeB(wi, vb.data(), 3, gi.size, 1, 1,
                       vector.data() + gi.offset, 1);
        AddATransposeBUpper(
            wi, y.data() + y_offset[i], 3, gi.size, -1,
            &pairs[pair_blocks[structure.pairs[pair++]].offset]);
        for (int j = i + 1; j < n; ++j, ++pair) {
          const int size = groups[structure.groups[j]].size;
          AddATransposeB(wi, y.data() + y_offset[j], 3, gi.size, size, -1,
                         &pairs[pair_blocks[structure.pairs[pair]].offset],
                         size);
        }
      }
    }
  }
  // S = U + the chunks' parts; rhs = -b_c + theirs; chunk order.
  SumChunkCopies(u_raw.data(), point_chunk_intervals, num_chunks,
                 reduced_values.data());
  *rhs = -Eigen::Map<const Eigen::VectorXd>(b_camera.data(), reduced_size);
  for (int c = 0; c < num_chunks; ++c) {
    for (int k = 0; k < reduced_size; ++k) (*rhs)[k] += chunk_vectors[c][k];
  }
}

void BundleLevenbergMarquardt::Impl::CopyReducedValues() {
  const LargeVector<double>& s = reduced_values;
  double* values = reduced.valuePtr();
  const int64_t num_values = static_cast<int64_t>(reduced_value_source.size());
#pragma omp parallel for schedule(static) num_threads(NumThreads())
  for (int64_t k = 0; k < num_values; ++k) {
    values[k] = s[reduced_value_source[k]];
  }
}

Eigen::Vector3d BundleLevenbergMarquardt::Impl::SolvePoint(
    int p, Eigen::Vector3d right, const double* camera) const {
  const PointStructure structure = StructureOf(p);
  for (int i = 0; i < structure.num_groups; ++i) {
    const Group& group = groups[structure.groups[i]];
    Eigen::Vector3d w_delta = Eigen::Vector3d::Zero();
    AddAB(&point_w[structure.w_offset[i]], camera + group.offset, 3,
          group.size, 1, w_delta.data(), 1);
    right -= w_delta;
  }
  return Eigen::Map<const Eigen::Matrix3d>(&point_v_inverse[9 * p]) * right;
}

bool BundleLevenbergMarquardt::Impl::ComputeStep(double mu,
                                                 double* factorization_seconds,
                                                 double* schur_seconds) {
  const auto schur_start = std::chrono::steady_clock::now();
  // V~_p = V_p + D_p / mu, symmetric positive definite (the LM diagonal is
  // > 0).
  Eigen::VectorXd rhs;
  EliminatePoints(
      [mu](int, Eigen::Matrix3d v) -> Eigen::Matrix3d {
        for (int i = 0; i < 3; ++i) {
          v(i, i) += std::clamp(v(i, i), kMinDiagonal, kMaxDiagonal) / mu;
        }
        return v.llt().solve(Eigen::Matrix3d::Identity());
      },
      &rhs);
  // S += D / mu.
  LargeVector<double>& s = reduced_values;
  for (size_t g = 0; g < groups.size(); ++g) {
    const Group& group = groups[g];
    for (int i = 0; i < group.size; ++i) {
      s[diagonal_pair_offset[g] + i * group.size + i] +=
          d_camera[group.offset + i] / mu;
    }
  }
  CopyReducedValues();
  *schur_seconds += Seconds(schur_start);
  const auto factorization_start = std::chrono::steady_clock::now();
  cholesky.factorize(reduced);
  if (cholesky.info() != Eigen::Success) {
    *factorization_seconds += Seconds(factorization_start);
    return false;
  }
  camera_step = cholesky.solve(rhs);
  *factorization_seconds += Seconds(factorization_start);
  if (cholesky.info() != Eigen::Success || !camera_step.allFinite()) {
    return false;
  }
  // delta_p = V~^-1 (-b_p - W_p delta_c).
  const int num_points = static_cast<int>(points.size());
#pragma omp parallel for schedule(static) num_threads(NumThreads())
  for (int p = 0; p < num_points; ++p) {
    Eigen::Map<Eigen::Vector3d> step(&point_step[3 * p]);
    if (point_held[p]) {
      step.setZero();
      continue;
    }
    step = SolvePoint(p, -Eigen::Map<const Eigen::Vector3d>(&point_b[3 * p]),
                      camera_step.data());
  }
  return std::all_of(point_step.begin(), point_step.end(),
                     [](double x) { return std::isfinite(x); });
}

double BundleLevenbergMarquardt::Impl::ModelCostChange() const {
  const int num_chunks = static_cast<int>(residual_chunks.size());
  std::vector<double> chunk_change(num_chunks, 0);
#pragma omp parallel for schedule(dynamic, 1) num_threads(NumThreads())
  for (int c = 0; c < num_chunks; ++c) {
    double change_sum = 0;
    for (size_t index = residual_chunks[c].first;
         index < residual_chunks[c].second; ++index) {
      const Residual& residual = residuals[index];
      Eigen::Vector2d j_delta = Eigen::Vector2d::Zero();
      for (int i = 0; i < residual.num_groups; ++i) {
        const Group& group = groups[residual.groups[i]];
        AddAB(&jacobians[residual.group_jacobian[i]],
              camera_step.data() + group.offset, 2, group.size, 1,
              j_delta.data(), 1);
      }
      if (residual.point >= 0) {
        j_delta +=
            Eigen::Map<const Eigen::Matrix<double, 2, 3, Eigen::RowMajor>>(
                &jacobians[residual.point_jacobian]) *
            Eigen::Map<const Eigen::Vector3d>(&point_step[3 * residual.point]);
      }
      const Eigen::Vector2d r(residual_values[2 * index],
                              residual_values[2 * index + 1]);
      change_sum -= r.dot(j_delta) + 0.5 * j_delta.squaredNorm();
    }
    chunk_change[c] = change_sum;  // a local sum, as in Evaluate
  }
  double change = 0;
  for (double part : chunk_change) change += part;
  return change;
}

double BundleLevenbergMarquardt::Impl::StepNorm() const {
  double sq = camera_step.squaredNorm();
  for (double x : point_step) sq += x * x;
  return std::sqrt(sq);
}

double BundleLevenbergMarquardt::Impl::ParameterNorm() const {
  double sq = 0;
  for (const Block& block : blocks) {
    for (int k = 0; k < block.size; ++k)
      sq += block.values[k] * block.values[k];
  }
  for (const double* point : points) {
    for (int k = 0; k < 3; ++k) sq += point[k] * point[k];
  }
  return std::sqrt(sq);
}

double BundleLevenbergMarquardt::Impl::GradientMaxNorm() const {
  double norm = 0;
  for (double g : b_camera) norm = std::max(norm, std::abs(g));
  for (double g : point_b) norm = std::max(norm, std::abs(g));
  return norm;
}

BundleLevenbergMarquardt::BundleLevenbergMarquardt(
    const BundleSolverOptions& options)
    : impl_(std::make_unique<Impl>(options)) {}

BundleLevenbergMarquardt::~BundleLevenbergMarquardt() = default;

void BundleLevenbergMarquardt::AddParameterBlock(
    double* values, int size, const ceres::Manifold* manifold, int group) {
  Impl::Block block;
  block.values = values;
  block.size = size;
  block.manifold = manifold;
  block.tangent_size = manifold != nullptr ? manifold->TangentSize() : size;
  block.group = group;
  impl_->structure_valid = false;
  impl_->last_block.fill({nullptr, -1});
  impl_->block_index.emplace(values, static_cast<int>(impl_->blocks.size()));
  impl_->blocks.push_back(block);
}

void BundleLevenbergMarquardt::Reserve(size_t num_residual_blocks,
                                       size_t num_points) {
  impl_->residuals.reserve(num_residual_blocks);
  impl_->points.reserve(num_points);
}

void BundleLevenbergMarquardt::AddPoint(double* values) {
  Impl& impl = *impl_;
  impl.structure_valid = false;
  if (impl.points_contiguous && !impl.points.empty() &&
      values != impl.points.back() + 3) {
    // The first point out of line: every point by hash from now on (the
    // first of two with the same address keeps it).
    impl.points_contiguous = false;
    impl.point_index.reserve(impl.points.capacity());
    for (size_t p = 0; p < impl.points.size(); ++p) {
      impl.point_index.emplace(impl.points[p], static_cast<int>(p));
    }
  }
  if (!impl.points_contiguous) {
    impl.point_index.emplace(values, static_cast<int>(impl.points.size()));
  }
  impl.points.push_back(values);
  impl.point_held.push_back(0);
}

void BundleLevenbergMarquardt::SetPointHeld(const double* values, bool held) {
  const int point = impl_->PointIndex(values);
  CHECK_GE(point, 0) << "not a point of the problem";
  impl_->point_held[point] = held ? 1 : 0;
}

void BundleLevenbergMarquardt::SetResidualBlockActive(size_t index,
                                                      bool active) {
  CHECK_LT(index, impl_->residuals.size());
  impl_->residuals[index].active = active;
}

void BundleLevenbergMarquardt::SetFunctionTolerance(double tolerance) {
  impl_->options.function_tolerance = tolerance;
}

size_t BundleLevenbergMarquardt::AddResidualBlock(
    const ceres::CostFunction* cost, const ceres::LossFunction* loss,
    const std::vector<double*>& parameters) {
  impl_->structure_valid = false;
  CHECK_EQ(cost->num_residuals(), 2);
  CHECK_LE(parameters.size(), kMaxParametersPerResidual);
  CHECK_EQ(parameters.size(), cost->parameter_block_sizes().size());
  Impl::Residual residual;
  residual.cost = cost;
  residual.loss = loss;
  residual.num_parameters = static_cast<int>(parameters.size());
  for (int k = 0; k < residual.num_parameters; ++k) {
    residual.parameters[k] = parameters[k];
    residual.block[k] = -1;
    residual.jacobian_columns[k] = cost->parameter_block_sizes()[k];
    // Consecutive residuals mostly share their blocks (one image's), and a
    // point is never a block.
    std::pair<const double*, int>& cached = impl_->last_block[k];
    int point = -1;
    if (cached.first != parameters[k]) {
      point = impl_->PointIndex(parameters[k]);
      const auto block = point < 0 ? impl_->block_index.find(parameters[k])
                                   : impl_->block_index.end();
      cached = {parameters[k],
                block != impl_->block_index.end() ? block->second : -1};
    } else if (cached.second < 0) {
      point = impl_->PointIndex(parameters[k]);
    }
    if (cached.second >= 0) {
      CHECK_EQ(impl_->blocks[cached.second].size,
               cost->parameter_block_sizes()[k]);
      residual.block[k] = cached.second;
      continue;
    }
    if (point >= 0) {
      CHECK_EQ(cost->parameter_block_sizes()[k], 3);
      CHECK_LT(residual.point, 0) << "two points in one residual block";
      residual.point = point;
      residual.point_parameter = k;
    }
  }
  // Tangent Jacobians from the cost if every refined block it gives them for
  // is on a manifold of that tangent size.
  const auto* tangent_cost = dynamic_cast<const TangentJacobianCost*>(cost);
  bool use_tangent = tangent_cost != nullptr;
  for (int k = 0; use_tangent && k < residual.num_parameters; ++k) {
    const int tangent_size = tangent_cost->TangentSize(k);
    if (tangent_size <= 0 || residual.block[k] < 0) continue;
    const Impl::Block& block = impl_->blocks[residual.block[k]];
    use_tangent =
        block.manifold != nullptr && block.tangent_size == tangent_size;
  }
  if (use_tangent) {
    residual.tangent_cost = tangent_cost;
    for (int k = 0; k < residual.num_parameters; ++k) {
      residual.tangent[k] =
          tangent_cost->TangentSize(k) > 0 && residual.block[k] >= 0;
      if (residual.tangent[k]) {
        residual.jacobian_columns[k] = tangent_cost->TangentSize(k);
      }
    }
  }
  impl_->residuals.push_back(std::move(residual));
  return impl_->residuals.size() - 1;
}

bool BundleLevenbergMarquardt::LinearizeGaussNewton(std::string* error) {
  Impl& impl = *impl_;
  if (!impl.structure_valid) {
    impl.structure_valid = impl.BuildStructure(error);
    if (!impl.structure_valid) return false;
  }
  impl.robust_loss = false;
  double cost = 0;
  const bool evaluated = impl.Evaluate(/*linearize=*/true, &cost);
  impl.robust_loss = true;
  if (!evaluated) {
    *error = "the residuals could not be evaluated at the current values";
    return false;
  }
  impl.point_rank.assign(impl.points.size(), 0);
  Eigen::VectorXd rhs;
  impl.EliminatePoints(
      [&impl](int p, const Eigen::Matrix3d& v) {
        return PointPseudoInverse(v, &impl.point_rank[p]);
      },
      &rhs);
  impl.CopyReducedValues();
  return true;
}

const Eigen::SparseMatrix<double>& BundleLevenbergMarquardt::ReducedMatrix()
    const {
  return impl_->reduced;
}

int BundleLevenbergMarquardt::GroupOffset(int group) const {
  return impl_->groups[group].offset;
}

int64_t BundleLevenbergMarquardt::NumDeterminedPointParameters() const {
  int64_t sum = 0;
  for (const int rank : impl_->point_rank) sum += rank;
  return sum;
}

Eigen::Vector2d BundleLevenbergMarquardt::Residual(size_t index) const {
  return Eigen::Vector2d(impl_->residual_values[2 * index],
                         impl_->residual_values[2 * index + 1]);
}

Eigen::Vector3d BundleLevenbergMarquardt::AddGradient(
    size_t index, double weight, Eigen::VectorXd* camera_gradient) const {
  const Impl& impl = *impl_;
  const Impl::Residual& residual = impl.residuals[index];
  const Eigen::Vector2d r = weight * Residual(index);
  for (int i = 0; i < residual.num_groups; ++i) {
    const Impl::Group& group = impl.groups[residual.groups[i]];
    AddATransposeB(&impl.jacobians[residual.group_jacobian[i]], r.data(), 2,
                   group.size, 1, 1, camera_gradient->data() + group.offset,
                   1);
  }
  if (residual.point < 0) return Eigen::Vector3d::Zero();
  return Eigen::Map<const Eigen::Matrix<double, 2, 3, Eigen::RowMajor>>(
             &impl.jacobians[residual.point_jacobian])
             .transpose() *
         r;
}

void BundleLevenbergMarquardt::EliminatePointVector(
    int point, const Eigen::Vector3d& b_p, Eigen::VectorXd* b_c) const {
  const Impl& impl = *impl_;
  const Eigen::Vector3d solved =
      Eigen::Map<const Eigen::Matrix3d>(&impl.point_v_inverse[9 * point]) *
      b_p;
  const Impl::PointStructure structure = impl.StructureOf(point);
  for (int i = 0; i < structure.num_groups; ++i) {
    const Impl::Group& group = impl.groups[structure.groups[i]];
    AddATransposeB(&impl.point_w[structure.w_offset[i]], solved.data(), 3,
                   group.size, 1, -1, b_c->data() + group.offset, 1);
  }
}

Eigen::Vector3d BundleLevenbergMarquardt::BackSubstitutePoint(
    int point, const Eigen::Vector3d& b_p, const Eigen::VectorXd& x_c) const {
  return impl_->SolvePoint(point, b_p, x_c.data());
}

void BundleLevenbergMarquardt::Solve(BundleSolverSummary* summary) {
  using Termination = BundleSolverSummary::Termination;
  Impl& impl = *impl_;
  const BundleSolverOptions& options = impl.options;
  const auto start_time = std::chrono::steady_clock::now();
  *summary = BundleSolverSummary();
  summary->num_residual_blocks = static_cast<int>(std::count_if(
      impl.residuals.begin(), impl.residuals.end(),
      [](const Impl::Residual& residual) { return residual.active; }));
  summary->num_points = static_cast<int>(
      std::count(impl.point_held.begin(), impl.point_held.end(), 0));
  const auto finish = [&](Termination termination, const std::string& message,
                          double cost) {
    summary->termination = termination;
    summary->message = message;
    summary->final_cost = cost;
    summary->seconds = Seconds(start_time);
  };
  std::string error;
  if (!impl.structure_valid || !impl.pattern_analyzed) {
    impl.structure_valid =
        impl.structure_valid || impl.BuildStructure(&error);
    if (impl.structure_valid) {
      impl.cholesky.analyzePattern(impl.reduced);
      impl.pattern_analyzed = impl.cholesky.info() == Eigen::Success;
      if (!impl.pattern_analyzed) {
        error = "the symbolic analysis of the reduced system failed";
      }
    }
    summary->structure_seconds = Seconds(start_time);
    if (!impl.pattern_analyzed) {
      finish(Termination::kFailure, error, 0);
      return;
    }
  }
  summary->reduced_system_size = impl.reduced_size;

  auto evaluation_start = std::chrono::steady_clock::now();
  double cost = 0;
  if (!impl.Evaluate(/*linearize=*/true, &cost)) {
    summary->evaluation_seconds += Seconds(evaluation_start);
    finish(Termination::kFailure,
           "the residuals could not be evaluated at the initial values", 0);
    return;
  }
  summary->evaluation_seconds += Seconds(evaluation_start);
  summary->initial_cost = cost;
  if (options.print_progress) {
    std::printf(
        "iter      cost      cost_change  |gradient|   |step|    "
        "tr_ratio  tr_radius  iter_time  total_time\n");
    PrintIteration(0, cost, 0.0, impl.GradientMaxNorm(), 0.0, 0.0,
                   options.initial_trust_region_radius, Seconds(start_time),
                   Seconds(start_time));
  }
  if (impl.GradientMaxNorm() <= options.gradient_tolerance) {
    finish(Termination::kConvergence, "gradient tolerance reached", cost);
    return;
  }
  double mu = options.initial_trust_region_radius;
  double decrease_factor = 2;
  std::vector<double> saved;
  for (int iteration = 1;; ++iteration) {
    if (iteration > options.max_num_iterations) {
      finish(Termination::kNoConvergence, "maximum number of iterations", cost);
      return;
    }
    const auto iteration_start = std::chrono::steady_clock::now();
    bool success = false;
    double candidate_cost = std::numeric_limits<double>::infinity();
    double ratio = 0;
    double step_norm = 0;
    if (impl.ComputeStep(mu, &summary->factorization_seconds,
                         &summary->schur_seconds)) {
      step_norm = impl.StepNorm();
      const double x_norm = impl.ParameterNorm();
      if (step_norm <= options.parameter_tolerance *
                           (x_norm + options.parameter_tolerance)) {
        finish(Termination::kConvergence, "parameter tolerance reached", cost);
        return;
      }
      const double model_change = impl.ModelCostChange();
      impl.ApplyStep(&saved);
      evaluation_start = std::chrono::steady_clock::now();
      const bool valid = impl.Evaluate(/*linearize=*/false, &candidate_cost);
      summary->evaluation_seconds += Seconds(evaluation_start);
      if (valid && model_change > 0) {
        ratio = (cost - candidate_cost) / model_change;
        success = ratio > kMinRelativeDecrease;
      }
      if (!valid) candidate_cost = std::numeric_limits<double>::infinity();
      if (!success) impl.Restore(saved);
    }
    const double cost_change = cost - candidate_cost;
    if (success) {
      ++summary->num_successful_steps;
      mu = std::min(kMaxTrustRegionRadius,
                    mu / std::max(1.0 / 3.0, 1.0 - std::pow(2 * ratio - 1, 3)));
      decrease_factor = 2;
      // Converged at the accepted step: it is the result, and its
      // linearization (the most expensive pass, ~1/3 of a 1-iteration solve
      // at 10^6 residuals) would serve no further step.
      if (std::abs(cost_change) <=
          options.function_tolerance * candidate_cost) {
        if (options.print_progress) {
          PrintIteration(iteration, candidate_cost, cost_change,
                         std::numeric_limits<double>::quiet_NaN(), step_norm,
                         ratio, mu, Seconds(iteration_start),
                         Seconds(start_time));
        }
        finish(Termination::kConvergence, "function tolerance reached",
               candidate_cost);
        return;
      }
      evaluation_start = std::chrono::steady_clock::now();
      double linearized_cost = 0;
      if (!impl.Evaluate(/*linearize=*/true, &linearized_cost)) {
        summary->evaluation_seconds += Seconds(evaluation_start);
        finish(Termination::kFailure,
               "the Jacobians could not be evaluated at an accepted step",
               candidate_cost);
        return;
      }
      summary->evaluation_seconds += Seconds(evaluation_start);
      cost = linearized_cost;
    } else {
      ++summary->num_unsuccessful_steps;
      mu /= decrease_factor;
      decrease_factor *= 2;
    }
    if (options.print_progress) {
      PrintIteration(iteration, cost, success ? cost_change : 0.0,
                     impl.GradientMaxNorm(), step_norm, ratio, mu,
                     Seconds(iteration_start), Seconds(start_time));
    }
    if (mu < kMinTrustRegionRadius) {
      finish(Termination::kConvergence, "minimum trust region radius reached",
             cost);
      return;
    }
    if (std::isfinite(cost_change) &&
        std::abs(cost_change) <= options.function_tolerance * cost) {
      finish(Termination::kConvergence, "function tolerance reached", cost);
      return;
    }
    if (success && impl.GradientMaxNorm() <= options.gradient_tolerance) {
      finish(Termination::kConvergence, "gradient tolerance reached", cost);
      return;
    }
  }
}

}  // namespace rig_calibrator
