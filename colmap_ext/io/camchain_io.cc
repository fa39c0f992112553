#include "colmap_ext/io/camchain_io.h"

#include <colmap/base/camera_models.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "colmap_ext/io/atomic_output.h"
#include "colmap_ext/io/number_text.h"

namespace rig_calibrator {
namespace {

// Kalibr's pixel convention puts the center of the top-left pixel at (0, 0),
// COLMAP's at (0.5, 0.5).
constexpr double kKalibrPixelShift = 0.5;

// (f_x, f_y); models with one focal length have f_x = f_y.
Eigen::Vector2d FocalLengths(const colmap::Camera& camera) {
  if (camera.FocalLengthIdxs().size() == 1) {
    return Eigen::Vector2d::Constant(camera.FocalLength());
  }
  return Eigen::Vector2d(camera.FocalLengthX(), camera.FocalLengthY());
}

// The normalized distorted point d = u + D(coeffs; u) of Kalibr's radtan
// (fisheye = false) or equidistant (fisheye = true) model at the undistorted
// normalized point u. COLMAP's OPENCV and OPENCV_FISHEYE distortion functions
// are exactly these models.
Eigen::Vector2d KalibrDistort(bool fisheye, const double coeffs[4],
                              const Eigen::Vector2d& u) {
  double du = 0;
  double dv = 0;
  if (fisheye) {
    colmap::OpenCVFisheyeCameraModel::Distortion(coeffs, u.x(), u.y(), &du,
                                                 &dv);
  } else {
    colmap::OpenCVCameraModel::Distortion(coeffs, u.x(), u.y(), &du, &dv);
  }
  return u + Eigen::Vector2d(du, dv);
}

// Fits the four coefficients of Kalibr's radtan or equidistant model to the
// distortion of `camera`, keeping its focal lengths and principal point.
// Both models are affine in their coefficients, d(k; u) = d(0; u) +
// sum_j k_j (d(e_j; u) - d(0; u)), so the fit over a grid of pixels, in
// pixels, is linear least squares: for each pixel p with undistorted point
// u = camera.ImageToWorld(p) and distorted normalized point
// d* = ((p_x - c_x) / f_x, (p_y - c_y) / f_y), minimize |F (d(k; u) - d*)|^2
// with F = diag(f_x, f_y).
bool FitKalibrDistortion(const colmap::Camera& camera, bool fisheye,
                         std::vector<double>* coeffs, double* max_error_px,
                         std::string* error) {
  constexpr int kGridX = 32;
  constexpr int kGridY = 24;
  const double fx = FocalLengths(camera).x();
  const double fy = FocalLengths(camera).y();
  const double cx = camera.PrincipalPointX();
  const double cy = camera.PrincipalPointY();
  std::vector<Eigen::Vector2d> undistorted;
  std::vector<Eigen::Vector2d> distorted;
  for (int iy = 0; iy < kGridY; ++iy) {
    for (int ix = 0; ix < kGridX; ++ix) {
      const Eigen::Vector2d pixel(
          0.5 + (camera.Width() - 1.0) * ix / (kGridX - 1),
          0.5 + (camera.Height() - 1.0) * iy / (kGridY - 1));
      const Eigen::Vector2d u = camera.ImageToWorld(pixel);
      // Keep pixels whose undistortion converged (it can fail far out in the
      // image, beyond the model's valid field of view).
      if (!u.allFinite() || (camera.WorldToImage(u) - pixel).norm() > 1e-6) {
        continue;
      }
      undistorted.push_back(u);
      distorted.emplace_back((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
    }
  }
  if (undistorted.size() < 16) {
    *error = "cannot fit Kalibr distortion to the " + camera.ModelName() +
             " camera: its undistortion fails over most of the image";
    return false;
  }
  const int n = static_cast<int>(undistorted.size());
  const double zero[4] = {0, 0, 0, 0};
  Eigen::MatrixXd a(2 * n, 4);
  Eigen::VectorXd b(2 * n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d base = KalibrDistort(fisheye, zero, undistorted[i]);
    for (int j = 0; j < 4; ++j) {
      double unit[4] = {0, 0, 0, 0};
      unit[j] = 1;
      const Eigen::Vector2d column =
          KalibrDistort(fisheye, unit, undistorted[i]) - base;
      a(2 * i, j) = fx * column.x();
      a(2 * i + 1, j) = fy * column.y();
    }
    b(2 * i) = fx * (distorted[i].x() - base.x());
    b(2 * i + 1) = fy * (distorted[i].y() - base.y());
  }
  const Eigen::Vector4d k = a.colPivHouseholderQr().solve(b);
  const Eigen::VectorXd residuals = a * k - b;
  *max_error_px = 0;
  for (int i = 0; i < n; ++i) {
    *max_error_px = std::max(*max_error_px, residuals.segment<2>(2 * i).norm());
  }
  if (!k.allFinite()) {
    *error = "the Kalibr distortion fit of the " + camera.ModelName() +
             " camera failed";
    return false;
  }
  coeffs->assign(k.data(), k.data() + 4);
  return true;
}

std::string YamlList(const std::vector<double>& values) {
  std::string text = "[";
  for (size_t i = 0; i < values.size(); ++i) {
    text += (i > 0 ? ", " : "") + FormatYamlFloat(values[i]);
  }
  return text + "]";
}

// A ROS topic placeholder from the camera name: ROS names allow letters,
// digits, '_' and '/'.
std::string TopicPlaceholder(const std::string& camera_name) {
  std::string topic = "/";
  for (const char c : camera_name) {
    topic += std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/'
                 ? c
                 : '_';
  }
  return topic + "/image_raw";
}

bool ReadDoubles(const YAML::Node& node, size_t size,
                 std::vector<double>* values) {
  if (!node || !node.IsSequence() || node.size() != size) {
    return false;
  }
  values->clear();
  for (const YAML::Node& element : node) {
    double value = 0;
    if (!element.IsScalar() || !YAML::convert<double>::decode(element, value) ||
        !std::isfinite(value)) {
      return false;
    }
    values->push_back(value);
  }
  return true;
}

// How a COLMAP camera model's distortion maps to Kalibr's: the COLMAP
// parameter index of every Kalibr coefficient (-1: 0), and the parameters
// Kalibr's model has not, with which the mapping is exact only when they are
// all 0 (else the coefficients are fitted, FitKalibrDistortion).
struct DistortionMapping {
  std::string model;
  std::string kalibr_model;
  std::vector<int> coeffs;
  std::vector<int> not_in_kalibr;
};

const DistortionMapping kDistortionMappings[] = {
    {"SIMPLE_PINHOLE", "radtan", {-1, -1, -1, -1}, {}},
    {"PINHOLE", "radtan", {-1, -1, -1, -1}, {}},
    {"SIMPLE_RADIAL", "radtan", {3, -1, -1, -1}, {}},
    {"RADIAL", "radtan", {3, 4, -1, -1}, {}},
    {"OPENCV", "radtan", {4, 5, 6, 7}, {}},
    // fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6.
    {"FULL_OPENCV", "radtan", {4, 5, 6, 7}, {8, 9, 10, 11}},
    {"OPENCV_FISHEYE", "equidistant", {4, 5, 6, 7}, {}},
    {"SIMPLE_RADIAL_FISHEYE", "equidistant", {3, -1, -1, -1}, {}},
    {"RADIAL_FISHEYE", "equidistant", {3, 4, -1, -1}, {}},
    {"FOV", "fov", {4}, {}},
    // fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1.
    {"THIN_PRISM_FISHEYE", "equidistant", {4, 5, 8, 9}, {6, 7, 10, 11}},
};

// The timing fields of a camera (see the header).
void WriteTiming(const RigDescriptionCamera& camera, std::ostringstream* yaml) {
  const CameraTiming& timing = *camera.timing;
  if (camera.timestamp_offset_s != 0) {
    *yaml << "  # timeshift_cam_imu = the capture-time offset against the "
             "frameset times ("
          << FormatYamlFloat(timing.time_offset_s)
          << " s) - the offset removed from the camera's names before "
             "grouping ("
          << FormatYamlFloat(camera.timestamp_offset_s) << " s)\n";
  }
  *yaml << "  timeshift_cam_imu: "
        << FormatYamlFloat(timing.time_offset_s - camera.timestamp_offset_s)
        << "\n";
  // A sigma that could not be computed (NaN) is not written.
  if (std::isfinite(timing.time_offset_sigma_s)) {
    *yaml << "  timeshift_cam_imu_sigma: "
          << FormatYamlFloat(timing.time_offset_sigma_s) << "\n";
  }
  if (timing.line_delay_s_per_row) {
    *yaml << "  line_delay: " << FormatYamlFloat(*timing.line_delay_s_per_row)
          << "\n";
    if (std::isfinite(timing.line_delay_sigma_s_per_row)) {
      *yaml << "  line_delay_sigma: "
            << FormatYamlFloat(timing.line_delay_sigma_s_per_row) << "\n";
    }
  }
  *yaml << "  timing_source: " << TimingSourceName(timing.source) << "\n";
}

}  // namespace

bool ColmapToKalibrCamera(const colmap::Camera& camera, KalibrCamera* kalibr,
                          std::string* error) {
  *kalibr = KalibrCamera();
  if (camera.Width() == 0 || camera.Height() == 0) {
    *error = "a Kalibr camera needs the image size";
    return false;
  }
  if (!camera.VerifyParams()) {
    *error = "invalid " + camera.ModelName() + " parameters";
    return false;
  }
  const std::vector<double>& p = camera.Params();
  kalibr->width = static_cast<int>(camera.Width());
  kalibr->height = static_cast<int>(camera.Height());
  kalibr->intrinsics = {FocalLengths(camera).x(), FocalLengths(camera).y(),
                        camera.PrincipalPointX() - kKalibrPixelShift,
                        camera.PrincipalPointY() - kKalibrPixelShift};
  const std::string model = camera.ModelName();
  const auto mapping = std::find_if(
      std::begin(kDistortionMappings), std::end(kDistortionMappings),
      [&](const DistortionMapping& m) { return m.model == model; });
  if (mapping == std::end(kDistortionMappings)) {
    *error = "the camera model " + model + " has no Kalibr equivalent";
    return false;
  }
  kalibr->distortion_model = mapping->kalibr_model;
  for (const int index : mapping->coeffs) {
    kalibr->distortion_coeffs.push_back(index < 0 ? 0.0 : p[index]);
  }
  for (const int index : mapping->not_in_kalibr) {
    kalibr->exact = kalibr->exact && p[index] == 0;
  }
  if (!kalibr->exact) {
    return FitKalibrDistortion(
        camera, kalibr->distortion_model == "equidistant",
        &kalibr->distortion_coeffs, &kalibr->max_fit_error_px, error);
  }
  return true;
}

bool KalibrToColmapCamera(const KalibrCamera& kalibr, colmap::Camera* camera,
                          std::string* error) {
  if (kalibr.camera_model != "pinhole") {
    *error = "the Kalibr camera model " + kalibr.camera_model +
             " has no COLMAP 3.8 equivalent (only pinhole has)";
    return false;
  }
  if (kalibr.intrinsics.size() != 4) {
    *error = "a Kalibr pinhole camera has 4 intrinsics [fu, fv, pu, pv]";
    return false;
  }
  if (kalibr.width <= 0 || kalibr.height <= 0) {
    *error = "the Kalibr camera has no valid resolution";
    return false;
  }
  const std::vector<double>& k = kalibr.intrinsics;
  const double cx = k[2] + kKalibrPixelShift;
  const double cy = k[3] + kKalibrPixelShift;
  const std::vector<double>& d = kalibr.distortion_coeffs;
  std::string model;
  std::vector<double> params;
  if (kalibr.distortion_model == "radtan" && d.size() == 4) {
    model = "OPENCV";
    params = {k[0], k[1], cx, cy, d[0], d[1], d[2], d[3]};
  } else if (kalibr.distortion_model == "equidistant" && d.size() == 4) {
    model = "OPENCV_FISHEYE";
    params = {k[0], k[1], cx, cy, d[0], d[1], d[2], d[3]};
  } else if (kalibr.distortion_model == "fov" && d.size() == 1) {
    model = "FOV";
    params = {k[0], k[1], cx, cy, d[0]};
  } else if (kalibr.distortion_model == "none" && d.empty()) {
    model = "PINHOLE";
    params = {k[0], k[1], cx, cy};
  } else {
    *error = "unsupported Kalibr distortion model '" + kalibr.distortion_model +
             "' with " + std::to_string(d.size()) +
             " coefficients (radtan 4, equidistant 4, fov 1, none 0)";
    return false;
  }
  *camera = colmap::Camera();
  camera->SetModelIdFromName(model);
  camera->SetWidth(kalibr.width);
  camera->SetHeight(kalibr.height);
  camera->SetParams(params);
  return true;
}

bool WriteCamchainYaml(const std::string& path, const RigDescription& rig,
                       std::vector<std::string>* notes, std::string* error) {
  std::ostringstream yaml;
  yaml << "# Kalibr camera chain written by rig_calibrator.\n"
       << "# Pixels: Kalibr convention, the center of the top-left pixel is "
          "(0, 0) (COLMAP's principal point minus 0.5).\n"
       << "# T_cn_cnm1 is cam_n_from_cam_(n-1): x_n = R x_(n-1) + t.\n";
  const auto timed = std::find_if(
      rig.cameras.begin(), rig.cameras.end(),
      [](const RigDescriptionCamera& camera) {
        return camera.timing.has_value() && camera.camera && camera.cam_from_rig;
      });
  if (timed != rig.cameras.end()) {
    yaml << "# timeshift_cam_imu (s): no IMU here, the reference camera "
         << rig.cameras[rig.reference_camera].name
         << " takes its place: t_ref = t_cam + timeshift_cam_imu, t_cam the "
            "camera's image timestamp, t_ref the reference camera's clock "
            "when the image was taken.\n"
         << "# line_delay (s/row): row v is taken at t_ref + line_delay * v. "
            "Not Kalibr's: timeshift_cam_imu_sigma, line_delay_sigma (1 "
            "sigma), timing_source.\n";
    if (timed->timing->source == TimingSource::kMeasuredAfterCalibration) {
      yaml << "# Measured after a calibration that assumed synchronized "
              "cameras: the capture-time offsets are lower bounds in "
              "magnitude.\n";
    }
  }
  std::vector<std::string> file_notes;
  const Rigid3d* previous_cam_from_rig = nullptr;
  int index = 0;
  for (const RigDescriptionCamera& camera : rig.cameras) {
    if (!camera.camera || !camera.cam_from_rig) {
      file_notes.push_back("camchain.yaml: the rig camera " + camera.name +
                           " is not calibrated and is left out, so camN "
                           "numbers skip it");
      yaml << "# The rig camera " << camera.name
           << " is not calibrated and is left out.\n";
      continue;
    }
    KalibrCamera kalibr;
    std::string fit_error;
    if (!ColmapToKalibrCamera(*camera.camera, &kalibr, &fit_error)) {
      *error = "camchain.yaml: the camera " + camera.name + ": " + fit_error;
      return false;
    }
    const std::string key = "cam" + std::to_string(index);
    yaml << "# " << key << " is the rig camera " << camera.name
         << " (image prefix " << camera.image_prefix << "), COLMAP "
         << camera.camera->ModelName();
    if (kalibr.exact) {
      yaml << ", converted exactly.\n";
    } else {
      const std::string note =
          "camchain.yaml: " + key + " (" + camera.name + ") approximates " +
          camera.camera->ModelName() + " by Kalibr " + kalibr.distortion_model +
          " (least-squares fit, max error " +
          FormatDouble(std::round(kalibr.max_fit_error_px * 1e4) / 1e4) +
          " px over the image)";
      yaml << ", approximated: " << kalibr.distortion_model
           << " fitted by least squares, max error "
           << FormatDouble(std::round(kalibr.max_fit_error_px * 1e4) / 1e4)
           << " px over the image.\n";
      file_notes.push_back(note);
    }
    for (const std::string& comment : camera.comments) {
      yaml << "# " << comment << "\n";
    }
    yaml << key << ":\n";
    if (previous_cam_from_rig != nullptr) {
      const Eigen::Matrix<double, 3, 4> t =
          (*camera.cam_from_rig * previous_cam_from_rig->Inverse()).ToMatrix();
      yaml << "  T_cn_cnm1:\n";
      for (int r = 0; r < 3; ++r) {
        yaml << "  - " << YamlList({t(r, 0), t(r, 1), t(r, 2), t(r, 3)})
             << "\n";
      }
      yaml << "  - " << YamlList({0, 0, 0, 1}) << "\n";
    }
    yaml << "  camera_model: " << kalibr.camera_model << "\n"
         << "  intrinsics: " << YamlList(kalibr.intrinsics) << "\n"
         << "  distortion_model: " << kalibr.distortion_model << "\n"
         << "  distortion_coeffs: " << YamlList(kalibr.distortion_coeffs)
         << "\n"
         << "  resolution: [" << kalibr.width << ", " << kalibr.height << "]\n"
         << "  rostopic: " << TopicPlaceholder(camera.name) << "\n";
    if (camera.timing) WriteTiming(camera, &yaml);
    previous_cam_from_rig = &*camera.cam_from_rig;
    ++index;
  }
  if (index == 0) {
    *error = "camchain.yaml: no calibrated camera to write";
    return false;
  }
  if (!WriteFileAtomically(path, yaml.str(), error)) {
    return false;
  }
  if (notes != nullptr) {
    notes->insert(notes->end(), file_notes.begin(), file_notes.end());
  }
  return true;
}

namespace {

// The intrinsics of a camchain entry (`where` names it in errors).
bool ReadCamchainCamera(const YAML::Node& node, const std::string& where,
                        colmap::Camera* camera, std::string* error) {
  KalibrCamera kalibr;
  std::vector<double> resolution;
  try {
    if (!node["camera_model"] || !node["distortion_model"]) {
      *error = where + " needs camera_model and distortion_model";
      return false;
    }
    kalibr.camera_model = node["camera_model"].as<std::string>();
    kalibr.distortion_model = node["distortion_model"].as<std::string>();
  } catch (const YAML::Exception& e) {
    *error = where + ": " + e.what();
    return false;
  }
  const YAML::Node intrinsics = node["intrinsics"];
  const YAML::Node coeffs = node["distortion_coeffs"];
  if (!ReadDoubles(intrinsics, intrinsics ? intrinsics.size() : 0,
                   &kalibr.intrinsics) ||
      !ReadDoubles(coeffs, coeffs ? coeffs.size() : 0,
                   &kalibr.distortion_coeffs) ||
      !ReadDoubles(node["resolution"], 2, &resolution)) {
    *error = where +
             " needs intrinsics, distortion_coeffs and resolution as lists "
             "of numbers";
    return false;
  }
  if (resolution[0] != std::floor(resolution[0]) ||
      resolution[1] != std::floor(resolution[1]) || resolution[0] < 1 ||
      resolution[1] < 1 || resolution[0] > 1e6 || resolution[1] > 1e6) {
    *error = where + ": the resolution must be two positive integers";
    return false;
  }
  kalibr.width = static_cast<int>(resolution[0]);
  kalibr.height = static_cast<int>(resolution[1]);
  std::string camera_error;
  if (!KalibrToColmapCamera(kalibr, camera, &camera_error)) {
    *error = where + ": " + camera_error;
    return false;
  }
  return true;
}

// A finite number at `key` of `node`, if the key is there; false with an
// error naming it otherwise.
bool ReadOptionalNumber(const YAML::Node& node, const char* key,
                        const std::string& where, std::optional<double>* value,
                        std::string* error) {
  const YAML::Node element = node[key];
  value->reset();
  if (!element) return true;
  double number = 0;
  if (!element.IsScalar() || !YAML::convert<double>::decode(element, number) ||
      !std::isfinite(number)) {
    *error = where + ": " + key + " must be a finite number";
    return false;
  }
  *value = number;
  return true;
}

// The timing fields of a camchain entry (see the header), if any.
bool ReadCamchainTiming(const YAML::Node& node, const std::string& where,
                        std::optional<CameraTiming>* timing,
                        std::string* error) {
  std::optional<double> shift, shift_sigma, line_delay, line_delay_sigma;
  if (!ReadOptionalNumber(node, "timeshift_cam_imu", where, &shift, error) ||
      !ReadOptionalNumber(node, "timeshift_cam_imu_sigma", where, &shift_sigma,
                          error) ||
      !ReadOptionalNumber(node, "line_delay", where, &line_delay, error) ||
      !ReadOptionalNumber(node, "line_delay_sigma", where, &line_delay_sigma,
                          error)) {
    return false;
  }
  const YAML::Node source_node = node["timing_source"];
  timing->reset();
  if (!shift && !line_delay) {
    if (shift_sigma || line_delay_sigma || source_node) {
      *error = where +
               ": timeshift_cam_imu_sigma, line_delay_sigma or timing_source "
               "without timeshift_cam_imu or line_delay";
      return false;
    }
    return true;
  }
  if ((shift_sigma && !shift) || (line_delay_sigma && !line_delay)) {
    *error = where + ": a timing sigma without its value";
    return false;
  }
  CameraTiming& read = timing->emplace();
  read.time_offset_s = shift.value_or(0);
  read.time_offset_sigma_s = shift_sigma.value_or(0);
  read.line_delay_s_per_row = line_delay;
  read.line_delay_sigma_s_per_row = line_delay_sigma.value_or(0);
  if (source_node) {
    const std::optional<TimingSource> source =
        source_node.IsScalar()
            ? TimingSourceFromName(source_node.Scalar())
            : std::nullopt;
    if (!source) {
      *error = where +
               ": timing_source must be \"measured after calibration\" or "
               "\"estimated in the adjustment\"";
      return false;
    }
    read.source = *source;
  }
  return true;
}

// T_cn_cnm1 of a camchain entry: a 4x4 rigid transform, its rotation made
// exactly orthonormal.
bool ReadCamchainTransform(const YAML::Node& node, const std::string& where,
                           Rigid3d* cn_from_cnm1, std::string* error) {
  std::vector<double> rows[4];
  const YAML::Node t = node["T_cn_cnm1"];
  bool valid = t && t.IsSequence() && t.size() == 4;
  for (int r = 0; valid && r < 4; ++r) {
    valid = ReadDoubles(t[r], 4, &rows[r]);
  }
  if (!valid) {
    *error = where + " needs T_cn_cnm1 as a 4x4 matrix";
    return false;
  }
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  for (int r = 0; r < 3; ++r) {
    rotation.row(r) << rows[r][0], rows[r][1], rows[r][2];
    translation(r) = rows[r][3];
  }
  const bool last_row_valid =
      rows[3][0] == 0 && rows[3][1] == 0 && rows[3][2] == 0 && rows[3][3] == 1;
  if (!last_row_valid ||
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() >
          1e-6 ||
      rotation.determinant() < 0) {
    *error = where + ": T_cn_cnm1 is not a rigid transform";
    return false;
  }
  *cn_from_cnm1 = Rigid3d(NearestRotation(rotation), translation);
  return true;
}

}  // namespace

bool ReadCamchainYaml(const std::string& path, RigDescription* rig,
                      std::string* error) {
  *rig = RigDescription();
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    *error = "cannot read the camchain " + path + ": " + e.what();
    return false;
  }
  if (!root.IsMap()) {
    *error = "the camchain " + path + " is not a YAML map of cam0, cam1, ...";
    return false;
  }
  Rigid3d cam_from_cam0;
  for (int index = 0;; ++index) {
    const std::string key = "cam" + std::to_string(index);
    const YAML::Node node = root[key];
    if (!node) break;
    const std::string where = path + ": " + key;
    if (!node.IsMap()) {
      *error = where + " is not a map";
      return false;
    }
    colmap::Camera camera;
    if (!ReadCamchainCamera(node, where, &camera, error)) return false;
    if (index > 0) {
      Rigid3d cn_from_cnm1;
      if (!ReadCamchainTransform(node, where, &cn_from_cnm1, error)) {
        return false;
      }
      cam_from_cam0 = cn_from_cnm1 * cam_from_cam0;
    }
    RigDescriptionCamera rig_camera;
    rig_camera.name = key;
    rig_camera.camera = camera;
    rig_camera.cam_from_rig = cam_from_cam0;
    if (!ReadCamchainTiming(node, where, &rig_camera.timing, error)) {
      return false;
    }
    rig->cameras.push_back(std::move(rig_camera));
  }
  if (rig->cameras.empty()) {
    *error = "the camchain " + path + " has no cam0";
    return false;
  }
  return true;
}

}  // namespace rig_calibrator
