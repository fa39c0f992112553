#!/usr/bin/env bash
# The user's path, timed: `rig_calibrator` with its defaults (camera models
# `auto`, refine_map, the uncertainty) on a synthetic map that looks like a
# COLMAP map, and the same data calibrated with the true camera models given
# by hand, for accuracy. The data: a ring of CAMERAS OPENCV cameras,
# FRAMESETS framesets, 300 correspondences per image of which 30 % wrong,
# 10 % of the images missing, a 60-image map whose images hold 3 000 noisy
# observations each (0.5 px) and whose points are off by 5 mm. Accuracy:
# the worst camera after `rig_calibrator evaluate`'s alignment, and each
# non-reference camera's cam_from_rig against the truth's, not aligned, with
# the summary's sigma and the turn common to them (relative to the
# reference camera).
#
# Usage: scripts/benchmark_command.sh RESULTS_DIR [FRAMESETS...]
#   RESULTS_DIR  created if needed; gets command.md (the tables), one folder
#                per size with the data, both runs' outputs, logs and
#                /usr/bin/time reports
#   FRAMESETS    frameset counts (default: 500); two or more also give the
#                exponent of time and memory in the framesets
# Environment:
#   RIG_CALIBRATOR_BUILD_DIR  build folder (default: build/)
#   BENCHMARK_CAMERAS         cameras on the ring (default 10)
#   BENCHMARK_THREADS         --RigCalibrator.num_threads (default -1: all)
#   BENCHMARK_SEED            the synthetic data's --seed (default 0)
#   BENCHMARK_TIME_MODEL      1: the rig is unsynchronized with rolling
#                             shutters (framesets at 15 Hz, the rig at
#                             1.5 m/s and 60 deg/s, offsets in +-50 ms, line
#                             delays 20-30 us/row), the frameset times are
#                             given (the names are frameset indices:
#                             timestamp_unit_s 1/15), and a third run has
#                             the time model off: the time model's cost.
#                             15 Hz: at 5 Hz the synthetic walk's 2.3 Hz
#                             bob aliases (docs/time_model.md) and at 500
#                             framesets the model check flags a camera
set -euo pipefail

log_tag=benchmark_command
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

check_arguments 1 "" "$@"
results="$1"
shift
sizes=("$@")
[[ ${#sizes[@]} -gt 0 ]] || sizes=(500)
cameras="${BENCHMARK_CAMERAS:-10}"
threads="${BENCHMARK_THREADS:--1}"
seed="${BENCHMARK_SEED:-0}"
time_model="${BENCHMARK_TIME_MODEL:-0}"
runs=(defaults true_models)
timed_data=()
timed_options=()
if [[ "$time_model" == 1 ]]; then
  runs+=(time_model_off)
  timed_data=(--frameset_rate_hz 15 --speed_m_s 1.5 --max_turn_rate_deg_s 60
              --max_time_offset_ms 50 --line_delay_us 20,30)
  timed_options=(--RigCalibrator.timestamp_tolerance 0.5
                 --RigCalibrator.timestamp_unit_s 0.0666666666666667)
fi
[[ -x "$rig_calibrator" && -x "$rig_calibrator_lab" ]] || die "no $rig_calibrator or $rig_calibrator_lab; build first (scripts/build.sh) or set RIG_CALIBRATOR_BUILD_DIR"
[[ -x /usr/bin/time ]] || die "/usr/bin/time is needed (apt-get install time)"
mkdir -p "$results" || die "cannot create $results"
results="$(cd "$results" && pwd)"

# run_timed NAME OUT_DIR ARGS...: the calibration, with /usr/bin/time -v.
# With allow_model_errors=1 an exit status of 1 (written, with a camera
# flagged: unsynchronized data calibrated without the time model) is a
# result too.
allow_model_errors=0
run_timed() {
  local name="$1" out="$2" status=0
  shift 2
  rm -rf "$out"
  /usr/bin/time -v -o "$out.time" "$rig_calibrator" \
    --RigCalibrator.num_threads "$threads" --output_path "$out" "$@" \
    >"$out.log" 2>&1 || status=$?
  [[ $status == 0 || ($status == 1 && $allow_model_errors == 1 &&
     -f "$out/timings.json") ]] || die "$name failed; see $out.log"
  "$rig_calibrator" evaluate --reference_path "$data/ground_truth/camchain.yaml" \
    --calibration_path "$out" --output_path "$out.errors.json" >/dev/null ||
    die "evaluating $name failed"
}

for framesets in "${sizes[@]}"; do
  case_dir="$results/ring${cameras}_${framesets}"
  data="$case_dir/data"
  mkdir -p "$case_dir"
  echo "[$log_tag] === $cameras cameras x $framesets framesets"
  rm -rf "$data"
  "$rig_calibrator_lab" synthetic --output_path "$data" --preset ring5 \
    --ring_num_cameras "$cameras" --num_framesets "$framesets" \
    --points_per_image 300 --outlier_ratio 0.3 --missing_image_ratio 0.1 \
    --num_map_images 60 --map_observations_per_image 3000 \
    --map_noise_px 0.5 --map_point_noise 0.005 --seed "$seed" \
    "${timed_data[@]}" \
    >"$case_dir/synthetic.log" ||
    die "generating the data failed; see $case_dir/synthetic.log"
  true_models="$(sed -n 's/.*--RigCalibrator.camera_model \([^ ]*\).*/\1/p' \
    "$case_dir/synthetic.log" | head -n 1)"
  [[ -n "$true_models" ]] || die "no camera models in $case_dir/synthetic.log"
  inputs=(--correspondences_path "$data/correspondences.txt"
          --input_path "$data/sparse" "${timed_options[@]}")
  echo "[$log_tag] defaults"
  run_timed "the defaults" "$case_dir/defaults" "${inputs[@]}"
  echo "[$log_tag] true models given by hand"
  run_timed "the true models" "$case_dir/true_models" "${inputs[@]}" \
    --RigCalibrator.camera_model "$true_models"
  if [[ "$time_model" == 1 ]]; then
    echo "[$log_tag] defaults, the time model off"
    allow_model_errors=1
    run_timed "the time model off" "$case_dir/time_model_off" "${inputs[@]}" \
      --RigCalibrator.time_offsets 0 --RigCalibrator.rolling_shutter 0
    allow_model_errors=0
  fi
done

/usr/bin/python3 - "$results" "$cameras" "${runs[*]}" "${sizes[@]}" <<'EOF'
import json, math, os, re, sys

results, cameras = sys.argv[1], int(sys.argv[2])
seed = os.environ.get("BENCHMARK_SEED", "0")
runs, sizes = sys.argv[3].split(), [int(s) for s in sys.argv[4:]]

def time_report(path):
    text = open(path).read()
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", text).group(1)
    seconds = 0.0
    for part in wall.split(":"):
        seconds = seconds * 60 + float(part)
    user = float(re.search(r"User time \(seconds\): (\S+)", text).group(1))
    system = float(re.search(r"System time \(seconds\): (\S+)", text).group(1))
    rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1))
    return seconds, user + system, rss_kb / 1024.0 ** 2

def worst(errors_path):
    errors = json.load(open(errors_path))
    keys = {"rotation_deg": "rot (deg)", "center_error": "centre",
            "focal_error_percent": "f (%)", "principal_point_error_px": "pp (px)",
            "mean_projection_diff_px": "proj (px)"}
    cams = errors.get("cameras", [])
    return {label: max(c[key] for c in cams) for key, label in keys.items()
            if cams and key in cams[0]}

out = ["# The calibrate command with its defaults", "",
       "Measured by `" + ("BENCHMARK_SEED=%s " % seed if seed != "0" else "") +
       ("BENCHMARK_TIME_MODEL=1 " if "time_model_off" in runs
        else "") + "bash scripts/benchmark_command.sh RESULTS " +
       " ".join(map(str, sizes)) + "` (" + str(os.cpu_count()) +
       " cores). The defaults: camera models `auto`, refine_map, the "
       "uncertainty; wall and CPU (user + system) of the whole command, "
       "reading and writing included, peak resident memory.", ""]
rows = {}
for framesets in sizes:
    case = os.path.join(results, "ring%d_%d" % (cameras, framesets))
    for run in runs:
        wall, cpu, rss = time_report(os.path.join(case, run + ".time"))
        timings = json.load(open(os.path.join(case, run, "timings.json")))
        rows[(framesets, run)] = (wall, cpu, rss, timings,
                                  worst(os.path.join(case, run + ".errors.json")))
stages = []
for (_, _, _, timings, _) in rows.values():
    for stage in timings["timings_s"]:
        if stage not in stages:
            stages.append(stage)
out.append("| framesets | run | wall (s) | CPU (s) | CPU/wall | peak (GB) | " +
           " | ".join(stages) + " |")
out.append("|---" * (6 + len(stages)) + "|")
for (framesets, run), (wall, cpu, rss, timings, _) in sorted(rows.items()):
    cells = []
    for stage in stages:
        if stage not in timings["timings_s"]:
            cells.append("-")
            continue
        cell = "%.1f / %.1f" % (timings["timings_s"][stage], timings["cpu_s"][stage])
        if stage in timings.get("iterations", {}):
            cell += " (%d it.)" % timings["iterations"][stage]
        cells.append(cell)
    out.append("| %d x %d | %s | %.1f | %.1f | %.2f | %.2f | %s |" %
               (framesets, cameras, run.replace("_", " "), wall, cpu, cpu / wall, rss,
                " | ".join(cells)))
out += ["", "Stage cells: wall / CPU seconds (solver iterations).", "",
        "Accuracy against the ground truth, the worst camera:", ""]
labels = list(next(iter(rows.values()))[4].keys())
out.append("| framesets | run | " + " | ".join(labels) + " |")
out.append("|---" * (2 + len(labels)) + "|")
for (framesets, run), (_, _, _, _, errors) in sorted(rows.items()):
    out.append("| %d x %d | %s | %s |" % (framesets, cameras, run.replace("_", " "),
               " | ".join("%.4g" % errors[label] for label in labels)))
def quaternion_product(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return [w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2]

def normalized(q):
    n = math.sqrt(sum(c * c for c in q))
    return [c / n for c in q]

def centre(q, t):  # c = -R^T t of cam_from_rig: -conj(q) t q
    w, x, y, z = normalized(q)
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
         [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
         [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
    return [-sum(r[i][k] * t[i] for i in range(3)) for k in range(3)]

def against_truth(summary_path, truth_path):
    """Each non-reference camera's cam_from_rig against the truth's, not
    aligned (evaluate aligns the rig, which moves a turn common to them onto
    the reference camera): the rotation error in the rig frame,
    Log(R_true^T R_est), with the summary's sigma, and their mean, the turn
    common to every camera relative to the reference camera."""
    cameras = json.load(open(summary_path))["cameras"]
    truth = json.load(open(truth_path))[0]["cameras"]
    vectors, rotation_z, centre_z, sigmas = [], [], [], []
    for camera, true in list(zip(cameras, truth))[1:]:
        pose, sigma = camera["cam_from_rig"], camera.get("uncertainty")
        if sigma is None or sigma.get("rotation_stddev_deg") is None:
            continue
        true_q = normalized(true["cam_from_rig_rotation"])
        error = quaternion_product([true_q[0]] + [-c for c in true_q[1:]],
                                   normalized(pose["rotation_wxyz"]))
        sign = 1 if error[0] >= 0 else -1
        vector = [math.degrees(2 * sign * c) for c in error[1:]]
        vectors.append(vector)
        sigmas.append(sigma["rotation_stddev_deg"])
        rotation_z.append(math.sqrt(sum(c * c for c in vector)) / sigma["rotation_stddev_deg"])
        estimated = centre(pose["rotation_wxyz"], pose["translation"])
        expected = centre(true["cam_from_rig_rotation"], true["cam_from_rig_translation"])
        centre_z += [(e - x) / sd for e, x, sd in
                     zip(estimated, expected, sigma["center_in_rig_stddev"])]
    if not vectors:
        return None
    mean = [sum(v[k] for v in vectors) / len(vectors) for k in range(3)]
    common = math.sqrt(sum(c * c for c in mean))
    rms = lambda values: math.sqrt(sum(v * v for v in values) / len(values))
    return (max(math.sqrt(sum(c * c for c in v)) for v in vectors), rms(rotation_z),
            rms(centre_z), max(abs(z) for z in rotation_z + centre_z), mean,
            common / rms(sigmas))

out += ["", "Each non-reference camera's cam_from_rig against the truth's, not aligned, "
        "with the summary's sigma; the common turn is the mean of their rotation errors "
        "(rig frame: x, y, z in deg), relative to the reference camera:", "",
        "| framesets | run | rotation, max (deg) | z RMS: rotation, centre | largest abs z "
        "| common turn (deg) | common turn / sigma |", "|---" * 7 + "|"]
for framesets in sizes:
    case = os.path.join(results, "ring%d_%d" % (cameras, framesets))
    for run in runs:
        result = against_truth(os.path.join(case, run, "calibration_summary.json"),
                               os.path.join(case, "data", "ground_truth", "rig_config.json"))
        if result is None:
            out.append("| %d x %d | %s | no sigma | | | | |" % (framesets, cameras, run))
            continue
        largest, rotation_z, centre_z, max_z, mean, common_z = result
        out.append("| %d x %d | %s | %.4f | %.2f, %.2f | %.1f | %s | %.1f |" %
                   (framesets, cameras, run.replace("_", " "), largest, rotation_z, centre_z,
                    max_z, ", ".join("%+.4f" % c for c in mean), common_z))
if len(sizes) >= 2:
    a, b = min(sizes), max(sizes)
    out += ["", "Exponent in the framesets, %d to %d (defaults): " % (a, b)]
    for index, name in ((0, "wall"), (1, "CPU"), (2, "peak memory")):
        ratio = rows[(b, "defaults")][index] / rows[(a, "defaults")][index]
        out[-1] += "%s %.2f; " % (name, math.log(ratio) / math.log(b / a))
open(os.path.join(results, "command.md"), "w").write("\n".join(out) + "\n")
print("\n".join(out))
EOF
