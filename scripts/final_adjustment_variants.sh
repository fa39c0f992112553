#!/usr/bin/env bash
# The final bundle adjustment's variants on one map and one set of 2D-3D
# correspondences (those of a demo run), each calibrated with rig_calibrator
# and evaluated against the demo's ground truth; prints a table (accuracy of
# the worst camera, mean reprojection error of the output model, time).
#
# Usage: scripts/final_adjustment_variants.sh [DEMO_OUTPUT [RESULTS_DIR]]
#   DEMO_OUTPUT  a finished scripts/demo.sh output (default demo_output/rendered)
#   RESULTS_DIR  new or empty folder for the runs (default: a temporary one,
#                removed at the end)
# Variants (options of rig_calibrator):
#   points fixed        --RigCalibrator.refine_points 0
#   rig observations    --RigCalibrator.refine_points 1 --RigCalibrator.map_observations 0
#   map observations    ... --RigCalibrator.map_observations 1 --RigCalibrator.refine_map 0
#   refine_map          ... --RigCalibrator.refine_map 1 (the default)
#   refine_map + intr.  ... --RigCalibrator.refine_map_intrinsics 1
set -euo pipefail

log_tag=final_adjustment_variants
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
check_arguments 0 2 "$@"
demo="${1:-$repo/demo_output/rendered}"
correspondences="$demo/rig/calibration/correspondences.txt"
map="$demo/map/sparse/0"
truth="$demo/dataset/ground_truth"
[[ -f "$correspondences" && -d "$map" && -f "$truth/rig_config.json" ]] ||
  die "$demo is not a finished demo output (run scripts/demo.sh first)"
[[ -x "$rig_calibrator" ]] || die "no $rig_calibrator; build first (scripts/build.sh)"
camera_models=$(awk '$1 == "camera_models" { print $2 }' "$truth/dataset.txt")
if [[ $# -ge 2 ]]; then
  results="$2"
  [[ ! -e "$results" || -z "$(ls -A "$results")" ]] || die "$results is not empty"
  mkdir -p "$results"
else
  results="$(mktemp -d)"
  trap 'rm -rf "$results"' EXIT
fi

variants=(
  "points fixed|--RigCalibrator.refine_points 0"
  "rig observations|--RigCalibrator.refine_points 1 --RigCalibrator.map_observations 0"
  "map observations|--RigCalibrator.map_observations 1 --RigCalibrator.refine_map 0"
  "refine_map (default)|--RigCalibrator.refine_map 1"
  "refine_map + map intrinsics|--RigCalibrator.refine_map 1 --RigCalibrator.refine_map_intrinsics 1"
)
rows=()
for variant in "${variants[@]}"; do
  name="${variant%%|*}"
  read -r -a options <<< "${variant#*|}"
  out="$results/$(echo "$name" | tr -c 'a-z0-9\n' '_')"
  echo "[$log_tag] $name: ${options[*]}"
  start=$SECONDS
  "$rig_calibrator" --correspondences_path "$correspondences" --input_path "$map" \
    --output_path "$out" --RigCalibrator.camera_model "$camera_models" "${options[@]}" \
    > "$out.log" 2>&1 || die "rig_calibrator failed for '$name' (log: $out.log)"
  seconds=$((SECONDS - start))
  "$rig_calibrator" evaluate --reference_path "$truth/rig_config.json" \
    --calibration_path "$out" --output_path "$out.errors.json" > /dev/null ||
    die "evaluate failed for '$name'"
  rows+=("$(python3 - "$name" "$seconds" "$out.errors.json" "$out/calibration_summary.json" "$out.log" <<'PY'
import json, re, sys
name, seconds, errors, summary, log = sys.argv[1:]
cameras = json.load(open(errors))["cameras"]
s = json.load(open(summary))
rot = max(c["rotation_deg"] for c in cameras)
center = max(c["center_error"] for c in cameras) * 1000
focal = max(c["focal_error_percent"] for c in cameras)
proj = max(c["mean_projection_diff_px"] for c in cameras)
ba = s["timings_s"].get("Final bundle adjustment", float("nan"))
m = s.get("map_images") or {}
rms = re.findall(r"^  RMS ([0-9.]+) -> ([0-9.]+) px over", open(log).read(), re.M)
print(f"| {name} | {rot:.4f} | {center:.3f} | {focal:.4f} | {proj:.3f} | "
      f"{float(rms[-1][1]) if rms else float('nan'):.3f} | "
      f"{m.get('input_mean_error_px', float('nan')):.3f} -> "
      f"{m.get('output_mean_error_px', float('nan')):.3f} | {ba:.1f} | {seconds} |")
PY
)")
done
echo
echo "| final adjustment | worst rotation (deg) | worst center (mm) | worst focal (%) | worst mean projection difference (px) | rig RMS (px) | map images' mean error, input -> output (px) | final BA (s) | run (s) |"
echo "|---|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
