#!/usr/bin/env bash
# Same input, same result, on a real COLMAP database (called by
# rendered_rig_e2e.sh with the demo's folders; the README's determinism
# statement quotes what it prints):
#   1. two runs on 1 thread, into folders with names of different lengths:
#      every output file identical byte for byte (timings.json, the wall times,
#      left out);
#   2. 1 thread against 2 threads, binary and text outputs: every output
#      file identical byte for byte (every stage, the bundle adjustments
#      included, gives the same result on any thread count);
#   3. another seed: within the e2e test's accuracy bounds of the truth
#      (0.5 degrees, 2 cm, 1 % focal length), and its difference to seed 0.
#
# Usage: tests/e2e/determinism_e2e.sh BUILD_DIR DATABASE RIG_IMAGES MAP_MODEL
#            TRUTH_DIR WORK_DIR [rig_calibrator options...]
#   DATABASE    COLMAP database with the map's and the rig images' features
#   RIG_IMAGES  the rig images (cam0/, cam1/, ...)
#   MAP_MODEL   the map (COLMAP sparse model folder)
#   TRUTH_DIR   ground truth with rig_config.json
#   WORK_DIR    created; gets one folder per run
set -euo pipefail

[[ $# -ge 6 ]] || {
  echo "usage: $0 BUILD_DIR DATABASE RIG_IMAGES MAP_MODEL TRUTH_DIR WORK_DIR [options...]" >&2
  exit 2
}
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "$1" && pwd)"
database="$2"
rig_images="$3"
map_model="$4"
truth="$5"
work="$6"
shift 6
options=("$@")  # passed to every run
fail() { echo "[determinism] FAILED: $*" >&2; echo "[determinism] outputs kept in $work" >&2; exit 1; }

rig_calibrator="$build/rig_calibrator"
compare="$repo/tests/e2e/compare_outputs.py"
[[ -x "$rig_calibrator" ]] || fail "no $rig_calibrator: build the project first"
mkdir -p "$work"

# calibrate NAME THREADS SEED OUTPUT_TYPE [OPTIONS...]: one database run into
# $work/NAME.
calibrate() {
  local start=$SECONDS name="$1" threads="$2" seed="$3" type="$4"
  shift 4
  "$rig_calibrator" --database_path "$database" --image_path "$rig_images" \
    --input_path "$map_model" --output_path "$work/$name" \
    --RigCalibrator.num_threads "$threads" --RigCalibrator.seed "$seed" \
    --output_type "$type" "${options[@]}" "$@" > "$work/$name.log" 2>&1 ||
    fail "rig_calibrator ($name; log: $work/$name.log)"
  echo "[determinism] $name: $threads thread(s), seed $seed, $type $*: $((SECONDS - start)) s"
}

# 1. Bit for bit on 1 thread, whatever the output folder is called.
long_name=run_on_one_thread_again_into_a_folder_with_a_much_longer_name
calibrate bin_1thread 1 0 BIN
calibrate "$long_name" 1 0 BIN
python3 "$compare" "$work/bin_1thread" "$work/$long_name" --ignore timings.json ||
  fail "two runs on 1 thread differ"
echo "[determinism] two runs on 1 thread: every output file identical"

# 2. 1 thread against 2 threads: bit for bit, binary and text outputs.
calibrate bin_2threads 2 0 BIN
python3 "$compare" "$work/bin_1thread" "$work/bin_2threads" --ignore timings.json ||
  fail "1 and 2 threads differ"
echo "[determinism] 1 and 2 threads: every output file identical"
calibrate txt_1thread 1 0 TXT
calibrate txt_2threads 2 0 TXT
python3 "$compare" "$work/txt_1thread" "$work/txt_2threads" --ignore timings.json ||
  fail "text outputs: 1 and 2 threads differ"
echo "[determinism] text outputs, 1 and 2 threads: every output file identical"

# 3. Another seed: other trees, other RANSAC samples, the same accuracy.
calibrate bin_seed1 2 1 BIN
max_of() {
  grep -o "\"$1\": *[-0-9.eE+]*" "$2" | awk -F: '
    { v = $2 + 0; if (NR == 1 || v > m) m = v }
    END { if (NR == 0) exit 1; print m }'
}
for reference in truth seed0; do
  errors="$work/seed1_vs_$reference.json"
  reference_path="$truth/rig_config.json"
  [[ "$reference" == seed0 ]] && reference_path="$work/bin_1thread/rig_config.json"
  "$rig_calibrator" evaluate --reference_path "$reference_path" \
    --calibration_path "$work/bin_seed1" --output_path "$errors" > /dev/null ||
    fail "evaluate seed 1 against $reference_path"
  rotation=$(max_of rotation_deg "$errors") || fail "no rotation errors in $errors"
  center=$(max_of center_error "$errors") || fail "no center errors in $errors"
  focal=$(max_of focal_error_percent "$errors") || fail "no focal errors in $errors"
  echo "[determinism] seed 1 against $reference: worst rotation $rotation deg, center $center m, focal $focal %"
done
errors="$work/seed1_vs_truth.json"
awk -v r="$(max_of rotation_deg "$errors")" -v c="$(max_of center_error "$errors")" \
  -v f="$(max_of focal_error_percent "$errors")" \
  'BEGIN { exit !(r < 0.5 && c < 0.02 && f < 1.0) }' ||
  fail "seed 1: errors above the bounds (0.5 deg, 0.02 m, 1 %)"
echo "[determinism] passed"
