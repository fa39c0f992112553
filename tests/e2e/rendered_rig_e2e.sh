#!/usr/bin/env bash
# End-to-end test on rendered images (ctest: rendered_rig_e2e, label e2e):
#   1. renders a small ring5 dataset in the room, builds a metric map and
#      calibrates the rig against it with the default options, camera
#      models chosen by auto (scripts/demo.sh: build_map.sh, then
#      calibrate_rig.sh with the database), every step through the build's
#      extended colmap: `colmap feature_extractor`, `colmap mapper`, ...,
#      `colmap rig_calibrator` (checked in the scripts' logs);
#   2. accuracy: every camera within 0.5 degrees, 2 cm and 1 % focal length
#      of the ground truth (colmap rig_calibrator evaluate);
#   3. outputs: `colmap model_analyzer` reads the model, and
#      check_calibration_outputs checks that the model, rigs/frames,
#      rig_config.json and camchain.yaml agree with calibration_summary.json
#      (image poses = cam_from_rig * rig_from_world to 1e-9), and that it
#      rejects a rig_config.json that is not the calibration's;
#   4. re-run: calibrating from the correspondences.txt the run wrote
#      reproduces the run (same cameras and images, intrinsics and poses
#      within 1e-6 relative).
#
# Usage: tests/e2e/rendered_rig_e2e.sh BUILD_DIR [WORK_DIR]
#   BUILD_DIR  the build tree: colmap and tests/check_calibration_outputs
#   WORK_DIR   scratch folder (default: a fresh temporary folder, removed on
#              success)
# COLMAP in the environment is ignored: the test is of the build's colmap.
set -euo pipefail

[[ $# -ge 1 ]] || { echo "usage: $0 BUILD_DIR [WORK_DIR]" >&2; exit 2; }
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "$1" && pwd)"
work="${2:-$(mktemp -d)}"
fail() { echo "[e2e] FAILED: $*" >&2; echo "[e2e] outputs kept in $work" >&2; exit 1; }

colmap="$build/colmap"
checker="$build/tests/check_calibration_outputs"
[[ -x "$colmap" ]] || fail "no $colmap: build the project first"
[[ -x "$checker" ]] || fail "no $checker: build the target check_calibration_outputs"

start=$SECONDS
mkdir -p "$work"
demo_log="$work/demo.log"
status=0
COLMAP="$colmap" DEMO_SKIP_BUILD=1 RIG_CALIBRATOR_BUILD_DIR="$build" \
  DEMO_PRESET=ring5 DEMO_SCENE=room DEMO_MAP_IMAGES=40 DEMO_FRAMESETS=8 \
  MAP_OVERLAP=4 RIG_MAX_FEATURES=2048 bash "$repo/scripts/demo.sh" "$work/demo" 2>&1 |
  tee "$demo_log" || status=${PIPESTATUS[0]}
[[ "$status" -eq 0 ]] || fail "the demo pipeline"
demo_seconds=$((SECONDS - start))
# The map's and the calibration's COLMAP steps and the calibration ran
# through the build's colmap.
grep -qxF "[build_map] colmap: $colmap" "$demo_log" ||
  fail "build_map.sh did not run $colmap (log: $demo_log)"
grep -qxF "[calibrate_rig] colmap: $colmap; calibration: $colmap rig_calibrator" "$demo_log" ||
  fail "calibrate_rig.sh did not run $colmap and $colmap rig_calibrator (log: $demo_log)"
echo "[e2e] every COLMAP step and the calibration ran through $colmap"
calibration="$work/demo/rig/calibration"
truth="$work/demo/dataset/ground_truth"

# 2. Accuracy against the ground truth.
errors="$work/errors.json"
"$colmap" rig_calibrator evaluate --reference_path "$truth/rig_config.json" \
  --calibration_path "$calibration" --output_path "$errors" \
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

# 3. The outputs, read by COLMAP (the build's colmap model_analyzer is
# COLMAP's) and by the project's readers.
"$colmap" model_analyzer --path "$calibration" > "$work/model_analyzer.log" 2>&1 ||
  fail "colmap model_analyzer cannot read $calibration (log: $work/model_analyzer.log)"
registered=$(sed -n 's/.*Registered images: *\([0-9]*\).*/\1/p' "$work/model_analyzer.log" | head -n 1)
map_registered=$("$colmap" model_analyzer --path "$work/demo/map/sparse/0" 2>&1 |
  sed -n 's/.*Registered images: *\([0-9]*\).*/\1/p' | head -n 1)
echo "[e2e] colmap model_analyzer: ${registered:-?} registered images (map: ${map_registered:-?})"
[[ -n "$registered" && -n "$map_registered" && "$registered" -gt "$map_registered" ]] ||
  fail "colmap model_analyzer finds no rig image in the calibrated model"
"$checker" "$calibration" || fail "the outputs of $calibration disagree"
"$build/tests/check_output_model" "$calibration" "$work/demo/map/sparse/0" || fail "the output model's errors are not its own"
# The checker itself must see a wrong file: the true rig's rig_config.json in
# place of the calibrated one (they differ by the calibration error).
tampered="$work/tampered"
cp -r "$calibration" "$tampered"
cp "$truth/rig_config.json" "$tampered/rig_config.json"
if "$checker" "$tampered" > "$work/tampered.log" 2>&1 ||
    ! grep -q "rig_config.json = summary: .*FAILED" "$work/tampered.log"; then
  fail "check_calibration_outputs misses a rig_config.json that is not the calibration's (log: $work/tampered.log)"
fi
echo "[e2e] check_calibration_outputs rejects the true rig's rig_config.json in place of the calibration's"

# 4. A re-run from the correspondence file the run wrote, with the same map
# and options (the demo's default, camera_model auto), reproduces the run
# without the database.
rerun="$work/rerun"
start=$SECONDS
"$colmap" rig_calibrator --correspondences_path "$calibration/correspondences.txt" \
  --input_path "$work/demo/map/sparse/0" --output_path "$rerun" \
  > "$work/rerun.log" 2>&1 ||
  fail "the re-run from $calibration/correspondences.txt (log: $work/rerun.log)"
echo "[e2e] re-run from correspondences.txt: $((SECONDS - start)) s"
"$checker" "$rerun" "$calibration" ||
  fail "the re-run from correspondences.txt does not reproduce the run"

bash "$repo/tests/e2e/determinism_e2e.sh" "$build" "$work/demo/rig/database.db" "$work/demo/dataset/rig_images" "$work/demo/map/sparse/0" "$truth" "$work/determinism" || fail "determinism (tests/e2e/determinism_e2e.sh)"
[[ $# -ge 2 ]] || rm -rf "$work"
echo "[e2e] passed (demo pipeline $demo_seconds s)"
