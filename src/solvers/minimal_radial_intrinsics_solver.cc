#include "src/solvers/minimal_radial_intrinsics_solver.h"

#include <colmap/base/polynomial.h>

#include <Eigen/Dense>
#include <algorithm>
#include <boost/math/tools/minima.hpp>
#include <boost/math/tools/toms748_solve.hpp>
#include <cmath>
#include <cstdint>
#include <limits>

#include "src/solvers/radial_profile_fit.h"

namespace rig_calibrator {
namespace {

// A companion-matrix eigenvalue is taken as a real root when its imaginary
// part is below this fraction of 1 + |root| (v is of order 1): a double root
// perturbed by rounding splits into a complex pair ~1e-8 apart, and a
// spurious near-real root does not survive the Newton polish.
constexpr double kMaxRelativeImaginaryPart = 1e-4;
// The sign scan of det M for the equidistant profile: steps of 7.5 % in the
// depth of the nearest point from 1e-4 to 1e4 times L (angles from ~90
// degrees to ~0).
constexpr int kNumEquidistantScanSteps = 256;
constexpr double kEquidistantScanRange = 9.2;  // ln(1e4)
// Root and minimum searches of the scan.
constexpr std::uintmax_t kMaxNumBracketIterations = 100;
// Newton steps after the root finding (2-3 reach machine precision).
constexpr int kMaxNumNewtonPolishIterations = 8;
// A polished root is a solution when the RMS radial residual of the sample
// is below this fraction of its RMS radius.
constexpr double kMaxRelativeResidual = 1e-6;
// Solutions closer than this fraction of L are one.
constexpr double kRelativeDuplicateTz = 1e-9;

// The sample in scaled form: rho~ = rho / sigma (sigma = RMS of rho),
// s~ = s / L, e = (c - mean(c)) / L, so that d = c + tz = L (e + v) with
// v = (tz + mean(c)) / L; phi is unchanged by the scaling, and a known f
// becomes f~ = f / sigma (f phi - rho = sigma (f~ phi - rho~)).
struct ScaledSample {
  std::vector<double> rho, s, e;
  double sigma = 0, length = 0, mean_c = 0;
  double min_v = 0;             // every depth is positive for v > min_v
  std::optional<double> focal;  // f~ when f is known
};

bool MakeScaledSample(const std::vector<Eigen::Vector2d>& x,
                      const std::vector<Eigen::Vector3d>& points_cam,
                      const std::optional<double>& known_focal,
                      ScaledSample* sample) {
  const int m = static_cast<int>(x.size());
  double sum_squared_rho = 0, sum_squared_length = 0;
  sample->mean_c = 0;
  for (int i = 0; i < m; ++i) {
    sample->mean_c += points_cam[i].z() / m;
  }
  for (int i = 0; i < m; ++i) {
    const double s = SignedRadialCoordinate(x[i], points_cam[i]);
    const double e = points_cam[i].z() - sample->mean_c;
    sample->rho.push_back(x[i].norm());
    sample->s.push_back(s);
    sample->e.push_back(e);
    sum_squared_rho += x[i].squaredNorm();
    sum_squared_length += s * s + e * e;
  }
  sample->sigma = std::sqrt(sum_squared_rho / m);
  sample->length = std::sqrt(sum_squared_length / m);
  if (!(sample->sigma > 0) || !(sample->length > 0) ||
      !std::isfinite(sample->sigma) || !std::isfinite(sample->length)) {
    return false;
  }
  sample->min_v = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < m; ++i) {
    sample->rho[i] /= sample->sigma;
    sample->s[i] /= sample->length;
    sample->e[i] /= sample->length;
    sample->min_v = std::max(sample->min_v, -sample->e[i]);
  }
  if (known_focal) {
    sample->focal = *known_focal / sample->sigma;
  }
  return true;
}

// Polynomials in v as coefficient vectors, lowest degree first.
typedef std::vector<double> Polynomial;

Polynomial Multiply(const Polynomial& a, const Polynomial& b) {
  Polynomial product(a.size() + b.size() - 1, 0.0);
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t j = 0; j < b.size(); ++j) {
      product[i + j] += a[i] * b[j];
    }
  }
  return product;
}

void AddScaled(const Polynomial& a, const double scale, Polynomial* sum) {
  if (sum->size() < a.size()) sum->resize(a.size(), 0.0);
  for (size_t i = 0; i < a.size(); ++i) {
    (*sum)[i] += scale * a[i];
  }
}

// factor (e + v)^power.
Polynomial ScaledPowerOfShift(const double factor, const double e,
                              const int power) {
  Polynomial result = {factor};
  for (int p = 0; p < power; ++p) {
    result = Multiply(result, {e, 1.0});
  }
  return result;
}

// Determinant of a square matrix of polynomials by cofactor expansion along
// the first row (at most 4x4: 24 products, no division, hence exact up to
// the rounding of the products).
Polynomial Determinant(const std::vector<std::vector<Polynomial>>& matrix) {
  const size_t size = matrix.size();
  if (size == 1) return matrix[0][0];
  Polynomial determinant = {0.0};
  for (size_t column = 0; column < size; ++column) {
    std::vector<std::vector<Polynomial>> minor;
    for (size_t row = 1; row < size; ++row) {
      std::vector<Polynomial> minor_row;
      for (size_t j = 0; j < size; ++j) {
        if (j != column) minor_row.push_back(matrix[row][j]);
      }
      minor.push_back(minor_row);
    }
    AddScaled(Multiply(matrix[0][column], Determinant(minor)),
              column % 2 == 0 ? 1.0 : -1.0, &determinant);
  }
  return determinant;
}

// Roots v > min_v of the polynomial profile's det M'(v), where row i of M' is
// row i of M times d_i^(2n+1) in scaled units:
//   [s_i (e_i + v)^(2n), s_i^3 (e_i + v)^(2n-2), .., s_i^(2n+1),
//    -rho_i (e_i + v)^(2n+1)],
// with a known f its first entry times f~ added to the last, then dropped.
std::vector<double> PolynomialProfileRoots(const ScaledSample& sample,
                                           const int num_radial_terms) {
  const int n = num_radial_terms;
  const int size = static_cast<int>(sample.rho.size());
  std::vector<std::vector<Polynomial>> matrix(size);
  for (int i = 0; i < size; ++i) {
    for (int j = 0; j <= n; ++j) {
      matrix[i].push_back(ScaledPowerOfShift(std::pow(sample.s[i], 2 * j + 1),
                                             sample.e[i], 2 * n - 2 * j));
    }
    matrix[i].push_back(
        ScaledPowerOfShift(-sample.rho[i], sample.e[i], 2 * n + 1));
    if (sample.focal) {
      AddScaled(matrix[i].front(), *sample.focal, &matrix[i].back());
      matrix[i].erase(matrix[i].begin());
    }
  }
  const Polynomial determinant = Determinant(matrix);
  Eigen::VectorXd coeffs(determinant.size());
  for (size_t i = 0; i < determinant.size(); ++i) {
    coeffs(determinant.size() - 1 - i) = determinant[i];
  }
  Eigen::VectorXd real, imag;
  if (!coeffs.allFinite() ||
      !colmap::FindPolynomialRootsCompanionMatrix(coeffs, &real, &imag)) {
    return {};
  }
  std::vector<double> roots;
  for (Eigen::Index i = 0; i < real.size(); ++i) {
    if (std::abs(imag(i)) <=
            kMaxRelativeImaginaryPart * (1 + std::abs(real(i))) &&
        real(i) > sample.min_v) {
      roots.push_back(real(i));
    }
  }
  return roots;
}

// det M(v) of the equidistant profile, M's rows [phi_i, phi_i^3, ..,
// phi_i^(2n+1), -rho_i] with phi_i = atan2(s_i, e_i + v); with a known f
// [phi_i^3, .., phi_i^(2n+1), f~ phi_i - rho_i].
double EquidistantDeterminant(const ScaledSample& sample,
                              const int num_radial_terms, const double v) {
  const int size = static_cast<int>(sample.rho.size());
  const int num_columns = num_radial_terms + 2;
  Eigen::MatrixXd M(size, num_columns);
  for (int i = 0; i < size; ++i) {
    const double phi = std::atan2(sample.s[i], sample.e[i] + v);
    double phi_power = phi;
    for (int j = 0; j <= num_radial_terms; ++j) {
      M(i, j) = phi_power;
      phi_power *= phi * phi;
    }
    M(i, num_columns - 1) = -sample.rho[i];
  }
  if (sample.focal) {
    M.col(num_columns - 1) += *sample.focal * M.col(0);
  }
  return M.rightCols(size).determinant();
}

// Roots of the equidistant profile's det M(v), bracketed by the sign scan of
// the depth of the nearest point, v - min_v = exp(u) in units of L, over
// u in [-kEquidistantScanRange, kEquidistantScanRange] (see the header).
std::vector<double> EquidistantProfileRoots(const ScaledSample& sample,
                                            const int num_radial_terms) {
  const auto v_of_u = [&](const double u) {
    return sample.min_v + std::exp(u);
  };
  const auto det = [&](const double u) {
    return EquidistantDeterminant(sample, num_radial_terms, v_of_u(u));
  };
  std::vector<double> u(kNumEquidistantScanSteps + 1);
  std::vector<double> values(kNumEquidistantScanSteps + 1);
  for (int k = 0; k <= kNumEquidistantScanSteps; ++k) {
    u[k] = kEquidistantScanRange * (2.0 * k / kNumEquidistantScanSteps - 1);
    values[k] = det(u[k]);
  }
  const boost::math::tools::eps_tolerance<double> tolerance(
      std::numeric_limits<double>::digits - 2);
  std::vector<double> roots;
  const auto solve_bracket = [&](const double lo, const double hi,
                                 const double det_lo, const double det_hi) {
    if (det_lo == 0 || det_hi == 0 || (det_lo < 0) == (det_hi < 0)) return;
    std::uintmax_t max_num_iterations = kMaxNumBracketIterations;
    const std::pair<double, double> bracket = boost::math::tools::toms748_solve(
        det, lo, hi, det_lo, det_hi, tolerance, max_num_iterations);
    roots.push_back(v_of_u((bracket.first + bracket.second) / 2));
  };
  for (int k = 0; k < kNumEquidistantScanSteps; ++k) {
    if (values[k] == 0) roots.push_back(v_of_u(u[k]));
    solve_bracket(u[k], u[k + 1], values[k], values[k + 1]);
  }
  // Two roots between neighbouring samples leave the signs equal but |det| a
  // local minimum there: the minimum of sign * det between the neighbours
  // splits them if it has the other sign.
  for (int k = 1; k < kNumEquidistantScanSteps; ++k) {
    const double sign = values[k] < 0 ? -1 : 1;
    if (!(sign * values[k] < sign * values[k - 1] &&
          sign * values[k] < sign * values[k + 1])) {
      continue;
    }
    std::uintmax_t max_num_iterations = kMaxNumBracketIterations;
    const double u_min =
        boost::math::tools::brent_find_minima(
            [&](const double u) { return sign * det(u); }, u[k - 1], u[k + 1],
            std::numeric_limits<double>::digits / 2, max_num_iterations)
            .first;
    const double det_min = det(u_min);
    solve_bracket(u[k - 1], u_min, values[k - 1], det_min);
    solve_bracket(u_min, u[k + 1], det_min, values[k + 1]);
  }
  return roots;
}

}  // namespace

std::vector<RadialIntrinsics> SolveMinimalRadialIntrinsics(
    const std::vector<Eigen::Vector2d>& x,
    const std::vector<Eigen::Vector3d>& points_cam, const RadialProfile profile,
    const int num_radial_terms, const std::optional<double>& known_focal) {
  ScaledSample sample;
  const size_t num_unknowns = num_radial_terms + (known_focal ? 1 : 2);
  if (num_radial_terms < 0 || num_radial_terms > 2 ||
      x.size() != num_unknowns || points_cam.size() != x.size() ||
      (known_focal && !(std::isfinite(*known_focal) && *known_focal > 0)) ||
      !MakeScaledSample(x, points_cam, known_focal, &sample)) {
    return {};
  }
  const std::vector<double> roots =
      profile == RadialProfile::kPolynomial
          ? PolynomialProfileRoots(sample, num_radial_terms)
          : EquidistantProfileRoots(sample, num_radial_terms);

  const double max_squared_error =
      x.size() * std::pow(kMaxRelativeResidual * sample.sigma, 2);
  std::vector<RadialIntrinsics> solutions;
  for (const double v : roots) {
    RadialIntrinsics model;
    model.profile = profile;
    model.num_radial_terms = num_radial_terms;
    model.tz = v * sample.length - sample.mean_c;
    double squared_error = 0;
    if (RefineRadialProfileAndTz(x, points_cam, known_focal,
                                 kMaxNumNewtonPolishIterations, &model,
                                 &squared_error) &&
        squared_error <= max_squared_error &&
        RadiusGrowsOverPoints(x, points_cam, model)) {
      solutions.push_back(model);
    }
  }
  std::sort(solutions.begin(), solutions.end(),
            [](const RadialIntrinsics& a, const RadialIntrinsics& b) {
              return a.tz < b.tz;
            });
  solutions.erase(
      std::unique(solutions.begin(), solutions.end(),
                  [&](const RadialIntrinsics& a, const RadialIntrinsics& b) {
                    return b.tz - a.tz <= kRelativeDuplicateTz * sample.length;
                  }),
      solutions.end());
  return solutions;
}

}  // namespace rig_calibrator
