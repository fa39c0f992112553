#!/usr/bin/env bash
# Calibrates a rig against a COLMAP map: copies the map's database (the input
# is never modified), extracts SIFT features of the rig images into the copy
# (one COLMAP camera per camera folder), then runs `colmap rig_calibrator`
# with the build's extended colmap.
#
# Usage: scripts/calibrate_rig.sh MAP_DB MAP_MODEL RIG_IMAGES OUT [rig_calibrator options...]
#   MAP_DB      the map's COLMAP 3.8 database (with its images' features)
#   MAP_MODEL   the map: a COLMAP sparse model folder
#   RIG_IMAGES  the rig images, one folder per camera (cam0/, cam1/, ...), the
#               images of a frameset with the same file name
#   OUT         created (must not exist or be empty); gets database.db (map +
#               rig features) and calibration/ (rig_calibrator's output:
#               model, rig_config.json, rigs/frames, camchain.yaml, summary)
#   options     passed to `colmap rig_calibrator`, e.g. --RigCalibrator.method 1dr
#               --RigCalibrator.camera_model OPENCV
# Environment:
#   COLMAP            colmap 3.8 binary of the feature extraction (default:
#                     build/colmap, the build's extended colmap, which also
#                     calibrates)
#   RIG_MAX_FEATURES  SIFT features per rig image (default 4096)
#   RIG_NUM_THREADS   feature extraction threads (default: all cores)
set -euo pipefail

log_tag=calibrate_rig
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

check_arguments 4 "" "$@"
map_db="$1"
map_model="$2"
rig_images="$3"
out="$4"
shift 4

# shellcheck source=find_colmap.sh
source "$repo/scripts/find_colmap.sh"
max_features="${RIG_MAX_FEATURES:-4096}"
threads="${RIG_NUM_THREADS:--1}"

[[ -f "$map_db" ]] || die "no map database $map_db"
[[ -f "$map_model/images.bin" || -f "$map_model/images.txt" ]] || die "no COLMAP model in $map_model"
[[ -d "$rig_images" ]] || die "no rig image folder $rig_images"
num_cameras=$(find "$rig_images" -mindepth 1 -maxdepth 1 -type d | wc -l)
[[ "$num_cameras" -ge 1 ]] || die "$rig_images has no camera folders (cam0/, cam1/, ...)"
if [[ -e "$out" && -n "$(ls -A "$out" 2>/dev/null)" ]]; then
  die "$out exists and is not empty; choose another OUT"
fi
mkdir -p "$out"
database="$out/database.db"
log="$out/calibrate_rig.log"
: > "$log"

start=$SECONDS
cp "$map_db" "$database"
echo "[calibrate_rig] copied the map database to $database"
echo "[calibrate_rig] colmap: $colmap; calibration: $colmap_extended rig_calibrator"
echo "[calibrate_rig] feature extraction of the rig images ($num_cameras cameras) ..."
if ! "$colmap" feature_extractor --database_path "$database" \
    --image_path "$rig_images" --ImageReader.single_camera_per_folder 1 \
    --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads "$threads" \
    --SiftExtraction.max_num_features "$max_features" >> "$log" 2>&1; then
  tail -n 20 "$log" >&2
  die "colmap feature_extractor failed (full log: $log)"
fi
echo "[calibrate_rig] feature extraction: $((SECONDS - start)) s"

start=$SECONDS
echo "[calibrate_rig] rig_calibrator ..."
status=0
"$colmap_extended" rig_calibrator --database_path "$database" --image_path "$rig_images" \
  --input_path "$map_model" --output_path "$out/calibration" "$@" 2>&1 |
  tee -a "$log" || status=${PIPESTATUS[0]}
[[ "$status" -eq 0 ]] || die "colmap rig_calibrator failed with status $status (log: $log)"
echo "[calibrate_rig] rig_calibrator: $((SECONDS - start)) s"
echo "[calibrate_rig] done: calibration in $out/calibration"
