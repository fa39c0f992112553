#!/usr/bin/env bash
# The time model's accuracy and sigma over many draws (docs/time_model.md,
# "Over many seeds"): one seed is one draw, and the issue's comparison, the
# rig "as accurate (within 1.25x) as the same data captured synchronized",
# is a comparison of spreads. Per preset and seed, `rig_calibrator_lab
# synthetic` with the time model (FRAMESETS framesets at FRAMESET_RATE_HZ,
# 1080 rows, the rig at 1.5 m/s turning at up to 60 degrees/s, the default
# noise, wrong matches and missing images) in two cases, (a) synchronized
# global shutters and (d) offsets in +-50 ms and line delays of 20-30 us per
# row, each calibrated by `rig_calibrator` with its defaults and the
# frameset times (the time model auto). Per preset and case, over every
# non-reference camera of every seed: the RMS of the rotation error and of
# the centre error per rig axis, the RMS of error / sigma (sigma the
# summary's: 1 when sigma is honest), its largest value, and (d) against
# (a), of the errors and of the sigmas (RMS; how precise the data make each
# case); over every camera (the reference camera's intrinsics are estimated
# too) the same for the focal length (fx, in %), the principal point (px)
# and the largest projection difference from the true model over the image
# (`rig_calibrator evaluate`); and the turn common to the non-reference
# cameras against the reference camera (their rotation errors' mean per
# seed), apart from each camera's own. CASES may add (e): (d)'s offsets and
# line delays, but the reference camera a global shutter (its line delay 0;
# the others as drawn), compared with (a) as (d) is. Its points and noise
# are another draw: the reference camera's capture changes which points
# each image sees, and with them the random stream of every image after it.
#
# Usage: scripts/benchmark_time_model_seeds.sh RESULTS_DIR [FRAMESETS]
#   RESULTS_DIR  created if needed; gets time_model_seeds.md (the tables),
#                and per preset, case and seed the data, output and log
#   FRAMESETS    framesets per data set (default 60)
# Environment:
#   RIG_CALIBRATOR_BUILD_DIR  build folder (default: build/)
#   TIME_MODEL_PRESETS        presets (default: ring5 fisheye_helmet5
#                             car_surround4)
#   FRAMESET_RATE_HZ          frameset rate (default 15)
#   SEEDS                     seeds (default: 1 2 3 4 5 6 7 8)
#   JOBS                      calibrations at once (default 2)
#   CASES                     cases to run (default: a d); the tables
#                             compare each with (a), which must be among
#                             them or already in RESULTS_DIR for every
#                             preset and seed
#   BOB_HZ                    the body's bob at this frequency instead of the
#                             preset's (rig_calibrator_lab synthetic --bob_hz;
#                             e.g. 4.83: the car shaking faster than 15 Hz
#                             framesets follow)
set -euo pipefail

log_tag=benchmark_time_model_seeds
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

check_arguments 1 2 "$@"
results="$1"
framesets="${2:-60}"
rate_hz="${FRAMESET_RATE_HZ:-15}"
unit_s="$(/usr/bin/python3 -c "print(1 / $rate_hz)")"
read -r -a presets <<<"${TIME_MODEL_PRESETS:-ring5 fisheye_helmet5 car_surround4}"
read -r -a seeds <<<"${SEEDS:-1 2 3 4 5 6 7 8}"
read -r -a cases <<<"${CASES:-a d}"
for case_name in "${cases[@]}"; do
  [[ $case_name =~ ^[ade]$ ]] || die "CASES: unknown case '$case_name' (a, d, e)"
done
if [[ " ${cases[*]} " != *" a "* ]]; then
  for preset in "${presets[@]}"; do
    for seed in "${seeds[@]}"; do
      [[ -d $results/${preset}_a_$seed ]] ||
        die "CASES without a needs (a)'s results in $results; no ${preset}_a_$seed"
    done
  done
fi
jobs="${JOBS:-2}"
bob_hz="${BOB_HZ:-0}"
[[ -x "$rig_calibrator" && -x "$rig_calibrator_lab" ]] || die "no $rig_calibrator or $rig_calibrator_lab; build first (scripts/build.sh) or set RIG_CALIBRATOR_BUILD_DIR"
mkdir -p "$results" || die "cannot create $results"
results="$(cd "$results" && pwd)"

# One draw: generate, calibrate (a failed calibration leaves calibration.failed).
run_one() {
  local preset="$1" case_name="$2" seed="$3"
  local dir="$results/${preset}_${case_name}_$seed" options=""
  [[ $case_name == a ]] || options="--max_time_offset_ms 50 --line_delay_us 20,30"
  [[ $bob_hz == 0 ]] || options+=" --bob_hz $bob_hz"
  rm -rf "$dir"
  mkdir -p "$dir"
  if [[ $case_name == e ]]; then
    # (d)'s offsets and line delays (drawn from their own random stream,
    # read back from a generation of (d)), the reference camera's line
    # delay 0.
    # shellcheck disable=SC2086
    "$rig_calibrator_lab" synthetic --output_path "$dir/draw" --preset "$preset" \
      --num_framesets "$framesets" --frameset_rate_hz "$rate_hz" --speed_m_s 1.5 \
      --max_turn_rate_deg_s 60 --image_height 1080 --seed "$seed" $options \
      >"$dir/synthetic.log" || { echo "generating $dir failed" >&2; return 1; }
    options="$(/usr/bin/python3 -c '
import json, sys
cameras = json.load(open(sys.argv[1]))["cameras"]
print("--camera_time_offsets_ms", ",".join(repr(1e3 * c["time_offset_s"]) for c in cameras),
      "--camera_line_delays_us", ",".join(["0"] + [repr(1e6 * c["line_delay_s"]) for c in cameras[1:]]))
' "$dir/draw/ground_truth/time_model.json")" || { echo "reading $dir/draw failed" >&2; return 1; }
    [[ $bob_hz == 0 ]] || options+=" --bob_hz $bob_hz"
    rm -rf "$dir/draw"
  fi
  # shellcheck disable=SC2086
  "$rig_calibrator_lab" synthetic --output_path "$dir/data" --preset "$preset" \
    --num_framesets "$framesets" --frameset_rate_hz "$rate_hz" --speed_m_s 1.5 \
    --max_turn_rate_deg_s 60 --image_height 1080 --seed "$seed" $options \
    >"$dir/synthetic.log" || { echo "generating $dir failed" >&2; return 1; }
  "$rig_calibrator" --correspondences_path "$dir/data/correspondences.txt" \
    --output_path "$dir/out" --RigCalibrator.timestamp_tolerance 0.5 \
    --RigCalibrator.timestamp_unit_s "$unit_s" >"$dir/calibration.log" 2>&1 ||
    touch "$dir/calibration.failed"
  [[ -e $dir/calibration.failed ]] ||
    "$rig_calibrator" evaluate --reference_path "$dir/data/ground_truth/camchain.yaml" \
      --calibration_path "$dir/out" --output_path "$dir/errors.json" >/dev/null ||
    { echo "evaluating $dir failed" >&2; return 1; }
  echo "[$log_tag] $preset ($case_name) seed $seed done"
}
export -f run_one
export results framesets rate_hz bob_hz unit_s rig_calibrator rig_calibrator_lab log_tag

for preset in "${presets[@]}"; do
  for seed in "${seeds[@]}"; do
    for case_name in "${cases[@]}"; do echo "$preset $case_name $seed"; done
  done
done | xargs -P "$jobs" -L 1 bash -c 'run_one "$0" "$1" "$2"' ||
  die "a data set could not be generated (see above)"

table_cases="a ${cases[*]/a/}"
/usr/bin/python3 - "$results" "$rate_hz" "$bob_hz" "${#seeds[@]}" "$table_cases" "${presets[@]}" <<'EOF'
import glob, json, math, os, sys

results, rate_hz, bob_hz, num_seeds, cases = sys.argv[1:6]
cases = sorted(set(cases.split()))
presets = sys.argv[6:]

def rotation(q):
    w, x, y, z = (v / math.sqrt(sum(c * c for c in q)) for v in q)
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]

def centre(q, t):  # c = -R^T t of cam_from_rig
    r = rotation(q)
    return [-sum(r[i][k] * t[i] for i in range(3)) for k in range(3)]

def angle_deg(q, p):  # the angle of q p^-1
    w1, x1, y1, z1 = q
    w2, x2, y2, z2 = p[0], -p[1], -p[2], -p[3]
    w = w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2
    norm = math.sqrt(sum(c * c for c in q) * sum(c * c for c in p))
    return math.degrees(2 * math.acos(min(1.0, abs(w) / norm)))

def turn_deg(q_true, q):
    """The rotation vector (degrees) of R_true^T R of cam_from_rig: the turn
    of the estimated camera against the true one, in the rig frame."""
    a, b = rotation(q_true), rotation(q)
    m = [[sum(a[k][i] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    angle = math.acos(max(-1.0, min(1.0, (m[0][0] + m[1][1] + m[2][2] - 1) / 2)))
    scale = angle / (2 * math.sin(angle)) if angle > 1e-12 else 0.5
    return [math.degrees(scale * v) for v in
            (m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1])]

def pp_index(model):
    one_focal = ("SIMPLE_PINHOLE", "SIMPLE_RADIAL", "RADIAL", "SIMPLE_RADIAL_FISHEYE",
                 "RADIAL_FISHEYE")
    return 1 if model in one_focal else 2

def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else float("nan")

stats = {}
failed = []
for preset in presets:
    for case in cases:
        rot, rot_z, axes, axes_z = [], [], [[], [], []], []
        rot_sigma, axes_sigma = [], [[], [], []]
        focal, focal_z, pp, pp_z, projection, other_model = [], [], [], [], [], 0
        common, own = [], []  # per seed the non-reference cameras' mean turn; each one's about it
        for folder in sorted(glob.glob(os.path.join(results, f"{preset}_{case}_*"))):
            if os.path.exists(os.path.join(folder, "calibration.failed")):
                failed.append(os.path.basename(folder))
                continue
            summary = json.load(open(os.path.join(folder, "out", "calibration_summary.json")))
            truth = json.load(open(os.path.join(folder, "data", "ground_truth",
                                                "rig_config.json")))[0]["cameras"]
            errors = json.load(open(os.path.join(folder, "errors.json")))["cameras"]
            for camera, true, error in zip(summary["cameras"], truth, errors):
                focal.append(error["focal_error_percent"])
                pp.append(error["principal_point_error_px"])
                projection.append(error["max_projection_diff_px"])
                stddev = camera.get("uncertainty", {}).get("params_stddev")
                if not stddev or not camera.get("calibrated", True):
                    continue
                # sigma is that of the chosen model's parameters: z only
                # where it is the lens's (another model's focal length and
                # principal point carry its bias, which sigma does not
                # cover). fx, cx, cy at COLMAP's positions.
                if camera["model"] != true["camera_model_name"]:
                    other_model += 1
                    continue
                params, true_params = camera["params"], true["camera_params"]
                k = pp_index(camera["model"])
                focal_z.append((params[0] - true_params[0]) / stddev[0])
                for axis in range(2):
                    pp_z.append((params[k + axis] - true_params[k + axis]) / stddev[k + axis])
            turns = []
            for camera, true in list(zip(summary["cameras"], truth))[1:]:
                if not camera.get("calibrated", True) or "uncertainty" not in camera:
                    failed.append(f"{os.path.basename(folder)} {camera['name']}")
                    continue
                pose = camera["cam_from_rig"]
                turns.append(turn_deg(true["cam_from_rig_rotation"], pose["rotation_wxyz"]))
                error = angle_deg(pose["rotation_wxyz"], true["cam_from_rig_rotation"])
                sigma = camera["uncertainty"]["rotation_stddev_deg"]
                rot.append(error)
                rot_z.append(error / sigma)
                rot_sigma.append(sigma)
                estimated = centre(pose["rotation_wxyz"], pose["translation"])
                expected = centre(true["cam_from_rig_rotation"], true["cam_from_rig_translation"])
                sigmas = camera["uncertainty"]["center_in_rig_stddev"]
                for k in range(3):
                    axes[k].append(estimated[k] - expected[k])
                    axes_z.append((estimated[k] - expected[k]) / sigmas[k])
                    axes_sigma[k].append(sigmas[k])
            if turns:
                mean = [sum(t[k] for t in turns) / len(turns) for k in range(3)]
                common.append(mean)
                own += [math.dist(t, mean) for t in turns]
        seeds = len(common)
        common_mean = [sum(c[k] for c in common) / seeds if seeds else float("nan")
                       for k in range(3)]
        common_sd = [math.sqrt(sum((c[k] - common_mean[k]) ** 2 for c in common) / (seeds - 1))
                     if seeds > 1 else float("nan") for k in range(3)]
        stats[(preset, case)] = dict(
            seeds=seeds, common=rms([math.hypot(*c) for c in common]), own=rms(own),
            common_mean=common_mean,
            common_mean_sigma=[sd / math.sqrt(seeds) for sd in common_sd],
            rotation=rms(rot), axes=[rms(a) for a in axes],
            rotation_sigma=rms(rot_sigma),
            centre_sigma=math.sqrt(sum(rms(a) ** 2 for a in axes_sigma)),
            centre=math.sqrt(sum(rms(a) ** 2 for a in axes)), rotation_z=rms(rot_z),
            centre_z=rms(axes_z), max_z=max([abs(z) for z in rot_z + axes_z], default=float("nan")),
            n=len(rot), focal=rms(focal), focal_z=rms(focal_z), pp=rms(pp), pp_z=rms(pp_z),
            projection=rms(projection), intrinsics_n=len(focal), other_model=other_model,
            intrinsics_max_z=max([abs(z) for z in focal_z + pp_z], default=float("nan")))
def table(header, cells, ratio_groups):
    """Markdown rows: per preset and case the cells of its stats, then per
    group of keys the ratios to (a) ("-" on the row of (a))."""
    labels = {"a": "(a) synchronized", "d": "(d) offsets and line delays",
              "e": "(e) as (d), the reference a global shutter"}
    lines = [header, "|---" * (header.count("|") - 1) + "|"]
    for preset in presets:
        for case in cases:
            label = labels[case]
            s, a = stats[(preset, case)], stats[(preset, "a")]
            ratios = [", ".join(f"{s[k] / a[k]:.2f}" for k in keys) if case != "a" else "-"
                      for keys in ratio_groups]
            lines.append("| " + " | ".join([preset, label] + cells(s) + ratios) + " |")
    return lines

# (d) / (a) when those are the cases (the tables as before (e) was added).
versus = "(d) / (a)" if cases == ["a", "d"] else "/ (a)"
bob = "" if bob_hz == "0" else f", the body bobbing at {bob_hz} Hz"
rows = [f"{rate_hz} Hz, {num_seeds} seeds, 1080 rows{bob}; RMS over the non-reference cameras "
        "of every seed; z = error / sigma", ""]
rows += table("| preset | case | cameras | rotation (deg) | centre x, y, z (mm) | centre (mm) "
              f"| rotation z | centre z (per axis) | largest abs z | {versus}: rotation, centre "
              f"| sigma {versus}: rotation, centre |",
              lambda s: [str(s["n"]), f"{s['rotation']:.4f}",
                         ", ".join(f"{1e3 * v:.3f}" for v in s["axes"]),
                         f"{1e3 * s['centre']:.3f}", f"{s['rotation_z']:.2f}",
                         f"{s['centre_z']:.2f}", f"{s['max_z']:.1f}"],
              [("rotation", "centre"), ("rotation_sigma", "centre_sigma")])
rows += ["", "Intrinsics, RMS over every camera of every seed (the reference camera's "
         "too); z (fx, the principal point per axis) over the cameras whose chosen model is "
         "the lens's", ""]
rows += table("| preset | case | cameras | another model | focal (%) | principal point (px) "
              "| projection, max (px) | focal z | principal point z | largest abs z "
              f"| {versus}: focal, principal point, projection |",
              lambda s: [str(s["intrinsics_n"]), str(s["other_model"]), f"{s['focal']:.4f}",
                         f"{s['pp']:.3f}", f"{s['projection']:.3f}", f"{s['focal_z']:.2f}",
                         f"{s['pp_z']:.2f}", f"{s['intrinsics_max_z']:.1f}"],
              [("focal", "pp", "projection")])
rows += ["", "The non-reference cameras' rotation errors as turns in the rig frame (R_true^T R "
         "of cam_from_rig): per seed their mean, the turn common to them against the "
         "reference camera; RMS of its size over the seeds, its mean per rig axis +- the "
         "mean's standard error; RMS of each camera's turn about that mean", ""]
rows += table("| preset | case | seeds | common turn (deg) | its mean x, y, z (deg) "
              f"| each camera's own (deg) | {versus}: common, own |",
              lambda s: [str(s["seeds"]), f"{s['common']:.4f}",
                         ", ".join(f"{m:+.4f} +- {e:.4f}" for m, e in
                                   zip(s["common_mean"], s["common_mean_sigma"])),
                         f"{s['own']:.4f}"],
              [("common", "own")])
if failed:
    rows += ["", "Failed or without sigma (left out): " + ", ".join(failed)]
with open(os.path.join(results, "time_model_seeds.md"), "w") as table:
    table.write("\n".join(rows) + "\n")
print("\n".join(rows))
EOF
