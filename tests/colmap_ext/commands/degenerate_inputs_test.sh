#!/bin/bash
# Degenerate rigs and data through the command (issue 15), from synthetic
# correspondence files: each case checks the exit status, the message (the
# problem by name and what to do), that the inputs are unchanged (checksums)
# and that a failed run leaves no output; where a fallback exists, that it
# calibrates (rig_calibrator evaluate against the ground truth).
#
# Usage: degenerate_inputs_test.sh BUILD_DIR
set -u

BUILD_DIR=$(cd "$1" && pwd)
BIN=$BUILD_DIR/rig_calibrator
LAB=$BUILD_DIR/rig_calibrator_lab
WORK=$(mktemp -d /tmp/degenerate_inputs.XXXXXX)
trap 'rm -rf "$WORK"' EXIT

fail() {
  echo "FAILED: $*"
  exit 1
}
sums() { (cd "$1" && find . -type f | sort | xargs sha256sum); }
synthetic() {  # synthetic NAME OPTIONS...
  local name=$1
  shift
  "$LAB" synthetic --output_path "$WORK/$name" --num_framesets 15 \
    --points_per_image 200 --seed 4 "$@" >"$WORK/$name.synthetic.log" ||
    fail "synthetic $name: $(tail -2 "$WORK/$name.synthetic.log")"
}
calibrate() {  # calibrate DATA_FOLDER OUTPUT OPTIONS...
  local data=$1 output=$2
  shift 2
  "$BIN" --correspondences_path "$data/correspondences.txt" \
    --output_path "$output" --RigCalibrator.camera_model OPENCV \
    --RigCalibrator.num_threads 1 "$@" >"$output.log" 2>&1
}
# Rotation error (deg), center error (m) and focal error (%) of the worst
# camera of calibration OUTPUT against the ground truth of DATA_FOLDER.
worst_errors() {
  "$BIN" evaluate --reference_path "$1/ground_truth/camchain.yaml" \
    --calibration_path "$2" --output_path "$2.evaluation.json" \
    >"$2.evaluate.log" 2>&1 || fail "evaluate $2: $(tail -3 "$2.evaluate.log")"
  python3 - "$2.evaluation.json" <<'EOF'
import json, sys
e = json.load(open(sys.argv[1]))
m = e["max"]
print(m["rotation_deg"], m["center_error"], m["focal_error_percent"])
EOF
}
# A failed run: exit status, message, no output or temporary sibling.
expect_failure() {  # expect_failure OUTPUT MESSAGE_REGEX
  local status=$3
  [ "$status" -ne 0 ] || fail "$1: exit status 0"
  grep -q "ERROR: .*$2" "$1.log" || fail "$1: expected '$2', got: $(grep ERROR "$1.log")"
  [ ! -e "$1" ] || fail "$1 was written"
  [ -z "$(find "$(dirname "$1")" -maxdepth 1 -name ".$(basename "$1").*")" ] ||
    fail "temporary output left next to $1"
}

# 1. Two stereo pairs, forward and backward (parallel and anti-parallel
# principal axes): diagnosed by name, calibrated by the rd_ra fallback.
synthetic pairs --preset stereo_pair --stereo_num_pairs 2 --stereo_alternate_facing 1
before=$(sums "$WORK/pairs")
calibrate "$WORK/pairs" "$WORK/pairs_out"
status=$?
[ "$status" -eq 0 ] || fail "front/rear pairs: exit $status: $(tail -3 "$WORK/pairs_out.log")"
grep -q "parallel principal axes: falling back to rd_ra" "$WORK/pairs_out.log" ||
  fail "front/rear pairs: no fallback message"
grep -q "warning: all principal axes are within 10 degrees of parallel or anti-parallel" "$WORK/pairs_out.log" ||
  fail "front/rear pairs: no diagnostic: $(grep -i warn "$WORK/pairs_out.log")"
read -r rotation center focal <<<"$(worst_errors "$WORK/pairs" "$WORK/pairs_out")"
echo "front/rear stereo pairs (rd_ra fallback): worst rotation $rotation deg," \
  "center $center m, focal $focal %"
python3 -c "import sys; r,c,f=map(float,sys.argv[1:]); sys.exit(not (r<0.1 and c<0.005 and f<0.5))" \
  "$rotation" "$center" "$focal" || fail "front/rear pairs: inaccurate"
[ "$(sums "$WORK/pairs")" = "$before" ] || fail "front/rear pairs: input changed"

# 2. A camera never in a frameset with the others: cam1's images renamed.
synthetic apart --preset ring5
sed -i 's|^IMAGE cam1/|IMAGE cam1/x|' "$WORK/apart/correspondences.txt"
before=$(sums "$WORK/apart")
calibrate "$WORK/apart" "$WORK/apart_out"
expect_failure "$WORK/apart_out" \
  "the cameras fall into 2 groups that never share a frameset: {cam0/, cam2/, cam3/, cam4/} {cam1/}.*Name the images so that the images taken together have the same name in every camera folder" $?
[ "$(sums "$WORK/apart")" = "$before" ] || fail "camera apart: input changed"
echo "camera never in a frameset: $(grep ERROR "$WORK/apart_out.log" | cut -c1-160)…"

# 3. Timestamp names, cam1's 12 ms late: with a 5 ms tolerance and no
# timestamp offsets nothing pairs up (the message gives the tolerance that
# would); with the offsets estimated (the default) or 15 ms it calibrates.
synthetic timed --preset stereo_pair
python3 - "$WORK/timed/correspondences.txt" <<'EOF'
import re, sys
path = sys.argv[1]
def timestamp(m):
    camera, frame = m.group(1), int(m.group(2))
    t = 1403715273000000000 + frame * 50000000 + (12000000 if camera == "cam1" else 0)
    return "IMAGE %s/%d.png" % (camera, t)
text = re.sub(r"^IMAGE (cam\d)/(\d+)\.png", timestamp, open(path).read(), flags=re.M)
open(path, "w").write(text)
EOF
before=$(sums "$WORK/timed")
calibrate "$WORK/timed" "$WORK/timed_out" --RigCalibrator.timestamp_tolerance 5e6 \
  --RigCalibrator.timestamp_offsets 0
expect_failure "$WORK/timed_out" \
  "never share a frameset.*12000000 apart.*set --RigCalibrator.timestamp_tolerance to at least that" $?
echo "timestamps 12 ms apart, tolerance 5 ms: $(grep -o 'The closest.*at least that' "$WORK/timed_out.log")"
calibrate "$WORK/timed" "$WORK/timed_ok" --RigCalibrator.timestamp_tolerance 15e6 ||
  fail "timestamps with 15 ms tolerance: $(tail -3 "$WORK/timed_ok.log")"
calibrate "$WORK/timed" "$WORK/timed_auto" --RigCalibrator.timestamp_tolerance 5e6 ||
  fail "timestamps with their offset removed: $(tail -3 "$WORK/timed_auto.log")"
grep -q "timestamp offsets removed before grouping (names minus cam0's, names' units): cam0 +0, cam1 +12000000" \
  "$WORK/timed_auto.log" || fail "timestamps: the removed offset is not in the log"
python3 - "$WORK/timed_auto/calibration_summary.json" <<'EOF' ||
import json, sys
offsets = json.load(open(sys.argv[1]))["timestamp_offsets"]
assert offsets["reference_camera"] == "cam0", offsets
assert abs(offsets["offsets_s"]["cam1"] - 0.012) < 1e-12, offsets
assert offsets["offsets_s"]["cam0"] == 0, offsets
EOF
  fail "timestamps: the removed offset is not in the summary"
echo "timestamps 12 ms apart, tolerance 5 ms, offsets auto: $(grep -o 'timestamp offsets removed.*' "$WORK/timed_auto.log")"
[ "$(sums "$WORK/timed")" = "$before" ] || fail "timestamps: input changed"

# 4. The same rig with the map in millimetres: the same calibration up to
# the scale (every threshold of the tool is in map units or pixels).
synthetic metres --preset ring5
synthetic millimetres --preset ring5 --map_scale 1000
calibrate "$WORK/metres" "$WORK/metres_out" || fail "metres: $(tail -3 "$WORK/metres_out.log")"
# Without frameset times (names, not timestamps) no output mentions timing.
! grep -qE '"(timing|timestamp_offsets|capture_time_offsets)"' "$WORK/metres_out/calibration_summary.json" ||
  fail "metres: timing in the summary without frameset times"
! grep -qE 'timeshift|line_delay|timing_source' "$WORK/metres_out/camchain.yaml" ||
  fail "metres: timing in camchain.yaml without frameset times"
! grep -qE 'id="timing"|time-offsets' "$WORK/metres_out/report.html" ||
  fail "metres: timing in report.html without frameset times"
! grep -qE ' dt [+-]|timestamp offsets' "$WORK/metres_out.log" ||
  fail "metres: timing in the terminal without frameset times"
calibrate "$WORK/millimetres" "$WORK/millimetres_out" ||
  fail "millimetres: $(tail -3 "$WORK/millimetres_out.log")"
python3 - "$WORK/metres_out/calibration_summary.json" \
  "$WORK/millimetres_out/calibration_summary.json" <<'EOF' || fail "map in millimetres"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
def cameras(s):
    return {c["name"]: c for c in s["cameras"]}
ca, cb = cameras(a), cameras(b)
params = max(abs(x - y) / max(1, abs(x)) for n in ca
             for x, y in zip(ca[n]["params"], cb[n]["params"]))
rotation = max(abs(x - y) for n in ca
               for x, y in zip(ca[n]["cam_from_rig"]["rotation_wxyz"],
                                  cb[n]["cam_from_rig"]["rotation_wxyz"]))
translation = max(abs(x - y / 1000) for n in ca
                  for x, y in zip(ca[n]["cam_from_rig"]["translation"],
                                  cb[n]["cam_from_rig"]["translation"]))
print("map in millimetres vs metres: intrinsics (relative) %.2g, rotation (quaternion) %.2g, "
      "translation %.2g m" % (params, rotation, translation))
sys.exit(not (params < 1e-6 and rotation < 1e-6 and translation < 1e-6))
EOF
echo "PASSED"
