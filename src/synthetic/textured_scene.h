// Procedural 3D scenes made of axis-aligned boxes with a rich, non-repeating
// texture, for rendering images on which SIFT finds many distinctive features
// (the rendered rig datasets with exact ground truth).
//
// Geometry: every surface is a face of an axis-aligned box. A solid box is
// seen from outside; the enclosure of a room is seen from inside. Rays that hit
// nothing see a featureless sky.
//
// Texture: a grey level defined in scene coordinates (the face's two in-plane
// world coordinates), so every view of a surface sees the same texture. It sums
// multi-octave gradient noise, random discs, rectangles and line segments at
// several scales (1 cm to 2 m), each seeded per face, so no two places look
// alike. It is low-pass filtered to the footprint of the pixel (octaves and
// shapes smaller than the footprint fade to their mean), so distant and
// grazing surfaces do not alias. Shading: a constant Lambertian factor per
// face from a fixed light direction.
//
// Frames: the world is z-up, metric. Everything is deterministic for a seed.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace rig_calibrator {

enum class SceneType { kRoom, kCourtyard, kStreet };

// Parses/prints "room", "courtyard", "street".
bool SceneTypeFromName(const std::string& name, SceneType* type);
std::string SceneTypeName(SceneType type);
std::vector<SceneType> AllSceneTypes();

struct SceneBox {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
  // True for the enclosure of a room: its faces are seen from inside.
  bool enclosure = false;
};

// Where cameras can walk: an ellipse in the horizontal plane, free of boxes
// with a margin, around which the scene has texture in every direction.
struct SceneWalk {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  Eigen::Vector2d radii = Eigen::Vector2d::Ones();  // along x and y
  double eye_height = 1.5;                          // meters above z = 0
};

struct SceneHit {
  double distance = 0;  // along the (unit) ray
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // facing the ray origin
  int face = -1;  // box index * 6 + axis * 2 + (0: min side, 1: max side)
};

class TexturedScene {
 public:
  // An empty scene (everything is sky).
  TexturedScene() = default;
  TexturedScene(std::vector<SceneBox> boxes, const SceneWalk& walk,
                unsigned int seed);

  // The preset scenes:
  //  room: an 8 x 6 x 3 m room with a pillar, cabinets, a table and crates.
  //  courtyard: a 26 x 24 m courtyard between building wings 9-14 m high with
  //    setbacks, a fountain, kiosks and posts.
  //  street: a 70 m street canyon, facades 6-8 m from its axis at varying
  //    depths and heights (8-20 m), parked cars, lamp posts, closed at both
  //    ends.
  static TexturedScene Make(SceneType type, unsigned int seed);

  // The nearest surface hit by origin + t * direction, t > 0, for a unit
  // direction; false for the sky.
  bool Intersect(const Eigen::Vector3d& origin,
                 const Eigen::Vector3d& direction, SceneHit* hit) const;

  // Shaded grey level in [0, 1] at a hit, low-pass filtered to `footprint`
  // (the size of the surface area that one sample covers, in meters).
  double Radiance(const SceneHit& hit, double footprint) const;

  // Grey level of the sky in a direction (a smooth, featureless gradient).
  double SkyRadiance(const Eigen::Vector3d& direction) const;

  // The RGB tint of a face (luminance 1), for colored renderings.
  Eigen::Vector3d FaceTint(int face) const;

  // True if `point` is at least `margin` away from every solid box and inside
  // every enclosure by `margin`: a valid camera position.
  bool IsFree(const Eigen::Vector3d& point, double margin) const;

  const std::vector<SceneBox>& boxes() const { return boxes_; }
  const SceneWalk& walk() const { return walk_; }
  unsigned int seed() const { return seed_; }

 private:
  std::vector<SceneBox> boxes_;
  SceneWalk walk_;
  unsigned int seed_ = 0;
};

}  // namespace rig_calibrator
