#!/usr/bin/env bash
# End-to-end test of the time model on rendered images (ctest:
# gopro_helmet_e2e, label e2e): the GoPro-like helmet of scripts/demo.sh
# (DEMO_PRESET=gopro_helmet5: five fisheye cameras, unsynchronized by
# offsets drawn in +-50 ms, rolling shutters of 20-30 us per row, framesets
# at 5 Hz, the rig walking at 1.5 m/s and turning at up to 60 deg/s through
# the courtyard), rendered, mapped by colmap and calibrated from SIFT
# features with the command's defaults (time_offsets and rolling_shutter
# auto), the lens models given (OPENCV_FISHEYE, the true ones; `auto` picks
# models with fewer distortion terms on these data, docs/time_model.md).
# Then the same rig rendered synchronized with global shutters (the same
# trajectory, map images byte-identical) is calibrated against the same map
# with the same options. Checks:
#   1. the time model was kept, every offset within 0.5 ms and every line
#      delay within 5 % of the truth (tests/e2e/check_time_model.py);
#   2. the rig and intrinsics as accurate as the synchronized run's: the
#      worst camera's rotation, centre, focal length and principal point
#      errors (colmap rig_calibrator evaluate) within 1.25 times the
#      synchronized run's, or within the larger of 0.005 deg, 0.5 mm,
#      0.01 % and 0.05 px and the time model's own 1-sigma (its worst
#      camera's, from the summary) of it: one run's error spreads by its
#      sigma, and the COLMAP map differs from run to run (the synchronized
#      rotation error was 0.013 deg in one run, 0.020 deg in another);
#   3. the outputs agree with the summary (check_calibration_outputs).
#
# Usage: tests/e2e/gopro_helmet_e2e.sh BUILD_DIR [WORK_DIR]
#   BUILD_DIR  the build tree: colmap, rig_calibrator_lab and
#              tests/check_calibration_outputs
#   WORK_DIR   scratch folder (default: a fresh temporary folder, removed on
#              success)
set -euo pipefail

[[ $# -ge 1 ]] || { echo "usage: $0 BUILD_DIR [WORK_DIR]" >&2; exit 2; }
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "$1" && pwd)"
work="${2:-$(mktemp -d)}"
fail() { echo "[gopro_e2e] FAILED: $*" >&2; echo "[gopro_e2e] outputs kept in $work" >&2; exit 1; }

colmap="$build/colmap"
lab="$build/rig_calibrator_lab"
checker="$build/tests/check_calibration_outputs"
for tool in "$colmap" "$lab" "$checker"; do
  [[ -x "$tool" ]] || fail "no $tool: build the project first"
done
models=cam0:OPENCV_FISHEYE,cam1:OPENCV_FISHEYE,cam2:OPENCV_FISHEYE,cam3:OPENCV_FISHEYE,cam4:OPENCV_FISHEYE
num_framesets=40

start=$SECONDS
mkdir -p "$work"
demo="$work/demo"
status=0
COLMAP="$colmap" DEMO_SKIP_BUILD=1 RIG_CALIBRATOR_BUILD_DIR="$build" \
  DEMO_PRESET=gopro_helmet5 DEMO_FRAMESETS=$num_framesets DEMO_CAMERA_MODEL=true \
  bash "$repo/scripts/demo.sh" "$demo" > "$work/demo.log" 2>&1 || status=$?
[[ "$status" -eq 0 ]] || fail "the demo pipeline (log: $work/demo.log)"
truth="$demo/dataset/ground_truth"
grep -qx "camera_models $models" "$truth/dataset.txt" ||
  fail "the rendered helmet's models are not $models ($truth/dataset.txt)"
echo "[gopro_e2e] demo: $((SECONDS - start)) s"

# The synchronized twin: the same walk, offsets and line delays 0.
sync="$work/synchronized"
mkdir -p "$sync"
"$lab" render --preset fisheye_helmet5 --scene courtyard --seed 0 \
  --num_map_images 60 --num_framesets $num_framesets --frameset_rate_hz 5 \
  --speed_m_s 1.5 --max_turn_rate_deg_s 60 \
  --camera_time_offsets_ms 0,0,0,0,0 --camera_line_delays_us 0,0,0,0,0 \
  --output_path "$sync/dataset" > "$work/synchronized_render.log" 2>&1 ||
  fail "rendering the synchronized twin (log: $work/synchronized_render.log)"
cmp -s "$sync/dataset/map_images/map_000000.png" "$demo/dataset/map_images/map_000000.png" ||
  fail "the synchronized twin's map images differ from the demo's"
tolerance=$(awk '$1 == "timestamp_tolerance_ns" { print $2 }' "$truth/dataset.txt")
COLMAP="$colmap" bash "$repo/scripts/calibrate_rig.sh" "$demo/map/database.db" \
  "$demo/map/sparse/0" "$sync/dataset/rig_images" "$sync/rig" \
  --RigCalibrator.camera_model "$models" \
  --RigCalibrator.timestamp_tolerance "$tolerance" > "$work/synchronized_calibration.log" 2>&1 ||
  fail "calibrating the synchronized twin (log: $work/synchronized_calibration.log)"

# 1. The time model.
/usr/bin/python3 "$repo/tests/e2e/check_time_model.py" \
  "$demo/rig/calibration/calibration_summary.json" "$truth/time_model.json" 0.5 5 ||
  fail "the capture-time model is not within 0.5 ms and 5 %"

# 2. Accuracy against the synchronized twin's.
for run in demo synchronized; do
  folder="$work/$run"
  "$colmap" rig_calibrator evaluate --reference_path "$folder/dataset/ground_truth/rig_config.json" \
    --calibration_path "$folder/rig/calibration" --output_path "$work/errors_$run.json" \
    > "$work/evaluate_$run.log" || fail "evaluate ($run)"
done
/usr/bin/python3 - "$work/errors_demo.json" "$work/errors_synchronized.json" \
  "$demo/rig/calibration/calibration_summary.json" << 'PYTHON' || fail "the time model's rig is less accurate than 1.25 times the synchronized one's"
import json, math, sys
timed, synchronized = (json.load(open(path))["cameras"] for path in sys.argv[1:3])

# The time model's worst 1-sigma per quantity over its cameras.
def sigmas(camera):
    u, params = camera["uncertainty"], camera["params"]
    single_focal = camera["model"].startswith("SIMPLE_") or camera["model"] in (
        "RADIAL", "RADIAL_FISHEYE")
    c = 1 if single_focal else 2
    return {"rotation_deg": u["rotation_stddev_deg"],
            "center_error": math.hypot(*u["center_in_rig_stddev"]),
            "focal_error_percent": 100 * u["params_stddev"][0] / params[0],
            "principal_point_error_px": math.hypot(u["params_stddev"][c],
                                                   u["params_stddev"][c + 1])}
summary_cameras = json.load(open(sys.argv[3]))["cameras"]
worst_sigma = {}
for camera in summary_cameras:
    if not camera.get("uncertainty", {}).get("determined"):
        continue
    for key, value in sigmas(camera).items():
        worst_sigma[key] = max(worst_sigma.get(key, 0.0), value)
failed = False
for key, floor, unit in (("rotation_deg", 0.005, "deg"), ("center_error", 0.0005, "m"),
                         ("focal_error_percent", 0.01, "%"),
                         ("principal_point_error_px", 0.05, "px")):
    worst_timed = max(camera[key] for camera in timed)
    worst_synchronized = max(camera[key] for camera in synchronized)
    margin = max(floor, worst_sigma.get(key, 0.0))
    bound = max(1.25 * worst_synchronized, worst_synchronized + margin)
    ok = worst_timed <= bound
    failed |= not ok
    print(f"[gopro_e2e] {key}: time model {worst_timed:.4g} {unit}, synchronized "
          f"{worst_synchronized:.4g} {unit} (ratio {worst_timed / worst_synchronized:.2f}, "
          f"the time model's sigma {worst_sigma.get(key, 0.0):.4g}, bound {bound:.4g})"
          f"{'' if ok else ' FAILED'}")
sys.exit(1 if failed else 0)
PYTHON

# 3. The outputs.
"$checker" "$demo/rig/calibration" || fail "the outputs of $demo/rig/calibration disagree"
[[ $# -ge 2 ]] || rm -rf "$work"
echo "[gopro_e2e] passed ($((SECONDS - start)) s)"
