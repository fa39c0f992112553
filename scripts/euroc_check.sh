#!/usr/bin/env bash
# The real-data check on EuRoC V1_01 (95 stereo framesets, 752x480, 20 Hz):
#   1. writes the reference calibration (the dataset's sensor.yaml files) as a
#      Kalibr camchain.yaml (scripts/euroc_tools.py reference),
#   2. builds a COLMAP map (CLI, CPU) from the stereo images of every
#      EUROC_MAP_EVERY-th frameset (the MAV stands on the ground in these
#      frames, so cam0 alone has no parallax; the step prints the image
#      motion), one self-calibrated camera per folder, and scales it to
#      metres by the known stereo baseline measured on those map framesets,
#   3. calibrates the pair from the odd framesets, which are not in the map
#      (scripts/calibrate_rig.sh, camera model EUROC_CAMERA_MODEL),
#   4. compares with the reference (rig_calibrator evaluate) and prints the
#      table, the recovered baseline and rotation, and the diagnosis inputs:
#      the rig's motion in the images, the map's self-calibrated focal
#      lengths, and (EUROC_DIAGNOSTIC=1) a second calibration against the
#      same map re-triangulated with the reference intrinsics held fixed,
#      which separates the map's errors from the calibrator's.
# The baseline is metric only through the map's scale, which comes from the
# same stereo baseline on other framesets: it checks consistency, not the
# baseline itself.
#
# Usage: scripts/euroc_check.sh [OUTPUT_DIR]   (default: demo_output/euroc in the
#                                               repository)
#   OUTPUT_DIR must not exist or be empty; EUROC_OVERWRITE=1 replaces an
#   earlier output of this script (recognized by its marker file).
# Environment:
#   EUROC_DIR          the data (default: ../shared/data/euroc_v1_01_micro
#                      beside the repository, as REAL_DATA_DIR of
#                      scripts/real_data_check.sh):
#                      mav0/cam{0,1}/sensor.yaml, mav0/cam{0,1}/data/*.png
#   EUROC_MAP_EVERY    map framesets: every N-th (default 8, i.e. 12 framesets)
#   EUROC_MAP_MODEL    camera model of the map's self-calibration (default
#                      RADIAL: one focal length, k1, k2)
#   EUROC_CAMERA_MODEL the calibration's --RigCalibrator.camera_model (default
#                      auto, the command's default; OPENCV is the reference's)
#   EUROC_DIAGNOSTIC   1 (default): also calibrate against the map
#                      re-triangulated with the reference intrinsics; 0: skip
#   EUROC_SKIP_BUILD   1: use the built tree as it is (else scripts/build.sh)
#   RIG_CALIBRATOR_BUILD_DIR, COLMAP, RIG_*: see scripts/build.sh and
#   scripts/calibrate_rig.sh
set -euo pipefail

log_tag=euroc
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
out="${1:-$repo/demo_output/euroc}"
data="${EUROC_DIR:-$(dirname "$repo")/shared/data/euroc_v1_01_micro}"
map_every="${EUROC_MAP_EVERY:-8}"
map_model="${EUROC_MAP_MODEL:-RADIAL}"
camera_model="${EUROC_CAMERA_MODEL:-auto}"
diagnostic="${EUROC_DIAGNOSTIC:-1}"
tools="$repo/scripts/euroc_tools.py"
marker=".euroc_check_output"

check_arguments 0 1 "$@"
[[ "$map_every" =~ ^[1-9][0-9]*$ ]] || die "EUROC_MAP_EVERY must be a positive integer, got '$map_every'"
[[ -d "$data" ]] ||
  die "no EuRoC data at $data (the default is ../shared/data/euroc_v1_01_micro beside the repository): set EUROC_DIR to the folder holding mav0/"
for camera in cam0 cam1; do
  [[ -f "$data/mav0/$camera/sensor.yaml" && -d "$data/mav0/$camera/data" ]] ||
    die "no $data/mav0/$camera/{sensor.yaml,data/}: set EUROC_DIR to the EuRoC folder"
done
command -v python3 > /dev/null || die "python3 is needed (scripts/setup_deps.sh installs it)"

if [[ -e "$out" && -n "$(ls -A "$out" 2>/dev/null)" ]]; then
  if [[ "${EUROC_OVERWRITE:-0}" == 1 && -f "$out/$marker" ]]; then
    echo "[euroc] EUROC_OVERWRITE=1: replacing the earlier output in $out"
    rm -rf -- "$out"
  elif [[ "${EUROC_OVERWRITE:-0}" == 1 ]]; then
    die "$out is not empty and was not written by this script; not replacing it"
  else
    die "$out exists and is not empty; remove it, give another OUTPUT_DIR, or set EUROC_OVERWRITE=1 to replace an earlier output of this script"
  fi
fi
mkdir -p "$out"
out="$(cd "$out" && pwd)"
touch "$out/$marker"

total_start=$SECONDS
step_name_width=52
# Runs one colmap command, its output appended to $log.
colmap_logged() {
  local log="$1"
  shift
  if ! "$colmap" "$@" >> "$log" 2>&1; then
    tail -n 20 "$log" >&2
    echo "[euroc] colmap $1 failed (log: $log)" >&2
    return 1
  fi
}

if [[ "${EUROC_SKIP_BUILD:-0}" != 1 ]]; then
  run_step "build" bash "$repo/scripts/build.sh"
fi
[[ -x "$rig_calibrator" ]] || die "no $rig_calibrator; build first (scripts/build.sh)"
# shellcheck source=find_colmap.sh
source "$repo/scripts/find_colmap.sh"

# --- 1. Reference --------------------------------------------------------------
reference="$out/reference/camchain.yaml"
write_reference() {
  mkdir -p "$out/reference"
  python3 "$tools" reference "$data/mav0/cam0/sensor.yaml" \
    "$data/mav0/cam1/sensor.yaml" "$reference"
}
run_step "reference calibration (camchain.yaml)" write_reference

# --- 2. Frames: map framesets and calibration framesets -------------------------
# Framesets are the timestamps present in both cameras. Map: index % N == 0;
# calibration: odd indices not in the map (disjoint for even N).
split_frames() {
  comm -12 <(ls "$data/mav0/cam0/data" | grep -i '\.png$' | sort) \
           <(ls "$data/mav0/cam1/data" | grep -i '\.png$' | sort) > "$out/framesets.txt"
  local count
  count=$(wc -l < "$out/framesets.txt")
  [[ "$count" -ge 4 ]] || { echo "only $count stereo framesets" >&2; return 1; }
  awk -v n="$map_every" '(NR - 1) % n == 0' "$out/framesets.txt" > "$out/map_framesets.txt"
  awk -v n="$map_every" '(NR - 1) % 2 == 1 && (NR - 1) % n != 0' "$out/framesets.txt" \
    > "$out/calibration_framesets.txt"
  local folder camera frame
  for camera in cam0 cam1; do
    mkdir -p "$out/map_images/map_$camera" "$out/rig_images/$camera"
    while read -r frame; do
      ln -s "$data/mav0/$camera/data/$frame" "$out/map_images/map_$camera/$frame"
    done < "$out/map_framesets.txt"
    while read -r frame; do
      ln -s "$data/mav0/$camera/data/$frame" "$out/rig_images/$camera/$frame"
    done < "$out/calibration_framesets.txt"
  done
  echo "$count stereo framesets: $(wc -l < "$out/map_framesets.txt") for the map" \
    "(every ${map_every}th), $(wc -l < "$out/calibration_framesets.txt") for the" \
    "calibration (the odd ones not in the map)"
}
run_step "frameset split" split_frames

# --- 3. Map ------------------------------------------------------------------------
map="$out/map"
map_log="$map/colmap.log"
build_map() {
  mkdir -p "$map/mapper"
  : > "$map_log"
  echo "feature extraction ($map_model, one camera per folder) ..."
  colmap_logged "$map_log" feature_extractor --database_path "$map/database.db" \
    --image_path "$out/map_images" --ImageReader.single_camera_per_folder 1 \
    --ImageReader.camera_model "$map_model" --SiftExtraction.use_gpu 0 \
    --SiftExtraction.max_num_features "${RIG_MAX_FEATURES:-4096}" || return 1
  python3 "$tools" pairs "$out/map_framesets.txt" "$map/pairs.txt"
  echo "matching ..."
  colmap_logged "$map_log" matches_importer --database_path "$map/database.db" \
    --match_list_path "$map/pairs.txt" --match_type pairs \
    --SiftMatching.use_gpu 0 || return 1
  echo "image motion in the verified matches:"
  python3 "$tools" parallax "$map/database.db"
  # The only parallax is the 11 cm stereo baseline (about 2 degrees at 3 m):
  # the default initial-pair angle (16 deg) and point angles (1.5 deg) are
  # for moving cameras.
  echo "mapping ..."
  colmap_logged "$map_log" mapper --database_path "$map/database.db" \
    --image_path "$out/map_images" --output_path "$map/mapper" \
    --Mapper.init_min_tri_angle 1 --Mapper.tri_min_angle 0.5 \
    --Mapper.filter_min_tri_angle 0.5 || return 1
  local best="" best_count=0 model count
  for model in "$map"/mapper/*/; do
    [[ -f "$model/images.bin" ]] || continue
    count=$("$colmap" model_analyzer --path "$model" 2>&1 |
            sed -n 's/.*Registered images: *\([0-9]*\).*/\1/p' | head -n 1)
    if [[ "${count:-0}" -gt "$best_count" ]]; then best_count="$count"; best="${model%/}"; fi
  done
  [[ -n "$best" ]] || { echo "the mapper reconstructed nothing (log: $map_log)" >&2; return 1; }
  echo "the mapper registered $best_count of $(( 2 * $(wc -l < "$out/map_framesets.txt") )) images"
  mkdir -p "$map/unscaled_txt"
  colmap_logged "$map_log" model_converter --input_path "$best" \
    --output_path "$map/unscaled_txt" --output_type TXT || return 1
  echo "the map's self-calibrated cameras (camera 1 = map_cam0, 2 = map_cam1):"
  grep -v '^#' "$map/unscaled_txt/cameras.txt" | sed 's/^/  /'
  # Metric scale: the reference baseline over the map's median cam0-cam1
  # distance of the map framesets (none of them is used for calibrating).
  local baseline
  baseline=$(python3 "$tools" rig "$reference" | awk '{ print $2 }')
  python3 "$tools" scale "$map/unscaled_txt" "$baseline" "$map/scale.txt" || return 1
  mkdir -p "$map/sparse/0"
  colmap_logged "$map_log" model_transformer --input_path "$best" \
    --output_path "$map/sparse/0" --transform_path "$map/scale.txt" || return 1
  "$colmap" model_analyzer --path "$map/sparse/0" 2>&1 |
    grep -E "Registered images|Points|Mean reprojection error" | sed 's/^.*\] /  /' || true
}
run_step "map (colmap, stereo framesets)" build_map

# --- 4. Calibration -----------------------------------------------------------------
run_step "calibration (colmap features + rig_calibrator)" \
  bash "$repo/scripts/calibrate_rig.sh" \
  "$map/database.db" "$map/sparse/0" "$out/rig_images" "$out/rig" \
  --RigCalibrator.camera_model "$camera_model"

# --- 5. Evaluation -------------------------------------------------------------------
# Prints evaluate's tables (all-camera alignment, then cam0 = rig frame so
# that cam1's center error is the error of the baseline vector) and the
# recovered baseline and relative rotation.
evaluate() {
  local calibration="$1" name="$2"
  "$rig_calibrator" evaluate --reference_path "$reference" \
    --calibration_path "$calibration" --output_path "$out/evaluation_$name.json" || return 1
  echo
  echo "aligned by the reference camera (cam0 = rig frame in both):"
  "$rig_calibrator" evaluate --reference_path "$reference" \
    --calibration_path "$calibration" --align_reference_camera 1 \
    --output_path "$out/evaluation_${name}_cam0_aligned.json" | tail -n 6 || return 1
  echo
  printf 'reference:   '; python3 "$tools" rig "$reference"
  printf 'calibration: '; python3 "$tools" rig "$calibration/camchain.yaml"
}
run_step "evaluation" evaluate "$out/rig/calibration" main

# --- 6. Diagnostic: the same map with the reference intrinsics -------------------------
# The map's points re-triangulated from its poses with the reference
# intrinsics held fixed, bundle adjusted (intrinsics fixed), scaled as above.
# rig_calibrator starts from COLMAP's default intrinsics as before, so this
# shows what it recovers when the map's geometry is right, and the two maps'
# RMS shows how well the images tell the focal lengths apart.
diagnostic_map() {
  local diag="$out/diagnostic" log="$out/diagnostic/colmap.log"
  mkdir -p "$diag/input" "$diag/triangulated" "$diag/adjusted" "$diag/adjusted_txt" \
           "$diag/sparse/0" "$diag/self_calibrated_adjusted"
  : > "$log"
  # The poses without points (every image's second line emptied).
  awk '!/^#/ { if (++n % 2 == 1) print; else print "" }' \
    "$map/unscaled_txt/images.txt" > "$diag/input/images.txt"
  : > "$diag/input/points3D.txt"
  local id0 id1
  id0=$(awk '!/^#/ && $10 ~ /^map_cam0\// { print $9; exit }' "$diag/input/images.txt")
  id1=$(awk '!/^#/ && $10 ~ /^map_cam1\// { print $9; exit }' "$diag/input/images.txt")
  [[ -n "$id0" && -n "$id1" ]] || { echo "the map lacks map_cam0 or map_cam1 images" >&2; return 1; }
  awk -v id0="$id0" -v id1="$id1" '/^cam[0-9]+:/ { name = $1 }
       /resolution:/ { gsub(/[\[\],]/, " "); r[name] = $2 " " $3 }
       /intrinsics:/ { gsub(/[\[\],]/, " "); i[name] = $2 " " $3 " " ($4 + 0.5) " " ($5 + 0.5) }
       /distortion_coeffs:/ { gsub(/[\[\],]/, " "); d[name] = $2 " " $3 " " $4 " " $5 }
       END { print id0 " OPENCV " r["cam0:"] " " i["cam0:"] " " d["cam0:"];
             print id1 " OPENCV " r["cam1:"] " " i["cam1:"] " " d["cam1:"] }' \
    "$reference" > "$diag/input/cameras.txt"
  echo "reference cameras in COLMAP's convention (principal point + 0.5):"
  sed 's/^/  /' "$diag/input/cameras.txt"
  local fixed=(--BundleAdjustment.refine_focal_length 0
               --BundleAdjustment.refine_principal_point 0
               --BundleAdjustment.refine_extra_params 0)
  colmap_logged "$log" point_triangulator --database_path "$map/database.db" \
    --image_path "$out/map_images" --input_path "$diag/input" \
    --output_path "$diag/triangulated" --Mapper.ba_refine_focal_length 0 \
    --Mapper.ba_refine_principal_point 0 --Mapper.ba_refine_extra_params 0 \
    --Mapper.tri_min_angle 0.5 --Mapper.filter_min_tri_angle 0.5 || return 1
  colmap_logged "$diag/ba_reference.log" bundle_adjuster \
    --input_path "$diag/triangulated" --output_path "$diag/adjusted" "${fixed[@]}" \
    --BundleAdjustment.max_num_iterations 1000 || return 1
  # The self-calibrated map adjusted the same way (its own intrinsics fixed),
  # for a like-for-like RMS.
  colmap_logged "$diag/ba_self_calibrated.log" bundle_adjuster \
    --input_path "$map/sparse/0" --output_path "$diag/self_calibrated_adjusted" \
    "${fixed[@]}" --BundleAdjustment.max_num_iterations 1000 || return 1
  echo "bundle adjustment RMS with the intrinsics held fixed:" \
    "reference intrinsics $(awk '/Final cost/ { print $4 }' "$diag/ba_reference.log") px," \
    "the map's self-calibrated intrinsics $(awk '/Final cost/ { print $4 }' "$diag/ba_self_calibrated.log") px"
  colmap_logged "$log" model_converter --input_path "$diag/adjusted" \
    --output_path "$diag/adjusted_txt" --output_type TXT || return 1
  local baseline
  baseline=$(python3 "$tools" rig "$reference" | awk '{ print $2 }')
  python3 "$tools" scale "$diag/adjusted_txt" "$baseline" "$diag/scale.txt" || return 1
  colmap_logged "$log" model_transformer --input_path "$diag/adjusted" \
    --output_path "$diag/sparse/0" --transform_path "$diag/scale.txt" || return 1
  "$rig_calibrator" --database_path "$out/rig/database.db" \
    --image_path "$out/rig_images" --input_path "$diag/sparse/0" \
    --output_path "$diag/calibration" --RigCalibrator.camera_model "$camera_model" \
    > "$diag/rig_calibrator.log" 2>&1 || { tail -n 20 "$diag/rig_calibrator.log" >&2; return 1; }
  sed -n '/^== Result/,/^$/p' "$diag/rig_calibrator.log"
  evaluate "$diag/calibration" diagnostic
}
if [[ "$diagnostic" == 1 ]]; then
  run_step "diagnostic: map with the reference intrinsics" diagnostic_map
fi

echo
print_timings "$total_start"
cat << INFO

[euroc] outputs in $out:
  reference/camchain.yaml       the reference (EuRoC sensor.yaml, Kalibr convention)
  map/sparse/0, map/database.db the metric map (stereo framesets, scaled by the baseline)
  rig/calibration               the calibration (model, rig_config.json, camchain.yaml,
                                calibration_summary.json with the diagnostics)
  evaluation_*.json             rig_calibrator evaluate's errors
  diagnostic/                   the map with the reference intrinsics and the
                                calibration against it (EUROC_DIAGNOSTIC=1)
INFO
