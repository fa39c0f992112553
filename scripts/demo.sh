#!/usr/bin/env bash
# The end-to-end demo on rendered images with exact ground truth:
#   1. builds rig_calibrator, the extended colmap and the lab
#      (scripts/build.sh),
#   2. renders a scene seen by a calibrated pinhole camera (the mapping
#      sequence) and by a rig (the calibration sequence; rig_calibrator_lab
#      render),
#   3. builds a metric COLMAP map from the mapping sequence (the build's
#      colmap, COLMAP 3.8's commands; aligned to the true camera positions),
#   4. calibrates the rig against the map (colmap feature_extractor, then
#      colmap rig_calibrator),
#   5. compares the calibration with the true rig.
# Prints the time of every step and where the outputs are.
#
# Usage: scripts/demo.sh [OUTPUT_DIR]   (default: demo_output/rendered/ in the
#   repository; must be new, empty or an earlier output of this demo, which
#   is replaced)
# Environment:
#   DEMO_PRESET      rig: ring5 (default), fisheye_helmet5, car_surround4,
#                    stereo_pair, or gopro_helmet5: the fisheye helmet as
#                    unsynchronized rolling-shutter cameras (GoPro-like):
#                    framesets at 5 Hz, capture-time offsets drawn in
#                    +-50 ms, line delays in 20-30 us per row, the rig at
#                    1.5 m/s turning at up to 60 deg/s on one continuous
#                    trajectory; the images are named by their capture times
#                    and grouped into framesets by
#                    --RigCalibrator.timestamp_tolerance
#   DEMO_SCENE       room (default; courtyard for gopro_helmet5, whose walk
#                    at 1.5 m/s is too fast for the room), courtyard, street
#   DEMO_SEED        0 (default)
#   DEMO_MAP_IMAGES  map images (default 60); DEMO_FRAMESETS (default 20;
#                    40 for gopro_helmet5: 8 s of its walk)
#   DEMO_CAMERA_MODEL  --RigCalibrator.camera_model: auto (default, the
#                    command's default), "true" (the rendered rig's true
#                    models), or any value the option takes
#   DEMO_CALIBRATION_OPTIONS  more options of `colmap rig_calibrator`,
#                    split at spaces, e.g. "--RigCalibrator.time_offsets 1
#                    --RigCalibrator.rolling_shutter 1"
#   DEMO_SKIP_BUILD  1: use the built tree as it is
#   RIG_CALIBRATOR_BUILD_DIR, COLMAP, MAP_*, RIG_*: see scripts/build.sh,
#   scripts/build_map.sh and scripts/calibrate_rig.sh
set -euo pipefail

log_tag=demo
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
out="${1:-$repo/demo_output/rendered}"
preset="${DEMO_PRESET:-ring5}"
default_scene=room
[[ "$preset" != gopro_helmet5 ]] || default_scene=courtyard
scene="${DEMO_SCENE:-$default_scene}"
seed="${DEMO_SEED:-0}"
num_map_images="${DEMO_MAP_IMAGES:-60}"
default_framesets=20
[[ "$preset" != gopro_helmet5 ]] || default_framesets=40
num_framesets="${DEMO_FRAMESETS:-$default_framesets}"
camera_model="${DEMO_CAMERA_MODEL:-auto}"
read -r -a calibration_options <<< "${DEMO_CALIBRATION_OPTIONS:-}"
# A folder this demo wrote before (it holds the marker file) is replaced; any
# other non-empty folder is left alone.
marker=".rig_calibrator_demo"
if [[ -e "$out" && -n "$(ls -A "$out" 2>/dev/null)" ]]; then
  [[ -f "$out/$marker" ]] ||
    die "$out exists, is not empty and was not written by this demo; remove it or give another OUTPUT_DIR"
  echo "[demo] replacing the previous demo output in $out"
  find "$out" -mindepth 1 -delete
fi
out="$(mkdir -p "$out" && cd "$out" && pwd)"
touch "$out/$marker"

demo_start=$SECONDS

if [[ "${DEMO_SKIP_BUILD:-0}" != 1 ]]; then
  run_step "build" bash "$repo/scripts/build.sh"
fi
# shellcheck source=find_colmap.sh
source "$repo/scripts/find_colmap.sh"
[[ -x "$rig_calibrator_lab" ]] ||
  die "no $rig_calibrator_lab: build it (scripts/build.sh) or set RIG_CALIBRATOR_BUILD_DIR"

# gopro_helmet5: fisheye_helmet5 with the time model (the options of
# `rig_calibrator_lab render`, as `synthetic` takes them).
time_model=()
if [[ "$preset" == gopro_helmet5 ]]; then
  preset=fisheye_helmet5
  time_model=(--frameset_rate_hz 5 --speed_m_s 1.5 --max_turn_rate_deg_s 60
              --max_time_offset_ms 50 --line_delay_us 20,30)
fi

dataset="$out/dataset"
run_step "render ($preset, $scene${time_model:+, time model})" \
  "$rig_calibrator_lab" render \
  --preset "$preset" --scene "$scene" --seed "$seed" \
  --num_map_images "$num_map_images" --num_framesets "$num_framesets" \
  "${time_model[@]}" --output_path "$dataset"

truth="$dataset/ground_truth"
map_params=$(awk '!/^#/ { print $4 }' "$truth/map_camera.txt")
true_models=$(awk '$1 == "camera_models" { print $2 }' "$truth/dataset.txt")
[[ -n "$map_params" && -n "$true_models" ]] || die "incomplete ground truth in $truth"
[[ "$camera_model" != true ]] || camera_model="$true_models"
# With a time model the rig images have time stamps for names (ns): the
# tolerance the renderer gives groups them into framesets.
grouping=()
tolerance=$(awk '$1 == "timestamp_tolerance_ns" { print $2 }' "$truth/dataset.txt")
[[ -z "$tolerance" ]] || grouping=(--RigCalibrator.timestamp_tolerance "$tolerance")

# Fewer features and a short matching window keep the demo fast: neighbours
# in the rendered sequence share thousands of inlier matches.
run_step "map (colmap)" env MAP_MAX_FEATURES="${MAP_MAX_FEATURES:-2048}" \
  MAP_OVERLAP="${MAP_OVERLAP:-5}" bash "$repo/scripts/build_map.sh" \
  "$dataset/map_images" "$out/map" "$truth/map_image_positions.txt" "$map_params"

# The camera models are chosen by the calibration (auto) unless
# DEMO_CAMERA_MODEL says otherwise.
run_step "calibration (colmap + rig_calibrator)" \
  bash "$repo/scripts/calibrate_rig.sh" "$out/map/database.db" "$out/map/sparse/0" \
  "$dataset/rig_images" "$out/rig" --RigCalibrator.camera_model "$camera_model" \
  "${grouping[@]}" "${calibration_options[@]}"

run_step "evaluation" "$colmap_extended" rig_calibrator evaluate \
  --reference_path "$truth/rig_config.json" \
  --calibration_path "$out/rig/calibration"

# One image folder for COLMAP's GUI: the model names the map images
# "map_000000.png" and the rig images "cam0/000000.png".
mkdir -p "$out/all_images"
ln -s "$dataset"/map_images/* "$out/all_images/"
ln -s "$dataset"/rig_images/* "$out/all_images/"

print_timings "$demo_start"
cat << INFO

[demo] outputs in $out:
  dataset/map_images, dataset/rig_images  the rendered images
  dataset/ground_truth                    the true rig (rig_config.json), poses
                                          (COLMAP text models map_model/ and
                                          rig_model/), map camera
  map/sparse/0, map/database.db           the metric COLMAP map (aligned to
                                          the true camera positions)
  rig/calibration                         the calibration: COLMAP model (map +
                                          rig images), rig_config.json,
                                          rigs/frames, camchain.yaml,
                                          calibration_summary.json
  rig/database.db                         map + rig image features
  all_images                              links to every image, for the GUI

Open the calibrated model in COLMAP (a build with the GUI, e.g. Debian's
colmap package; COLMAP >= 3.12 also reads the rigs/frames files):
  colmap gui --database_path $out/rig/database.db \\
             --image_path $out/all_images \\
             --import_path $out/rig/calibration
INFO
