#!/usr/bin/env bash
# A quick demo without images: sets up and builds, writes a synthetic 5-camera
# ring (2D-3D correspondences with noise, outliers and missing images, exact
# ground truth; rig_calibrator_lab synthetic), calibrates it with rig_calibrator
# and evaluates the result.
#   bash scripts/demo_synthetic.sh [OUTPUT_DIR] [PRESET]
# PRESET: ring5 (default), fisheye_helmet5, car_surround4, stereo_pair.
set -euo pipefail

log_tag=demo_synthetic
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
out="${1:-$repo/demo_output/synthetic}"
preset="${2:-ring5}"

bash "$repo/scripts/build.sh"
mkdir -p "$out"

echo "== Synthetic dataset ($preset) in $out/data"
log="$(mktemp)"
"$rig_calibrator_lab" synthetic --preset "$preset" --output_path "$out/data" \
  --overwrite 1 | tee "$log"
models="$(grep -o 'camera_model [^ ]*' "$log" | cut -d' ' -f2)"
rm -f "$log"

# The synthetic map points are exact: refining them (the default, right for
# maps that COLMAP built) would only add unknowns.
echo "== Calibration"
"$rig_calibrator" --correspondences_path "$out/data/correspondences.txt" \
  --output_path "$out/calibration" --overwrite 1 \
  --RigCalibrator.camera_model "$models" --RigCalibrator.refine_points 0

echo "== Accuracy against the ground truth"
"$rig_calibrator" evaluate --reference_path "$out/data/ground_truth/camchain.yaml" \
  --calibration_path "$out/calibration" --output_path "$out/errors.json"
echo "Outputs: $out/calibration (COLMAP model, rig files, camchain.yaml, summary);"
echo "errors: $out/errors.json"
