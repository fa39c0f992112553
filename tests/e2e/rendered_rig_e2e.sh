#!/usr/bin/env bash
# End-to-end test on rendered images: renders a small ring5 dataset in the
# room, builds a metric map with the colmap CLI, calibrates the rig against
# it and checks the calibration against the ground truth (every camera:
# rotation < 0.5 degrees, center < 2 cm, focal length < 1 %).
#
# Usage: tests/e2e/rendered_rig_e2e.sh BUILD_DIR [WORK_DIR]
#   BUILD_DIR  holds the built rig_calibrator
#   WORK_DIR   scratch folder (default: a fresh temporary folder, removed on
#              success)
set -euo pipefail

[[ $# -ge 1 ]] || { echo "usage: $0 BUILD_DIR [WORK_DIR]" >&2; exit 2; }
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "$1" && pwd)"
work="${2:-$(mktemp -d)}"
fail() { echo "[e2e] FAILED: $*" >&2; echo "[e2e] outputs kept in $work" >&2; exit 1; }

DEMO_SKIP_BUILD=1 RIG_CALIBRATOR_BUILD_DIR="$build" DEMO_PRESET=ring5 \
  DEMO_SCENE=room DEMO_MAP_IMAGES=40 DEMO_FRAMESETS=8 MAP_OVERLAP=4 \
  RIG_MAX_FEATURES=2048 bash "$repo/scripts/demo.sh" "$work/demo" ||
  fail "the demo pipeline"

errors="$work/errors.json"
"$build/rig_calibrator" evaluate \
  --reference_path "$work/demo/dataset/ground_truth/rig_config.json" \
  --calibration_path "$work/demo/rig/calibration" --output_path "$errors" \
  > /dev/null || fail "evaluate"

# The largest value of a per-camera field of the evaluation's JSON.
max_of() {
  grep -o "\"$1\": *[-0-9.eE+]*" "$errors" | awk -F: '
    { v = $2 + 0; if (NR == 1 || v > m) m = v }
    END { if (NR == 0) exit 1; print m }'
}
num_cameras=$(grep -c '"name": *"cam' "$errors" || true)
[[ "$num_cameras" -eq 5 ]] || fail "$num_cameras of 5 cameras calibrated"
rotation=$(max_of rotation_deg) || fail "no rotation errors in $errors"
center=$(max_of center_error) || fail "no center errors in $errors"
focal=$(max_of focal_error_percent) || fail "no focal errors in $errors"
echo "[e2e] max errors: rotation $rotation deg, center $center m, focal $focal %"
awk -v r="$rotation" -v c="$center" -v f="$focal" \
  'BEGIN { exit !(r < 0.5 && c < 0.02 && f < 1.0) }' ||
  fail "errors above the bounds (0.5 deg, 0.02 m, 1 %)"
[[ $# -ge 2 ]] || rm -rf "$work"
echo "[e2e] passed"
