#!/usr/bin/env bash
# The real-data check: rig_calibrator with its default options on real maps,
# every camera's error against a reference next to the σ it reports.
#
#   1. infrascal_ring (a real COLMAP map of a real 5-camera ring, 19
#      timestamps; CC BY-SA 4.0, see its README): for every split in
#      REAL_DATA_SPLITS, the held-out timestamps' images and observations are
#      removed from the map and given back as 2D-3D correspondences
#      (scripts/real_data_tools.py split); the reference is the map's own
#      rig (mean of the other timestamps' per-timestamp rigs, with its
#      standard error) and the map's intrinsics. rig_calibrator then runs
#      with its defaults (camera_model auto, refine_map, uncertainty) on the
#      reduced map and the correspondences.
#   2. the EuRoC V1_01 stereo excerpt (REAL_DATA_EUROC=1, the default):
#      scripts/euroc_check.sh with its default camera model (auto), compared
#      with the dataset's pattern calibration (both its calibrations: against
#      the self-calibrated map, and against the map with the reference
#      intrinsics).
# Per case and camera it prints the rotation and centre error against the
# reference, the reported σ, the reference's standard error and
# z = |error| / sqrt(σ² + reference²), the focal length's error and z, the
# principal point's (not judged: the ring's map held it at the centre), and
# the verdict: within 3 σ, flagged (a warning or error names the camera), or
# off and silent / not calibrated (the check fails, exit 1).
#
# Usage: scripts/real_data_check.sh [OUTPUT_DIR]   (default:
#          demo_output/real_data in the repository; replaced if it holds an
#          earlier output of this script)
# Environment:
#   REAL_DATA_DIR     the shared data folder (default: ../shared/data beside
#                     the repository)
#   REAL_DATA_SPLITS  ring splits (default "mod:2:1 mod:2:0 mod:3:0 mod:3:1
#                     mod:3:2"; see real_data_tools.py)
#   REAL_DATA_EUROC   1 (default): also the EuRoC pair (builds a COLMAP map,
#                     a few minutes); 0: the ring only
#   REAL_DATA_OPTIONS extra rig_calibrator options for the ring runs (default
#                     none: the defaults are what is checked)
#   RIG_CALIBRATOR_BUILD_DIR: see scripts/build.sh (built if missing)
set -euo pipefail

log_tag=real_data
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
check_arguments 0 1 "$@"
out="${1:-$repo/demo_output/real_data}"
data="${REAL_DATA_DIR:-$(dirname "$repo")/shared/data}"
splits="${REAL_DATA_SPLITS:-mod:2:1 mod:2:0 mod:3:0 mod:3:1 mod:3:2}"
with_euroc="${REAL_DATA_EUROC:-1}"
read -r -a extra_options <<< "${REAL_DATA_OPTIONS:-}"
marker=".real_data_check_output"
python=/usr/bin/python3
tools="$repo/scripts/real_data_tools.py"

[[ -f "$data/infrascal_ring/map/images.txt" ]] ||
  die "no $data/infrascal_ring/map/images.txt: set REAL_DATA_DIR to the shared data folder"
"$python" -c "import numpy" 2> /dev/null ||
  die "$python with numpy is needed (scripts/setup_deps.sh installs python3-numpy)"
if [[ -e "$out" && -n "$(ls -A "$out" 2> /dev/null)" ]]; then
  [[ -f "$out/$marker" ]] || die "$out exists and is not an output of this script"
  rm -rf "$out"
fi
mkdir -p "$out"
touch "$out/$marker"
[[ -x "$rig_calibrator" ]] || bash "$repo/scripts/build.sh"
table="$out/table.jsonl"
: > "$table"
total_start=$SECONDS

# One ring split: case, calibration with the defaults, comparison.
ring_case() {
  local split="$1" dir="$out/ring_${1//:/_}"
  mkdir -p "$dir"
  "$python" "$tools" split "$data/infrascal_ring/map" "$dir" "$split" || return 1
  local status=0
  "$rig_calibrator" --correspondences_path "$dir/correspondences.txt" \
    --input_path "$dir/map" --output_path "$dir/calibration" \
    "${extra_options[@]}" > "$dir/rig_calibrator.log" 2>&1 || status=$?
  echo "rig_calibrator exit $status (log: $dir/rig_calibrator.log)"
  sed -n '/^== Diagnostics/,/^$/p' "$dir/rig_calibrator.log" | head -n 30
  if [[ ! -f "$dir/calibration/calibration_summary.json" ]]; then
    tail -n 20 "$dir/rig_calibrator.log" >&2
    return 1
  fi
  "$python" "$tools" compare "$dir/reference.json" \
    "$dir/calibration/calibration_summary.json" --label "ring $split" \
    --table "$table"
}
for split in $splits; do
  run_step "ring, held out $split" ring_case "$split"
done

euroc_cases() {
  local dir="$out/euroc"
  EUROC_DIR="$data/euroc_v1_01_micro" EUROC_SKIP_BUILD=1 \
    bash "$repo/scripts/euroc_check.sh" "$dir" > "$out/euroc.log" 2>&1 ||
    { tail -n 30 "$out/euroc.log" >&2; return 1; }
  "$python" "$tools" euroc-reference \
    "$data/euroc_v1_01_micro/mav0/cam0/sensor.yaml" \
    "$data/euroc_v1_01_micro/mav0/cam1/sensor.yaml" "$out/euroc_reference.json"
  echo "self-calibrated map:"
  "$python" "$tools" compare "$out/euroc_reference.json" \
    "$dir/rig/calibration/calibration_summary.json" --label "euroc" \
    --table "$table"
  if [[ -f "$dir/diagnostic/calibration/calibration_summary.json" ]]; then
    echo "map with the reference intrinsics:"
    "$python" "$tools" compare "$out/euroc_reference.json" \
      "$dir/diagnostic/calibration/calibration_summary.json" \
      --label "euroc, reference-intrinsics map" --table "$table"
  fi
}
if [[ "$with_euroc" == 1 ]]; then
  run_step "EuRoC V1_01 stereo pair" euroc_cases
fi

print_timings "$total_start"
echo
echo "[$log_tag] === verdict over every case (rows: $table)"
"$python" "$tools" verdicts "$table"
