#include "src/synthetic/scene_renderer.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>

#include "src/geometry/rigid3d.h"
#include "src/synthetic/hash_random.h"

namespace rig_calibrator {
namespace {

// A round trip through ImageToWorld and WorldToImage that misses the pixel by
// more than this means the model has no ray there.
constexpr double kMaxRoundTripErrorPx = 1e-3;

// The camera-frame unit ray through an image point, or false.
bool UnitRay(const colmap::Camera& camera, const Eigen::Vector2d& image_point,
             Eigen::Vector3d* ray) {
  const Eigen::Vector2d normalized = camera.ImageToWorld(image_point);
  if (!normalized.allFinite()) return false;
  const Eigen::Vector2d reprojected = camera.WorldToImage(normalized);
  if (!reprojected.allFinite() ||
      (reprojected - image_point).norm() > kMaxRoundTripErrorPx) {
    return false;
  }
  *ray = normalized.homogeneous().normalized();
  return true;
}

// A standard normal number determined by (seed, x, y, channel): Box-Muller
// on two hashed uniforms, so the noise does not depend on thread scheduling.
double GaussianNoise(uint64_t seed, int x, int y, int channel) {
  const uint64_t h1 = Mix(seed ^ Mix((static_cast<uint64_t>(y) << 32) ^
                                     (static_cast<uint64_t>(x) << 2) ^
                                     static_cast<uint64_t>(channel)));
  const uint64_t h2 = Mix(h1);
  const double u1 = (static_cast<double>(h1 >> 11) + 1.0) * 0x1.0p-53;
  const double u2 = ToUnit(h2);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

// A row's camera pose in the form the ray casting uses.
struct RowPose {
  Eigen::Matrix3d world_from_cam_rotation;
  Eigen::Vector3d center;
};

// Face index of the hit of each pixel's center ray (row-major), kSky for
// rays that hit nothing, kNoRay for pixels without a ray; the hits in *hits.
constexpr int kNoRay = -2;
constexpr int kSky = -1;

std::vector<int> IntersectCenterRays(const TexturedScene& scene,
                                     const CameraRays& rays,
                                     const std::vector<RowPose>& row_poses,
                                     std::vector<SceneHit>* hits) {
  const int width = rays.width();
  const int height = rays.height();
  const size_t num_pixels = static_cast<size_t>(width) * height;
  hits->assign(num_pixels, SceneHit());
  std::vector<int> faces(num_pixels, kNoRay);
#pragma omp parallel for schedule(dynamic)
  for (int y = 0; y < height; ++y) {
    const RowPose& pose = row_poses[y];
    for (int x = 0; x < width; ++x) {
      const size_t pixel = static_cast<size_t>(y) * width + x;
      const Eigen::Vector3f& camera_ray = rays.CenterRay(x, y);
      if (camera_ray.isZero()) continue;
      const Eigen::Vector3d direction =
          pose.world_from_cam_rotation * camera_ray.cast<double>();
      faces[pixel] = scene.Intersect(pose.center, direction, &(*hits)[pixel])
                         ? (*hits)[pixel].face
                         : kSky;
    }
  }
  return faces;
}

// A bitmap from row-major 8-bit pixels, 3 channels for RGB, 1 for grey.
colmap::Bitmap ToBitmap(const std::vector<uint8_t>& pixels, int width,
                        int height, bool as_rgb) {
  const int channels = as_rgb ? 3 : 1;
  colmap::Bitmap bitmap;
  bitmap.Allocate(width, height, as_rgb);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const uint8_t* p =
          &pixels[(static_cast<size_t>(y) * width + x) * channels];
      bitmap.SetPixel(x, y,
                      as_rgb ? colmap::BitmapColor<uint8_t>(p[0], p[1], p[2])
                             : colmap::BitmapColor<uint8_t>(p[0]));
    }
  }
  return bitmap;
}

}  // namespace

bool RenderOptions::Check(std::string* error) const {
  if (supersampling < 1 || supersampling > 8) {
    *error = "supersampling must be in [1, 8]";
    return false;
  }
  if (!(noise_stddev >= 0 && noise_stddev <= 50)) {
    *error = "noise_stddev must be in [0, 50] grey levels";
    return false;
  }
  return true;
}

CameraRays::CameraRays(const colmap::Camera& camera, int supersampling)
    : width_(static_cast<int>(camera.Width())),
      height_(static_cast<int>(camera.Height())),
      supersampling_(std::max(1, supersampling)) {
  const int num_samples = NumSamples();
  const size_t num_pixels = static_cast<size_t>(width_) * height_;
  center_rays_.assign(num_pixels, Eigen::Vector3f::Zero());
  rays_.assign(num_pixels * num_samples, Eigen::Vector3f::Zero());
  pixel_angles_.assign(num_pixels, 0.0f);
  masked_.assign(num_pixels, 0);
  // The center rays in double precision, for the angles between neighbours.
  std::vector<Eigen::Vector3d> center_rays(num_pixels, Eigen::Vector3d::Zero());
  int num_masked = 0;
#pragma omp parallel for schedule(dynamic) reduction(+ : num_masked)
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      const size_t pixel = static_cast<size_t>(y) * width_ + x;
      Eigen::Vector3d ray;
      bool masked = false;
      if (UnitRay(camera, Eigen::Vector2d(x + 0.5, y + 0.5), &ray)) {
        center_rays[pixel] = ray;
        center_rays_[pixel] = ray.cast<float>();
      } else {
        masked = true;
      }
      // With an odd number of samples per axis the middle sample is the
      // center, already computed.
      const int middle = supersampling_ % 2 == 1 ? supersampling_ / 2 : -1;
      for (int sy = 0; sy < supersampling_; ++sy) {
        for (int sx = 0; sx < supersampling_; ++sx) {
          const Eigen::Vector2d sample(x + (sx + 0.5) / supersampling_,
                                       y + (sy + 0.5) / supersampling_);
          if (sx == middle && sy == middle) {
            rays_[pixel * num_samples + sy * supersampling_ + sx] =
                center_rays_[pixel];
          } else if (UnitRay(camera, sample, &ray)) {
            rays_[pixel * num_samples + sy * supersampling_ + sx] =
                ray.cast<float>();
          } else {
            masked = true;
          }
        }
      }
      masked_[pixel] = masked;
      if (masked) ++num_masked;
    }
  }
  num_masked_pixels_ = num_masked;
  // Central differences where both neighbours have a ray, one-sided at
  // borders and next to masked pixels.
  auto neighbour_angle = [&](int x, int y, int dx, int dy) {
    const size_t pixel = static_cast<size_t>(y) * width_ + x;
    double angle = 0;
    int count = 0;
    for (const int sign : {-1, 1}) {
      const int nx = x + sign * dx;
      const int ny = y + sign * dy;
      if (nx < 0 || ny < 0 || nx >= width_ || ny >= height_) continue;
      const size_t neighbour = static_cast<size_t>(ny) * width_ + nx;
      if (center_rays_[neighbour].isZero()) continue;
      angle += AngleBetweenRad(center_rays[pixel], center_rays[neighbour]);
      ++count;
    }
    return count > 0 ? angle / count : 0.0;
  };
#pragma omp parallel for schedule(static)
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      const size_t pixel = static_cast<size_t>(y) * width_ + x;
      if (center_rays_[pixel].isZero()) continue;
      pixel_angles_[pixel] = static_cast<float>(
          std::max(neighbour_angle(x, y, 1, 0), neighbour_angle(x, y, 0, 1)));
    }
  }
}

colmap::Bitmap RenderImage(const TexturedScene& scene, const CameraRays& rays,
                           const std::vector<Rigid3d>& cam_from_world_per_row,
                           const RenderOptions& options, uint64_t noise_seed) {
  colmap::Bitmap bitmap;
  std::string error;
  if (!options.Check(&error)) {
    LOG(ERROR) << "Invalid render options: " << error;
    return bitmap;
  }
  if (rays.width() <= 0 || rays.height() <= 0) {
    LOG(ERROR) << "Cannot render an image of size " << rays.width() << "x"
               << rays.height();
    return bitmap;
  }
  const int width = rays.width();
  const int height = rays.height();
  if (static_cast<int>(cam_from_world_per_row.size()) != height) {
    LOG(ERROR) << "Cannot render " << height << " rows with "
               << cam_from_world_per_row.size() << " row poses";
    return bitmap;
  }
  const int channels = options.as_rgb ? 3 : 1;
  const int num_samples = rays.NumSamples();
  std::vector<RowPose> row_poses(height);
  for (int y = 0; y < height; ++y) {
    row_poses[y].world_from_cam_rotation =
        cam_from_world_per_row[y].RotationMatrix().transpose();
    row_poses[y].center = cam_from_world_per_row[y].Center();
  }
  // Grazing incidence stretches the footprint by 1 / cos; the cap keeps
  // far, grazing floors from blurring to a flat grey.
  constexpr double kMinCosine = 0.2;

  // The color seen along a camera-frame ray whose pixel spans `ray_angle`.
  auto shade = [&](const Eigen::Vector3d& direction, const SceneHit* hit,
                   double ray_angle) -> Eigen::Vector3d {
    if (hit == nullptr) {
      return Eigen::Vector3d::Constant(scene.SkyRadiance(direction));
    }
    const double cosine =
        std::max(kMinCosine, std::abs(hit->normal.dot(direction)));
    const double radiance =
        scene.Radiance(*hit, hit->distance * ray_angle / cosine);
    return options.as_rgb
               ? Eigen::Vector3d(radiance * scene.FaceTint(hit->face))
               : Eigen::Vector3d::Constant(radiance);
  };

  // Pass 1: what the center ray of every pixel hits.
  const size_t num_pixels = static_cast<size_t>(width) * height;
  std::vector<SceneHit> center_hits;
  const std::vector<int> center_faces =
      IntersectCenterRays(scene, rays, row_poses, &center_hits);

  // Pass 2: one pre-filtered sample inside a face, supersampling where the
  // surface changes.
  std::vector<uint8_t> pixels(num_pixels * channels);
#pragma omp parallel for schedule(dynamic)
  for (int y = 0; y < height; ++y) {
    const Eigen::Matrix3d& world_from_cam_rotation =
        row_poses[y].world_from_cam_rotation;
    const Eigen::Vector3d& center = row_poses[y].center;
    for (int x = 0; x < width; ++x) {
      const size_t pixel = static_cast<size_t>(y) * width + x;
      const int face = center_faces[pixel];
      bool uniform = face != kNoRay && !rays.IsMasked(x, y);
      if (x > 0) uniform &= center_faces[pixel - 1] == face;
      if (x + 1 < width) uniform &= center_faces[pixel + 1] == face;
      if (y > 0) uniform &= center_faces[pixel - width] == face;
      if (y + 1 < height) uniform &= center_faces[pixel + width] == face;
      const double pixel_angle = rays.PixelAngle(x, y);
      Eigen::Vector3d color = Eigen::Vector3d::Zero();
      if (uniform) {
        const Eigen::Vector3d direction =
            world_from_cam_rotation * rays.CenterRay(x, y).cast<double>();
        color = shade(direction, face == kSky ? nullptr : &center_hits[pixel],
                      pixel_angle);
      } else {
        // A sample covers 1 / supersampling of the pixel along each axis.
        const double sample_angle = pixel_angle / rays.supersampling();
        for (int s = 0; s < num_samples; ++s) {
          const Eigen::Vector3f& camera_ray = rays.Ray(x, y, s);
          if (camera_ray.isZero()) continue;  // black: no ray
          const Eigen::Vector3d direction =
              world_from_cam_rotation * camera_ray.cast<double>();
          SceneHit hit;
          const bool hits = scene.Intersect(center, direction, &hit);
          color += shade(direction, hits ? &hit : nullptr, sample_angle);
        }
        color /= num_samples;
      }
      for (int c = 0; c < channels; ++c) {
        const double value =
            255.0 * color(c) +
            options.noise_stddev * GaussianNoise(noise_seed, x, y, c);
        pixels[pixel * channels + c] = static_cast<uint8_t>(
            std::lround(std::min(255.0, std::max(0.0, value))));
      }
    }
  }

  return ToBitmap(pixels, width, height, options.as_rgb);
}

colmap::Bitmap RenderImage(const TexturedScene& scene, const CameraRays& rays,
                           const Rigid3d& cam_from_world,
                           const RenderOptions& options, uint64_t noise_seed) {
  return RenderImage(
      scene, rays,
      std::vector<Rigid3d>(std::max(0, rays.height()), cam_from_world),
      options, noise_seed);
}

colmap::Bitmap RenderImage(const TexturedScene& scene,
                           const colmap::Camera& camera,
                           const Rigid3d& cam_from_world,
                           const RenderOptions& options, uint64_t noise_seed) {
  return RenderImage(scene, CameraRays(camera, options.supersampling),
                     cam_from_world, options, noise_seed);
}

}  // namespace rig_calibrator
