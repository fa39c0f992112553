#include "src/synthetic/synthetic_rig.h"

#include <colmap/base/camera_models.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <unordered_set>
#include <utility>

#include "src/synthetic/capture_model.h"
#include "src/synthetic/correspondence_generator.h"
#include "src/synthetic/rig_motion.h"
#include "src/synthetic/rig_presets.h"
#include "src/synthetic/synthetic_map.h"

namespace rig_calibrator {
namespace {

// Which (frameset, camera) images exist: round(ratio * total) images are
// dropped at random, skipping drops that would empty a frameset.
std::vector<std::vector<char>> ChooseExistingImages(int num_framesets,
                                                    int num_cameras,
                                                    double missing_ratio,
                                                    std::mt19937* rng) {
  std::vector<std::vector<char>> exists(num_framesets,
                                        std::vector<char>(num_cameras, 1));
  std::vector<std::pair<int, int>> images;
  for (int j = 0; j < num_framesets; ++j) {
    for (int c = 0; c < num_cameras; ++c) {
      images.emplace_back(j, c);
    }
  }
  std::shuffle(images.begin(), images.end(), *rng);
  const int num_to_drop =
      static_cast<int>(std::lround(missing_ratio * images.size()));
  std::vector<int> remaining(num_framesets, num_cameras);
  int num_dropped = 0;
  for (const auto& [frameset, camera] : images) {
    if (num_dropped == num_to_drop) {
      break;
    }
    if (remaining[frameset] > 1) {
      exists[frameset][camera] = 0;
      --remaining[frameset];
      ++num_dropped;
    }
  }
  return exists;
}

// The dataset cameras: the true model and size, COLMAP's initial parameters.
std::vector<RigCamera> InitialCameras(const RigGroundTruth& truth) {
  std::vector<RigCamera> cameras;
  for (size_t c = 0; c < truth.cameras.size(); ++c) {
    const colmap::Camera& true_camera = truth.cameras[c];
    RigCamera camera;
    camera.name = truth.camera_names[c];
    camera.camera = true_camera;
    camera.camera.SetParams(colmap::CameraModelInitializeParams(
        true_camera.ModelId(),
        1.2 * std::max(true_camera.Width(), true_camera.Height()),
        true_camera.Width(), true_camera.Height()));
    cameras.push_back(camera);
  }
  return cameras;
}

// The generator's view of image (frameset j, camera c), with its feature
// window drawn from *rng for partial windows. With a time model the image is
// taken at t_j + delta_c (its top row), its rows at their own poses with a
// rolling shutter.
ImageContext MakeImageContext(const SyntheticRigOptions& options,
                              const RigGroundTruth& truth, int j, int c,
                              std::mt19937* rng) {
  ImageContext context;
  context.camera = &truth.cameras[c];
  if (truth.trajectory) {
    const ImageCapture capture = CaptureOfImage(truth, c, j);
    context.pose = CameraPose(capture.CamFromWorldAt(capture.top_row_time_s));
    if (capture.line_delay_s > 0) context.rolling_shutter = capture;
  } else {
    context.pose = CameraPose(truth.cam_from_rig[c] * truth.rig_from_world[j]);
  }
  const Eigen::Vector2d size(context.camera->Width(), context.camera->Height());
  context.window_max = size;
  if (options.feature_window < 1) {
    // Drawn only for partial windows, so that whole-image datasets stay
    // those of earlier versions for the same seed.
    const Eigen::Vector2d window = options.feature_window * size;
    std::uniform_real_distribution<double> unit(0, 1);
    context.window_min.x() = unit(*rng) * (size.x() - window.x());
    context.window_min.y() = unit(*rng) * (size.y() - window.y());
    context.window_max = context.window_min + window;
  }
  return context;
}

// The correspondences of one image: num_track_points re-observed map points
// (as far as visible), new points up to points_per_image, the last
// num_outliers of them matched to wrong map points; then shuffled, with
// pixel noise. Appends the image and its outlier flags to *rig.
void GenerateImage(const SyntheticRigOptions& options,
                   const ImageContext& context, int j, int c,
                   int num_track_points, int num_outliers,
                   PointGenerator* generator, std::mt19937* rng,
                   SyntheticRig* rig) {
  std::vector<int64_t> ids;
  std::vector<Eigen::Vector2d> xys;
  generator->TrackPoints(context, j, num_track_points, &ids, &xys);
  while (static_cast<int>(ids.size()) < options.points_per_image) {
    int64_t id = -1;
    Eigen::Vector2d xy;
    if (!generator->NewVisiblePoint(context, j, &id, &xy)) {
      break;
    }
    ids.push_back(id);
    xys.push_back(xy);
  }
  if (static_cast<int>(ids.size()) < options.points_per_image) {
    LOG(WARNING) << "Image " << c << "/" << j << " got only " << ids.size()
                 << " of " << options.points_per_image << " points";
  }

  // The last num_outliers correspondences keep their 2D point but are
  // matched to a wrong map point; the order is shuffled afterwards.
  std::unordered_set<int64_t> observed(ids.begin(), ids.end());
  std::vector<char> is_outlier(ids.size(), 0);
  for (size_t k = std::max<int>(0, static_cast<int>(ids.size()) - num_outliers);
       k < ids.size(); ++k) {
    int64_t wrong_id = -1;
    if (generator->WrongPoint(context, j, xys[k], observed, &wrong_id)) {
      ids[k] = wrong_id;
      observed.insert(wrong_id);
      is_outlier[k] = 1;
    }
  }
  std::vector<int> order(ids.size());
  for (size_t k = 0; k < order.size(); ++k) {
    order[k] = k;
  }
  std::shuffle(order.begin(), order.end(), *rng);

  RigImage image;
  image.name = rig->truth.camera_names[c] + "/" + FramesetName(j) + ".png";
  image.camera_index = c;
  image.frameset_index = j;
  std::vector<char> shuffled_is_outlier;
  for (const int k : order) {
    Correspondence correspondence;
    correspondence.point2D =
        AddPixelNoise(*context.camera, xys[k], options.noise_px, rng);
    correspondence.point3D = generator->Point(ids[k]);
    correspondence.point3D_id = ids[k];
    image.correspondences.push_back(correspondence);
    shuffled_is_outlier.push_back(is_outlier[k]);
  }
  rig->dataset.images.push_back(std::move(image));
  rig->is_outlier.push_back(std::move(shuffled_is_outlier));
}

// The time model of options.frameset_rate_hz > 0: the continuous
// trajectory (its phases drawn from *rng, as the per-frameset trajectory's),
// the frameset times and rig poses, and each camera's time offset and line
// delay (DrawCaptureTimes).
void AddTimeModel(const SyntheticRigOptions& options,
                  const MotionProfile& motion, const Rigid3d& body_from_rig,
                  std::mt19937* rng, RigGroundTruth* truth) {
  truth->trajectory.emplace(TimeModelMotion(options, motion), options.speed_m_s,
                            options.max_turn_rate_deg_s, options.rotation_only,
                            rng);
  truth->body_from_rig = body_from_rig;
  for (int f = 0; f < options.num_framesets; ++f) {
    const double time_s = f / options.frameset_rate_hz;
    truth->frameset_times_s.push_back(time_s);
    truth->rig_from_world.push_back(RigFromWorldAtTime(*truth, time_s));
  }
  DrawCaptureTimes(options, truth);
}

// Changes the map's unit (SyntheticRigOptions::map_scale): x' = s x for
// every 3D point and translation; rotations and pixels stay.
void ScaleMap(double scale, SyntheticRig* rig) {
  for (RigImage& image : rig->dataset.images) {
    for (Correspondence& correspondence : image.correspondences) {
      correspondence.point3D *= scale;
    }
  }
  for (Rigid3d& pose : rig->truth.rig_from_world) pose.translation *= scale;
  for (Rigid3d& pose : rig->truth.cam_from_rig) pose.translation *= scale;
  if (rig->truth.trajectory) {
    rig->truth.trajectory->ScalePositions(scale);
    rig->truth.body_from_rig.translation *= scale;
  }
  for (MapImage& image : rig->dataset.map_images) {
    image.cam_from_world.translation *= scale;
  }
  for (auto& [point3D_id, point3D] : rig->dataset.map_points3D) {
    point3D *= scale;
  }
  for (Eigen::Vector3d& point3D : rig->true_points3D) point3D *= scale;
  for (Rigid3d& pose : rig->true_map_cam_from_world) {
    pose.translation *= scale;
  }
}

// The preset's definition with the options' variants (ring size, stereo
// copies).
PresetDefinition DefinitionOf(const SyntheticRigOptions& options) {
  PresetDefinition definition =
      MakePresetDefinition(options.preset, options.ring_num_cameras);
  if (options.stereo_num_pairs > 1 || options.stereo_alternate_facing) {
    ReplicateStereoPair(options.stereo_num_pairs,
                        options.stereo_alternate_facing, &definition);
  }
  if (options.image_height > 0) {
    for (CameraSpec& spec : definition.cameras) {
      colmap::Camera camera;
      camera.SetModelIdFromName(spec.model_name);
      camera.SetWidth(spec.width);
      camera.SetHeight(spec.height);
      camera.SetParams(spec.params);
      camera.Rescale(static_cast<double>(options.image_height) / spec.height);
      spec.width = static_cast<int>(camera.Width());
      spec.height = static_cast<int>(camera.Height());
      spec.params = camera.Params();
    }
  }
  return definition;
}

// The time-model part of SyntheticRigOptions::Check, for options whose other
// values are valid (the preset's cameras are known).
bool CheckTimeModel(const SyntheticRigOptions& options,
                    std::ostringstream* message) {
  const SyntheticRigOptions defaults;
  const double rate = options.frameset_rate_hz;
  if (!(rate >= 0 && std::isfinite(rate))) {
    *message << "frameset_rate_hz must be >= 0 and finite, got " << rate;
    return false;
  }
  if (!(options.speed_m_s > 0 && std::isfinite(options.speed_m_s)) ||
      !(options.max_turn_rate_deg_s > 0 &&
        std::isfinite(options.max_turn_rate_deg_s))) {
    *message << "speed_m_s and max_turn_rate_deg_s must be positive numbers, "
                "got "
             << options.speed_m_s << ", " << options.max_turn_rate_deg_s;
    return false;
  }
  if (!(options.bob_hz >= 0 && std::isfinite(options.bob_hz))) {
    *message << "bob_hz must be >= 0 and finite, got " << options.bob_hz;
    return false;
  }
  if (!(options.max_time_offset_s >= 0 &&
        std::isfinite(options.max_time_offset_s))) {
    *message << "max_time_offset_s must be >= 0 and finite, got "
             << options.max_time_offset_s;
    return false;
  }
  if (!(options.min_line_delay_s >= 0 &&
        options.max_line_delay_s >= options.min_line_delay_s &&
        std::isfinite(options.max_line_delay_s))) {
    *message << "need 0 <= min_line_delay_s <= max_line_delay_s (finite), got "
             << options.min_line_delay_s << ", " << options.max_line_delay_s;
    return false;
  }
  if (rate == 0 &&
      (options.speed_m_s != defaults.speed_m_s ||
       options.max_turn_rate_deg_s != defaults.max_turn_rate_deg_s ||
       options.bob_hz != defaults.bob_hz || options.max_time_offset_s > 0 ||
       !options.time_offsets_s.empty() || options.max_line_delay_s > 0 ||
       !options.line_delays_s.empty())) {
    *message << "speed_m_s, max_turn_rate_deg_s, bob_hz, time offsets and "
                "line delays need the time model, frameset_rate_hz > 0";
    return false;
  }
  const std::vector<CameraSpec> cameras = DefinitionOf(options).cameras;
  const size_t num_cameras = cameras.size();
  if (!options.time_offsets_s.empty()) {
    if (options.max_time_offset_s > 0 ||
        options.time_offsets_s.size() != num_cameras ||
        options.time_offsets_s[0] != 0 ||
        !std::all_of(options.time_offsets_s.begin(),
                     options.time_offsets_s.end(),
                     [](double offset) { return std::isfinite(offset); })) {
      *message << "time_offsets_s needs one finite offset per camera ("
               << num_cameras << "), the reference camera's 0, and no "
               << "max_time_offset_s; got " << options.time_offsets_s.size()
               << " offsets";
      return false;
    }
  }
  if (!options.line_delays_s.empty()) {
    if (options.max_line_delay_s > 0 ||
        options.line_delays_s.size() != num_cameras ||
        !std::all_of(options.line_delays_s.begin(),
                     options.line_delays_s.end(), [](double delay) {
                       return delay >= 0 && std::isfinite(delay);
                     })) {
      *message << "line_delays_s needs one finite delay >= 0 per camera ("
               << num_cameras << ") and no min/max_line_delay_s; got "
               << options.line_delays_s.size() << " delays";
      return false;
    }
  }
  // A camera reads its whole image out within one frameset period.
  for (size_t c = 0; c < num_cameras && rate > 0; ++c) {
    const double line_delay = options.line_delays_s.empty()
                                  ? options.max_line_delay_s
                                  : options.line_delays_s[c];
    if (line_delay * cameras[c].height > 1 / rate) {
      *message << "the readout of camera cam" << c << " (line delay "
               << line_delay << " s x " << cameras[c].height
               << " rows) is longer than the frameset period " << 1 / rate
               << " s (frameset_rate_hz " << rate << ")";
      return false;
    }
  }
  return true;
}

}  // namespace

void DrawCaptureTimes(const SyntheticRigOptions& options,
                      RigGroundTruth* truth) {
  const int num_cameras = truth->cameras.size();
  std::mt19937 time_rng(options.seed + 4);
  std::uniform_real_distribution<double> offset(-options.max_time_offset_s,
                                                options.max_time_offset_s);
  std::uniform_real_distribution<double> line_delay(options.min_line_delay_s,
                                                    options.max_line_delay_s);
  truth->time_offsets_s = options.time_offsets_s;
  if (truth->time_offsets_s.empty()) {
    for (int c = 0; c < num_cameras; ++c) {
      truth->time_offsets_s.push_back(c == 0 ? 0.0 : offset(time_rng));
    }
  }
  truth->line_delays_s = options.line_delays_s;
  if (truth->line_delays_s.empty()) {
    for (int c = 0; c < num_cameras; ++c) {
      truth->line_delays_s.push_back(line_delay(time_rng));
    }
  }
}

MotionProfile TimeModelMotion(const SyntheticRigOptions& options,
                              MotionProfile motion) {
  if (options.bob_hz > 0) motion.bob_period_s = 1 / options.bob_hz;
  return motion;
}

std::string FramesetName(int frameset) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d", frameset);
  return name;
}

bool SyntheticRigOptions::Check(std::string* error) const {
  std::ostringstream message;
  if (num_framesets < 1) {
    message << "num_framesets must be >= 1, got " << num_framesets;
  } else if (points_per_image < 0) {
    message << "points_per_image must be >= 0, got " << points_per_image;
  } else if (!(noise_px >= 0)) {
    message << "noise_px must be >= 0, got " << noise_px;
  } else if (!(outlier_ratio >= 0 && outlier_ratio <= 1)) {
    message << "outlier_ratio must be in [0, 1], got " << outlier_ratio;
  } else if (!(missing_image_ratio >= 0 && missing_image_ratio < 1)) {
    message << "missing_image_ratio must be in [0, 1), got "
            << missing_image_ratio;
  } else if (!(min_depth > 0 && max_depth >= min_depth)) {
    message << "need 0 < min_depth <= max_depth, got " << min_depth << ", "
            << max_depth;
  } else if (!(near_planar_ratio >= 0 && near_planar_ratio <= 1)) {
    message << "near_planar_ratio must be in [0, 1], got " << near_planar_ratio;
  } else if (!(track_ratio >= 0 && track_ratio <= 1)) {
    message << "track_ratio must be in [0, 1], got " << track_ratio;
  } else if (ring_num_cameras != 0 &&
             (preset != RigPreset::kRing5 || ring_num_cameras < 2 ||
              ring_num_cameras > kMaxRingCameras)) {
    message << "ring_num_cameras must be 0, or 2.." << kMaxRingCameras
            << " with the ring5 preset, got " << ring_num_cameras << " with "
            << RigPresetName(preset);
  } else if (stereo_num_pairs < 1 || stereo_num_pairs > 8 ||
             ((stereo_num_pairs > 1 || stereo_alternate_facing) &&
              preset != RigPreset::kStereoPair)) {
    message << "stereo_num_pairs must be 1..8 and stereo_num_pairs > 1 or "
               "stereo_alternate_facing need the stereo_pair preset, got "
            << stereo_num_pairs << " with " << RigPresetName(preset);
  } else if (image_height != 0 && (image_height < 16 || image_height > 20000)) {
    message << "image_height must be 0 or in [16, 20000] rows, got "
            << image_height;
  } else if (!(map_scale > 0 && std::isfinite(map_scale))) {
    message << "map_scale must be a positive number, got " << map_scale;
  } else if (!(feature_window > 0 && feature_window <= 1)) {
    message << "feature_window must be in (0, 1], got " << feature_window;
  } else if (map_observations_per_image < 0) {
    message << "map_observations_per_image must be >= 0, got "
            << map_observations_per_image;
  } else if (num_map_images < 0 || !(map_noise_px >= 0) ||
             !(map_point_noise >= 0) || !(map_pose_noise_deg >= 0) ||
             !(map_pose_noise >= 0) || !std::isfinite(map_drift_deg) ||
             !(std::abs(map_scale_drift) < 0.5)) {
    message << "num_map_images, map_noise_px, map_point_noise, "
               "map_pose_noise_deg and map_pose_noise must be >= 0, "
               "map_drift_deg finite and |map_scale_drift| < 0.5, got "
            << num_map_images << ", " << map_noise_px << ", "
            << map_point_noise << ", " << map_pose_noise_deg << ", "
            << map_pose_noise << ", " << map_drift_deg << ", "
            << map_scale_drift;
  } else if (CheckTimeModel(*this, &message)) {
    return true;
  }
  *error = message.str();
  return false;
}

SyntheticRig GenerateSyntheticRig(const SyntheticRigOptions& options) {
  SyntheticRig rig;
  std::string error;
  if (!options.Check(&error)) {
    LOG(ERROR) << "Invalid synthetic rig options: " << error;
    return rig;
  }
  // One random stream, drawn in this order: trajectory phases, missing
  // images, then per image (frameset-major) its window, points, wrong
  // matches, order and noise (the time offsets and line delays have their
  // own, AddTimeModel).
  std::mt19937 rng(options.seed);
  const PresetDefinition definition = DefinitionOf(options);
  rig.truth = TruthOfDefinition(definition);
  const int num_cameras = rig.truth.cameras.size();

  const Rigid3d body_from_rig = BodyFromCamera(definition.cameras[0]);
  if (options.frameset_rate_hz > 0) {
    AddTimeModel(options, definition.motion, body_from_rig, &rng, &rig.truth);
  } else {
    std::vector<Rigid3d> trajectory =
        MakeTrajectory(definition.motion, options.num_framesets, &rng);
    for (Rigid3d& world_from_body : trajectory) {
      if (options.rotation_only) {
        world_from_body.translation = trajectory.front().translation;
      }
      rig.truth.rig_from_world.push_back(
          (world_from_body * body_from_rig).Inverse());
    }
  }

  rig.dataset.cameras = InitialCameras(rig.truth);
  for (int j = 0; j < options.num_framesets; ++j) {
    rig.dataset.frameset_names.push_back(FramesetName(j));
  }
  rig.dataset.frameset_times_s = rig.truth.frameset_times_s;
  rig.dataset.reference_camera = 0;

  const std::vector<std::vector<char>> image_exists = ChooseExistingImages(
      options.num_framesets, num_cameras, options.missing_image_ratio, &rng);
  const int num_outliers = static_cast<int>(
      std::lround(options.outlier_ratio * options.points_per_image));
  const int num_inliers = options.points_per_image - num_outliers;
  const int num_track_points =
      static_cast<int>(std::lround(options.track_ratio * num_inliers));

  PointGenerator generator(options, &rng);
  for (int j = 0; j < options.num_framesets; ++j) {
    for (int c = 0; c < num_cameras; ++c) {
      if (!image_exists[j][c]) {
        continue;
      }
      const ImageContext context =
          MakeImageContext(options, rig.truth, j, c, &rng);
      GenerateImage(options, context, j, c, num_track_points, num_outliers,
                    &generator, &rng, &rig);
    }
  }
  rig.true_points3D = generator.Points();
  // A separate random stream, so that the rig images stay those of earlier
  // versions for the same seed.
  AddSyntheticMap(options, &rig);
  if (options.map_scale != 1.0) ScaleMap(options.map_scale, &rig);
  return rig;
}

SyntheticRig SelectFramesets(const SyntheticRig& rig,
                             const std::vector<int>& framesets) {
  SyntheticRig selected;
  selected.dataset.cameras = rig.dataset.cameras;
  selected.dataset.map_cameras = rig.dataset.map_cameras;
  selected.dataset.map_images = rig.dataset.map_images;
  selected.dataset.map_points3D = rig.dataset.map_points3D;
  selected.true_points3D = rig.true_points3D;
  selected.true_map_cam_from_world = rig.true_map_cam_from_world;
  selected.dataset.reference_camera = rig.dataset.reference_camera;
  selected.truth = rig.truth;
  selected.truth.rig_from_world.clear();
  selected.truth.frameset_times_s.clear();
  const int num_framesets = rig.dataset.frameset_names.size();
  std::vector<int> new_index(num_framesets, -1);
  for (const int frameset : framesets) {
    if (frameset < 0 || frameset >= num_framesets || new_index[frameset] >= 0) {
      LOG(ERROR) << "Skipping frameset index " << frameset
                 << " (out of range or repeated; the rig has " << num_framesets
                 << " framesets)";
      continue;
    }
    new_index[frameset] = selected.dataset.frameset_names.size();
    selected.dataset.frameset_names.push_back(
        rig.dataset.frameset_names[frameset]);
    selected.truth.rig_from_world.push_back(rig.truth.rig_from_world[frameset]);
    if (!rig.truth.frameset_times_s.empty()) {
      selected.truth.frameset_times_s.push_back(
          rig.truth.frameset_times_s[frameset]);
    }
    if (!rig.dataset.frameset_times_s.empty()) {
      selected.dataset.frameset_times_s.push_back(
          rig.dataset.frameset_times_s[frameset]);
    }
  }
  // A dataset's frameset times increase (ValidateDataset): a selection out
  // of time order has none (the truth keeps them).
  const std::vector<double>& times = selected.dataset.frameset_times_s;
  if (std::adjacent_find(times.begin(), times.end(), [](double a, double b) {
        return !(b > a);
      }) != times.end()) {
    LOG(WARNING) << "The selected framesets are not in time order: the "
                    "dataset gets no frameset times";
    selected.dataset.frameset_times_s.clear();
  }
  // Images in the order of the selected framesets, cameras in order within.
  std::vector<std::vector<int>> images_of_frameset(
      selected.dataset.frameset_names.size());
  for (size_t i = 0; i < rig.dataset.images.size(); ++i) {
    const int frameset = rig.dataset.images[i].frameset_index;
    if (frameset >= 0 && frameset < num_framesets && new_index[frameset] >= 0) {
      images_of_frameset[new_index[frameset]].push_back(i);
    }
  }
  for (size_t j = 0; j < images_of_frameset.size(); ++j) {
    for (const int i : images_of_frameset[j]) {
      RigImage image = rig.dataset.images[i];
      image.frameset_index = j;
      selected.dataset.images.push_back(std::move(image));
      selected.is_outlier.push_back(
          i < rig.is_outlier.size() ? rig.is_outlier[i] : std::vector<char>());
    }
  }
  return selected;
}

void SetKnownIntrinsics(SyntheticRig* rig) {
  for (size_t c = 0; c < rig->dataset.cameras.size(); ++c) {
    rig->dataset.cameras[c].camera = rig->truth.cameras[c];
    rig->dataset.cameras[c].intrinsics_known = true;
  }
}

}  // namespace rig_calibrator
