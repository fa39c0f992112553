#include "src/synthetic/textured_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "src/synthetic/enum_names.h"
#include "src/synthetic/hash_random.h"

namespace rig_calibrator {
namespace {

// One Mix of the cell coordinates multiplied by large odd constants: cheap
// (it runs once per lattice corner) and unrelated across neighbouring cells.
inline uint64_t HashCell(uint64_t seed, int64_t i, int64_t j) {
  return Mix(seed ^ (static_cast<uint64_t>(i) * 0x9e3779b97f4a7c15ull) ^
             (static_cast<uint64_t>(j) * 0xc2b2ae3d27d4eb4full));
}

// Successive independent uniforms from one cell hash.
class CellRandom {
 public:
  explicit CellRandom(uint64_t hash) : state_(hash) {}
  double Uniform(double lo, double hi) {
    state_ = Mix(state_);
    return lo + (hi - lo) * ToUnit(state_);
  }

 private:
  uint64_t state_;
};

inline double Clamp01(double x) { return std::min(1.0, std::max(0.0, x)); }

// 0 below edge0, 1 above edge1, C1-smooth in between.
inline double SmoothStep(double edge0, double edge1, double x) {
  const double t = Clamp01((x - edge0) / (edge1 - edge0));
  return t * t * (3.0 - 2.0 * t);
}

// Perlin's quintic fade 6t^5 - 15t^4 + 10t^3 (C2 at the lattice).
inline double Fade(double t) {
  return t * t * t * (t * (6.0 * t - 15.0) + 10.0);
}

// 2D gradient noise (Perlin): unit gradients from 16 directions hashed per
// lattice point, dotted with the offset to the point and blended with Fade.
// Zero mean, values within about [-0.7, 0.7].
double GradientNoise(uint64_t seed, double x, double y) {
  static const std::array<Eigen::Vector2d, 16> kGradients = [] {
    std::array<Eigen::Vector2d, 16> gradients;
    for (int k = 0; k < 16; ++k) {
      const double angle = (k + 0.5) * 2.0 * M_PI / 16.0;
      gradients[k] = Eigen::Vector2d(std::cos(angle), std::sin(angle));
    }
    return gradients;
  }();
  const double fx = std::floor(x);
  const double fy = std::floor(y);
  const int64_t ix = static_cast<int64_t>(fx);
  const int64_t iy = static_cast<int64_t>(fy);
  const double dx = x - fx;
  const double dy = y - fy;
  auto corner = [&](int64_t cx, int64_t cy, double ox, double oy) {
    const Eigen::Vector2d& g = kGradients[HashCell(seed, cx, cy) & 15];
    return g.x() * ox + g.y() * oy;
  };
  const double n00 = corner(ix, iy, dx, dy);
  const double n10 = corner(ix + 1, iy, dx - 1.0, dy);
  const double n01 = corner(ix, iy + 1, dx, dy - 1.0);
  const double n11 = corner(ix + 1, iy + 1, dx - 1.0, dy - 1.0);
  const double u = Fade(dx);
  const double v = Fade(dy);
  const double nx0 = n00 + u * (n10 - n00);
  const double nx1 = n01 + u * (n11 - n01);
  return nx0 + v * (nx1 - nx0);
}

// Multi-octave noise with wavelengths 2 m ... 1.6 cm; octave k has amplitude
// (lambda_k / lambda_0)^0.3, so fine detail keeps contrast. Each octave is
// rotated and shifted so lattice axes do not line up across octaves. An
// octave fades out when its wavelength drops below 2-4 footprints.
double FractalNoise(uint64_t seed, const Eigen::Vector2d& uv,
                    double footprint) {
  constexpr int kNumOctaves = 8;
  constexpr double kLongestWavelength = 2.0;
  struct Octave {
    double cos_angle, sin_angle, amplitude;
  };
  static const std::array<Octave, kNumOctaves> kOctaves = [] {
    std::array<Octave, kNumOctaves> octaves;
    for (int k = 0; k < kNumOctaves; ++k) {
      const double angle = 0.61 + 1.37 * k;
      octaves[k] = {std::cos(angle), std::sin(angle), std::pow(0.5, 0.3 * k)};
    }
    return octaves;
  }();
  double sum = 0;
  double wavelength = kLongestWavelength;
  for (int k = 0; k < kNumOctaves; ++k, wavelength *= 0.5) {
    const double weight =
        SmoothStep(2.0 * footprint, 4.0 * footprint, wavelength);
    if (weight <= 0) break;
    const Octave& octave = kOctaves[k];
    const double x =
        (octave.cos_angle * uv.x() - octave.sin_angle * uv.y()) / wavelength;
    const double y =
        (octave.sin_angle * uv.x() + octave.cos_angle * uv.y()) / wavelength;
    sum += weight * octave.amplitude * GradientNoise(seed + k, x, y);
  }
  return sum;
}

// One layer of random shapes on a square grid of `cell` meters: each cell
// holds at most one shape (a disc or a rotated rectangle) that fits inside
// the cell, so a point only looks at its own cell.
struct ShapeLayer {
  double cell;
  double probability;  // that a cell holds a shape
  bool disc;
  // Disc radius, or rectangle half-length, as fractions of the cell.
  double min_size, max_size;
  // Rectangle half-width as a fraction of its half-length (1: square-ish).
  double min_aspect, max_aspect;
  double min_contrast, max_contrast;
};

const std::array<ShapeLayer, 9>& ShapeLayers() {
  static const std::array<ShapeLayer, 9> kLayers = {{
      {0.035, 0.55, true, 0.14, 0.38, 1, 1, 0.20, 0.45},
      {0.09, 0.55, true, 0.12, 0.38, 1, 1, 0.20, 0.45},
      {0.24, 0.5, true, 0.10, 0.36, 1, 1, 0.15, 0.40},
      {0.7, 0.45, true, 0.08, 0.32, 1, 1, 0.12, 0.30},
      {0.13, 0.35, false, 0.12, 0.32, 0.35, 1.0, 0.15, 0.40},
      {0.4, 0.4, false, 0.10, 0.32, 0.25, 1.0, 0.12, 0.35},
      {1.3, 0.4, false, 0.10, 0.32, 0.3, 1.0, 0.10, 0.25},
      {0.3, 0.3, false, 0.25, 0.40, 0.04, 0.10, 0.15, 0.40},
      {1.0, 0.3, false, 0.25, 0.40, 0.03, 0.07, 0.12, 0.30},
  }};
  return kLayers;
}

// The signed contribution of one layer at uv: contrast times the coverage of
// the shape, with edges blurred over the footprint. A shape thinner than the
// footprint fades out (its mean over the footprint is close to the background).
double ShapeLayerValue(uint64_t seed, const ShapeLayer& layer,
                       const Eigen::Vector2d& uv, double footprint) {
  if (layer.cell < footprint) return 0;
  const double fx = std::floor(uv.x() / layer.cell);
  const double fy = std::floor(uv.y() / layer.cell);
  CellRandom random(
      HashCell(seed, static_cast<int64_t>(fx), static_cast<int64_t>(fy)));
  if (random.Uniform(0, 1) >= layer.probability) return 0;
  const double size =
      layer.cell * random.Uniform(layer.min_size, layer.max_size);
  const double half_width =
      size * random.Uniform(layer.min_aspect, layer.max_aspect);
  // The bounding circle, kept inside the cell.
  const double bound = layer.disc ? size : std::hypot(size, half_width);
  const double cx = fx * layer.cell + random.Uniform(bound, layer.cell - bound);
  const double cy = fy * layer.cell + random.Uniform(bound, layer.cell - bound);
  const double px = uv.x() - cx;
  const double py = uv.y() - cy;
  const double edge = std::max(footprint, 1e-4);
  // Outside the bounding circle plus the blur nothing is covered.
  if (px * px + py * py > (bound + edge) * (bound + edge)) return 0;
  const double thickness = 2.0 * half_width;
  const double visibility =
      SmoothStep(0.5 * footprint, 2.0 * footprint, thickness);
  if (visibility <= 0) return 0;
  const double sign = random.Uniform(0, 1) < 0.5 ? -1.0 : 1.0;
  const double contrast =
      sign * random.Uniform(layer.min_contrast, layer.max_contrast);
  double signed_distance;
  if (layer.disc) {
    signed_distance = std::hypot(px, py) - size;
  } else {
    const double angle = random.Uniform(0, M_PI);
    const double c = std::cos(angle);
    const double s = std::sin(angle);
    const double along = std::abs(c * px + s * py) - size;
    const double across = std::abs(-s * px + c * py) - half_width;
    signed_distance = std::max(along, across);
  }
  const double coverage = Clamp01(0.5 - signed_distance / edge);
  return visibility * contrast * coverage;
}

// The unshaded grey level of a face's texture at uv (meters in the face's
// plane), in [0, 1].
double TextureValue(uint64_t face_seed, const Eigen::Vector2d& uv,
                    double footprint) {
  double value = 0.5 + 0.42 * FractalNoise(face_seed, uv, footprint);
  const auto& layers = ShapeLayers();
  for (size_t k = 0; k < layers.size(); ++k) {
    value +=
        ShapeLayerValue(Mix(face_seed + 101 + k), layers[k], uv, footprint);
  }
  return Clamp01(value);
}

uint64_t FaceSeed(unsigned int scene_seed, int face) {
  return Mix(Mix(static_cast<uint64_t>(scene_seed) + 0x5851f42d4c957f2dull) +
             static_cast<uint64_t>(face));
}

SceneBox Solid(double x0, double y0, double z0, double x1, double y1,
               double z1) {
  SceneBox box;
  box.min =
      Eigen::Vector3d(std::min(x0, x1), std::min(y0, y1), std::min(z0, z1));
  box.max =
      Eigen::Vector3d(std::max(x0, x1), std::max(y0, y1), std::max(z0, z1));
  return box;
}

void AddTable(double x0, double y0, double x1, double y1, double height,
              std::vector<SceneBox>* boxes) {
  constexpr double kLeg = 0.06;
  boxes->push_back(Solid(x0, y0, height - 0.05, x1, y1, height));
  for (const double x : {x0, x1 - kLeg}) {
    for (const double y : {y0, y1 - kLeg}) {
      boxes->push_back(Solid(x, y, 0, x + kLeg, y + kLeg, height - 0.05));
    }
  }
}

// A scene whose walk ellipse is centered on the origin.
TexturedScene SceneWithWalk(std::vector<SceneBox> boxes,
                            const Eigen::Vector2d& walk_radii,
                            double eye_height, unsigned int seed) {
  SceneWalk walk;
  walk.radii = walk_radii;
  walk.eye_height = eye_height;
  return TexturedScene(std::move(boxes), walk, seed);
}

TexturedScene MakeRoom(unsigned int seed) {
  std::vector<SceneBox> boxes;
  SceneBox room = Solid(-4, -3, 0, 4, 3, 3);
  room.enclosure = true;
  boxes.push_back(room);
  boxes.push_back(Solid(-0.25, -0.25, 0, 0.25, 0.25, 3));  // pillar
  boxes.push_back(Solid(-4, -0.2, 2.75, 4, 0.2, 3));       // ceiling beam
  boxes.push_back(Solid(-4, -1.2, 0, -3.4, 0.6, 2.0));     // cabinet
  boxes.push_back(Solid(-2.5, 2.6, 0, -0.5, 3, 2.2));      // shelf
  boxes.push_back(Solid(-0.4, 2.75, 1.6, 0.9, 3, 1.75));   // wall board
  boxes.push_back(Solid(1.0, 2.85, 0.8, 2.0, 3, 2.2));     // picture
  boxes.push_back(Solid(3.9, -0.8, 1.0, 4, 0.6, 2.0));     // panel
  boxes.push_back(Solid(-1.0, -3, 0, 1.0, -2.6, 0.45));    // bench
  boxes.push_back(Solid(2.0, -3, 0, 2.9, -2.75, 1.9));     // locker
  boxes.push_back(Solid(2.8, -2.6, 0, 3.5, -1.9, 0.7));    // crates
  boxes.push_back(Solid(3.0, -2.5, 0.7, 3.6, -2.0, 1.2));
  boxes.push_back(Solid(-3.5, 2.0, 0, -2.7, 2.8, 0.9));
  boxes.push_back(Solid(-3.9, -2.9, 0, -3.0, -2.1, 1.1));
  AddTable(2.6, 1.2, 3.6, 2.4, 0.78, &boxes);
  return SceneWithWalk(std::move(boxes), Eigen::Vector2d(2.3, 1.4), 1.5, seed);
}

TexturedScene MakeCourtyard(unsigned int seed) {
  std::vector<SceneBox> boxes;
  boxes.push_back(Solid(-40, -40, -1, 40, 40, 0));  // ground
  // Wings: x or y range of a segment, its front line and its height.
  boxes.push_back(Solid(-22, 12, 0, -6, 22, 12));  // north
  boxes.push_back(Solid(-6, 13.5, 0, 4, 22, 9));
  boxes.push_back(Solid(4, 12, 0, 22, 22, 14));
  boxes.push_back(Solid(-22, -22, 0, -2, -12, 10));  // south
  boxes.push_back(Solid(-2, -22, 0, 9, -11, 13));
  boxes.push_back(Solid(9, -22, 0, 22, -12.5, 11));
  boxes.push_back(Solid(-22, -12, 0, -13, -3, 11));  // west
  boxes.push_back(Solid(-22, -3, 0, -14.5, 5, 9.5));
  boxes.push_back(Solid(-22, 5, 0, -13, 12, 12.5));
  boxes.push_back(Solid(13, -12, 0, 22, 0, 13.5));  // east
  boxes.push_back(Solid(12, 0, 0, 22, 12, 10));
  // Balconies and a canopy.
  boxes.push_back(Solid(-18, 11.2, 4, -14, 12, 4.2));
  boxes.push_back(Solid(8, 11.2, 7, 12, 12, 7.2));
  boxes.push_back(Solid(-13, -9, 3.5, -12.2, -5, 3.7));
  boxes.push_back(Solid(12, -8, 2.8, 13, -3, 3.0));
  boxes.push_back(Solid(-1, -11, 3.2, 6, -10, 3.4));
  // Fountain, kiosks, benches, posts.
  boxes.push_back(Solid(-1.5, -1.5, 0, 1.5, 1.5, 0.6));
  boxes.push_back(Solid(-0.3, -0.3, 0.6, 0.3, 0.3, 2.0));
  boxes.push_back(Solid(6, 4, 0, 8.5, 6, 2.6));
  boxes.push_back(Solid(-9, -6, 0, -7, -4.5, 2.2));
  boxes.push_back(Solid(-5, 7, 0, -3, 7.5, 0.45));
  boxes.push_back(Solid(2, -8, 0, 4, -7.5, 0.45));
  for (const double x : {-4.0, 4.0}) {
    for (const double y : {-8.5, 8.5}) {
      boxes.push_back(Solid(x - 0.08, y - 0.08, 0, x + 0.08, y + 0.08, 3));
    }
  }
  return SceneWithWalk(std::move(boxes), Eigen::Vector2d(6.5, 6.0), 1.6, seed);
}

TexturedScene MakeStreet(unsigned int seed) {
  std::vector<SceneBox> boxes;
  boxes.push_back(Solid(-60, -30, -1, 60, 30, 0));  // ground
  // Buildings on both sides, from x = -35 to 35, with widths, setbacks and
  // heights from a fixed sequence (the geometry does not depend on the seed).
  CellRandom layout(0x5eed5eedull);
  for (const double side : {-1.0, 1.0}) {
    double x = -35;
    while (x < 35) {
      const double width = std::min(35 - x, layout.Uniform(6, 10));
      const double front = 6 + layout.Uniform(0, 2);
      const double height = layout.Uniform(8, 20);
      boxes.push_back(Solid(x, side * front, 0, x + width, side * 20, height));
      // A shop front canopy on some buildings.
      if (layout.Uniform(0, 1) < 0.5) {
        boxes.push_back(Solid(x + 1, side * (front - 0.8), 2.8, x + width - 1,
                              side * front, 3.0));
      }
      x += width;
    }
  }
  boxes.push_back(Solid(-45, -20, 0, -35, 20, 15));  // closing the ends
  boxes.push_back(Solid(35, -20, 0, 45, 20, 18));
  // Parked cars (body and cabin) and lamp posts.
  for (const double side : {-1.0, 1.0}) {
    for (int k = 0; k < 5; ++k) {
      const double x = -26 + 12 * k + (side > 0 ? 5 : 0);
      boxes.push_back(Solid(x, side * 3.6, 0.2, x + 4.2, side * 5.4, 1.0));
      boxes.push_back(
          Solid(x + 1.0, side * 3.8, 1.0, x + 3.2, side * 5.2, 1.5));
    }
    for (int k = 0; k < 6; ++k) {
      const double x = -30 + 12 * k + (side > 0 ? 0 : 6);
      boxes.push_back(
          Solid(x - 0.1, side * 5.6 - 0.1, 0, x + 0.1, side * 5.6 + 0.1, 5));
    }
  }
  return SceneWithWalk(std::move(boxes), Eigen::Vector2d(12, 1.8), 1.6, seed);
}

constexpr EnumNameTable<SceneType, 3> kSceneTypeNames = {
    {{SceneType::kRoom, "room"},
     {SceneType::kCourtyard, "courtyard"},
     {SceneType::kStreet, "street"}}};

}  // namespace

bool SceneTypeFromName(const std::string& name, SceneType* type) {
  return EnumFromName(kSceneTypeNames, name, type);
}

std::string SceneTypeName(SceneType type) {
  return EnumName(kSceneTypeNames, type);
}

std::vector<SceneType> AllSceneTypes() { return EnumValues(kSceneTypeNames); }

TexturedScene::TexturedScene(std::vector<SceneBox> boxes, const SceneWalk& walk,
                             unsigned int seed)
    : boxes_(std::move(boxes)), walk_(walk), seed_(seed) {}

TexturedScene TexturedScene::Make(SceneType type, unsigned int seed) {
  switch (type) {
    case SceneType::kRoom:
      return MakeRoom(seed);
    case SceneType::kCourtyard:
      return MakeCourtyard(seed);
    case SceneType::kStreet:
      return MakeStreet(seed);
  }
  return TexturedScene();
}

bool TexturedScene::Intersect(const Eigen::Vector3d& origin,
                              const Eigen::Vector3d& direction,
                              SceneHit* hit) const {
  // Slab test per box: along axis a the ray is between the box's planes for
  // t in [(min_a - o_a) / d_a, (max_a - o_a) / d_a] (swapped for d_a < 0). A
  // solid box is entered at the largest entry time, an enclosure is left at
  // the smallest exit time.
  constexpr double kMinDistance = 1e-6;
  constexpr double kTinyComponent = 1e-12;
  // No zero components: 0 * inf would make the slab times NaN.
  const Eigen::Array3d safe_direction =
      direction.array().unaryExpr([](double d) {
        return std::abs(d) < kTinyComponent ? std::copysign(kTinyComponent, d)
                                            : d;
      });
  const Eigen::Array3d inverse = safe_direction.inverse();
  const Eigen::Array3d start = origin.array();
  double best = std::numeric_limits<double>::infinity();
  int best_box = -1;
  for (size_t b = 0; b < boxes_.size(); ++b) {
    const SceneBox& box = boxes_[b];
    const Eigen::Array3d t_min = (box.min.array() - start) * inverse;
    const Eigen::Array3d t_max = (box.max.array() - start) * inverse;
    const double t_enter = t_min.min(t_max).maxCoeff();
    const double t_exit = t_min.max(t_max).minCoeff();
    if (t_enter > t_exit) continue;
    const double t = box.enclosure ? t_exit : t_enter;
    if (t > kMinDistance && t < best) {
      best = t;
      best_box = static_cast<int>(b);
    }
  }
  if (best_box < 0) return false;
  // The face: the axis whose slab time is the hit time, on the side the ray
  // crosses there.
  const SceneBox& box = boxes_[best_box];
  const Eigen::Array3d t_min = (box.min.array() - start) * inverse;
  const Eigen::Array3d t_max = (box.max.array() - start) * inverse;
  int axis = 0;
  if (box.enclosure) {
    t_min.max(t_max).minCoeff(&axis);
  } else {
    t_min.min(t_max).maxCoeff(&axis);
  }
  // Entering through the min side (or leaving an enclosure through the max
  // side) happens when the ray goes toward +axis.
  const bool positive = safe_direction(axis) > 0;
  const bool max_side = box.enclosure ? positive : !positive;
  hit->distance = best;
  hit->point = origin + best * direction;
  hit->face = best_box * 6 + axis * 2 + (max_side ? 1 : 0);
  hit->normal = Eigen::Vector3d::Zero();
  // Against the ray: outward for solid boxes, inward for enclosures.
  hit->normal(axis) = positive ? -1.0 : 1.0;
  return true;
}

double TexturedScene::Radiance(const SceneHit& hit, double footprint) const {
  const int axis = (hit.face % 6) / 2;
  const Eigen::Vector2d uv =
      axis == 0   ? Eigen::Vector2d(hit.point.y(), hit.point.z())
      : axis == 1 ? Eigen::Vector2d(hit.point.x(), hit.point.z())
                  : Eigen::Vector2d(hit.point.x(), hit.point.y());
  const uint64_t face_seed = FaceSeed(seed_, hit.face);
  // Lambertian term of a light from above and the side, mild: 0.6 ... 1.
  static const Eigen::Vector3d kLight =
      Eigen::Vector3d(0.4, 0.3, 0.85).normalized();
  const double shading = 0.8 + 0.2 * hit.normal.dot(kLight);
  // Per-face brightness so neighbouring faces differ.
  const double brightness = 0.85 + 0.15 * ToUnit(Mix(face_seed));
  return Clamp01(shading * brightness * TextureValue(face_seed, uv, footprint));
}

double TexturedScene::SkyRadiance(const Eigen::Vector3d& direction) const {
  return 0.8 + 0.15 * std::max(0.0, direction.z());
}

Eigen::Vector3d TexturedScene::FaceTint(int face) const {
  CellRandom random(Mix(FaceSeed(seed_, face) + 7));
  Eigen::Vector3d tint(random.Uniform(0.75, 1.0), random.Uniform(0.75, 1.0),
                       random.Uniform(0.75, 1.0));
  // Rec. 601 luminance 1, so the grey level of a colored rendering (as
  // COLMAP's reader computes it) is the texture's.
  return tint / (0.299 * tint(0) + 0.587 * tint(1) + 0.114 * tint(2));
}

bool TexturedScene::IsFree(const Eigen::Vector3d& point, double margin) const {
  for (const SceneBox& box : boxes_) {
    if (box.enclosure) {
      if (((point - box.min).array() < margin).any() ||
          ((box.max - point).array() < margin).any()) {
        return false;
      }
    } else {
      const Eigen::Vector3d outside = (box.min - point)
                                          .cwiseMax(point - box.max)
                                          .cwiseMax(Eigen::Vector3d::Zero());
      if (outside.norm() < margin) return false;
    }
  }
  return true;
}

}  // namespace rig_calibrator
