// Renders images of a TexturedScene through COLMAP's camera models, by
// inverse mapping: a pixel's center (COLMAP convention, the center of the
// top-left pixel is (0.5, 0.5)) is turned into a ray with
// colmap::Camera::ImageToWorld and cast into the scene; plus mild Gaussian
// noise. The texture is low-pass filtered to the footprint of the pixel
// (distance times the angle between neighbouring pixel rays, enlarged at
// grazing incidence), which antialiases it, and views at different distances
// agree. Pixels where the surface changes (silhouettes, face boundaries, the
// sky line: a 4-neighbour's center ray hits another face) are supersampled
// instead: the average of s x s samples, each filtered to its own footprint.
//
// Samples whose rays the camera model cannot produce (ImageToWorld does not
// invert WorldToImage there, e.g. fisheye rays at or beyond 90 degrees, which
// a COLMAP 3.8 model cannot represent) are black.
#pragma once

#include <colmap/base/camera.h>
#include <colmap/util/bitmap.h>

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "src/geometry/rigid3d.h"
#include "src/synthetic/textured_scene.h"

namespace rig_calibrator {

struct RenderOptions {
  // Samples per pixel along each axis where the surface changes (2: 2 x 2).
  int supersampling = 2;
  // Standard deviation of the Gaussian pixel noise, in grey levels (0-255).
  double noise_stddev = 1.5;
  // RGB (faces tinted, grey level unchanged) or 8-bit grey.
  bool as_rgb = true;

  // False (with a message) for values outside their ranges.
  bool Check(std::string* error) const;
};

// The camera-frame unit rays of every sample of every pixel of a camera,
// computed once per camera (the costly, iterative part of inverse mapping)
// and reused for all its images.
class CameraRays {
 public:
  CameraRays(const colmap::Camera& camera, int supersampling);

  int width() const { return width_; }
  int height() const { return height_; }
  int supersampling() const { return supersampling_; }
  int NumSamples() const { return supersampling_ * supersampling_; }

  // The ray through the center of pixel (x, y); the zero vector where the
  // camera has no ray.
  const Eigen::Vector3f& CenterRay(int x, int y) const {
    return center_rays_[static_cast<size_t>(y) * width_ + x];
  }
  // Sample s (row-major over the s x s sub-grid) of pixel (x, y); the zero
  // vector where the camera has no ray.
  const Eigen::Vector3f& Ray(int x, int y, int s) const {
    return rays_[(static_cast<size_t>(y) * width_ + x) * NumSamples() + s];
  }
  // Angle in radians between the rays of neighbouring pixels at (x, y), the
  // larger of the horizontal and vertical one.
  float PixelAngle(int x, int y) const {
    return pixel_angles_[static_cast<size_t>(y) * width_ + x];
  }
  // True if a sample or the center of pixel (x, y) has no ray.
  bool IsMasked(int x, int y) const {
    return masked_[static_cast<size_t>(y) * width_ + x] != 0;
  }
  int NumMaskedPixels() const { return num_masked_pixels_; }

 private:
  int width_ = 0;
  int height_ = 0;
  int supersampling_ = 1;
  std::vector<Eigen::Vector3f> center_rays_;
  std::vector<Eigen::Vector3f> rays_;
  std::vector<float> pixel_angles_;
  std::vector<char> masked_;
  int num_masked_pixels_ = 0;
};

// Renders the scene seen by a camera at cam_from_world. `noise_seed` seeds
// the pixel noise (deterministic; rows are rendered in parallel with OpenMP).
// With invalid options, logs the error and returns an empty bitmap.
colmap::Bitmap RenderImage(const TexturedScene& scene, const CameraRays& rays,
                           const Rigid3d& cam_from_world,
                           const RenderOptions& options, uint64_t noise_seed);

// The same with a pose per image row (a rolling shutter, or a global one
// with every row's pose the same): every pixel of row r (its centre ray,
// its samples) is cast from cam_from_world_per_row[r], e.g. the poses of
// CamFromWorldPerRow (capture_model.h). Logs an error and returns an empty
// bitmap unless there is one pose per row.
colmap::Bitmap RenderImage(const TexturedScene& scene, const CameraRays& rays,
                           const std::vector<Rigid3d>& cam_from_world_per_row,
                           const RenderOptions& options, uint64_t noise_seed);

// The same, computing the camera's rays first.
colmap::Bitmap RenderImage(const TexturedScene& scene,
                           const colmap::Camera& camera,
                           const Rigid3d& cam_from_world,
                           const RenderOptions& options, uint64_t noise_seed);

}  // namespace rig_calibrator
