#!/usr/bin/env bash
# Today's calibration on data from unsynchronized cameras and rolling
# shutters (docs/time_model.md, "without a time model"): per preset,
# `rig_calibrator_lab synthetic` with the time model (FRAMESETS framesets at
# 5 Hz, the rig at 1.5 m/s turning at up to 60 degrees/s, the default noise,
# wrong matches and missing images) in four cases, (a) synchronized global
# shutters, (b) capture-time offsets in +-50 ms, (c) line delays of 20-30
# microseconds per row, (d) both; each calibrated by `rig_calibrator` with
# its defaults and evaluated against the ground truth.
#
# Usage: scripts/benchmark_time_model.sh RESULTS_DIR [FRAMESETS]
#   RESULTS_DIR  created if needed; gets time_model.md (the table), and per
#                preset and case the data, the output, its log and errors
#   FRAMESETS    framesets per data set (default 100)
# Environment:
#   RIG_CALIBRATOR_BUILD_DIR  build folder (default: build/)
#   TIME_MODEL_PRESETS        presets (default: ring5 fisheye_helmet5
#                             car_surround4)
set -euo pipefail

log_tag=benchmark_time_model
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

check_arguments 1 2 "$@"
results="$1"
framesets="${2:-100}"
read -r -a presets <<<"${TIME_MODEL_PRESETS:-ring5 fisheye_helmet5 car_surround4}"
[[ -x "$rig_calibrator" && -x "$rig_calibrator_lab" ]] || die "no $rig_calibrator or $rig_calibrator_lab; build first (scripts/build.sh) or set RIG_CALIBRATOR_BUILD_DIR"
mkdir -p "$results" || die "cannot create $results"
results="$(cd "$results" && pwd)"

declare -A case_options=(
  [a]=""
  [b]="--max_time_offset_ms 50"
  [c]="--line_delay_us 20,30"
  [d]="--max_time_offset_ms 50 --line_delay_us 20,30"
)
for preset in "${presets[@]}"; do
  for case_name in a b c d; do
    dir="$results/${preset}_$case_name"
    rm -rf "$dir"
    mkdir -p "$dir"
    echo "[$log_tag] $preset ($case_name) ${case_options[$case_name]}"
    # shellcheck disable=SC2086
    "$rig_calibrator_lab" synthetic --output_path "$dir/data" --preset "$preset" \
      --num_framesets "$framesets" --frameset_rate_hz 5 --speed_m_s 1.5 \
      --max_turn_rate_deg_s 60 ${case_options[$case_name]} \
      >"$dir/synthetic.log" || die "generating $dir failed; see $dir/synthetic.log"
    # A calibration that reports an error still writes its outputs; the
    # table says so.
    "$rig_calibrator" --correspondences_path "$dir/data/correspondences.txt" \
      --output_path "$dir/out" >"$dir/calibration.log" 2>&1 ||
      echo "exit $?" >"$dir/calibration.failed"
    "$rig_calibrator" evaluate --reference_path "$dir/data/ground_truth/camchain.yaml" \
      --calibration_path "$dir/out" --output_path "$dir/errors.json" >/dev/null ||
      die "evaluating $dir failed"
  done
done

/usr/bin/python3 - "$results" "${presets[@]}" <<'EOF'
import json, os, re, sys

results, presets = sys.argv[1], sys.argv[2:]
cases = {"a": "synchronized, global shutter", "b": "offsets in +-50 ms",
         "c": "line delays 20-30 us/row", "d": "offsets and line delays"}
rows = ["| preset | case | rotation (deg) | center (m) | focal (%) | principal point (px) "
        "| projection, max (px) | reprojection RMS (px) | chosen model not the true one "
        "| diagnostics |",
        "|---|---|---|---|---|---|---|---|---|---|"]
for preset in presets:
    for case, label in cases.items():
        folder = os.path.join(results, f"{preset}_{case}")
        errors = json.load(open(os.path.join(folder, "errors.json")))["cameras"]
        summary = json.load(open(os.path.join(folder, "out", "calibration_summary.json")))
        time_model = json.load(open(os.path.join(folder, "data", "ground_truth",
                                                 "time_model.json")))
        def worst(key):
            camera = max(errors, key=lambda c: c[key])
            return f"{camera[key]:.3g} ({camera['name']})"
        rms = max(summary["cameras"], key=lambda c: c["rms_px"])
        # The true models, as the synthetic command prints them for
        # --RigCalibrator.camera_model: cam0:OPENCV,cam1:...
        log = open(os.path.join(folder, "synthetic.log")).read()
        true_models = dict(item.split(":") for item in
                           re.search(r"camera_model (\S+)", log).group(1).split(","))
        wrong_models = [f"{c['name']} {c['model']}" for c in summary["cameras"]
                        if c["model"] != true_models[c["name"]]]
        # Diagnostics are "LEVEL CODE: message" (notes have no level); the
        # cameras a message names are given with its code.
        found = {}
        for text in summary["diagnostics"]:
            head, _, message = text.partition(": ")
            if head.split(" ")[0] in ("warning", "error"):
                found.setdefault(head, set()).update(re.findall(r"\bcam\d+\b", message))
        codes = [f"{head} ({', '.join(sorted(cams))})" if cams else head
                 for head, cams in sorted(found.items())]
        if os.path.exists(os.path.join(folder, "calibration.failed")):
            codes.insert(0, "exit code != 0")
        offsets = [c["time_offset_s"] * 1e3 for c in time_model["cameras"]]
        delays = [c["line_delay_s"] * 1e6 for c in time_model["cameras"]]
        rows.append(f"| {preset} | ({case}) {label} | {worst('rotation_deg')} "
                    f"| {worst('center_error')} | {worst('focal_error_percent')} "
                    f"| {worst('principal_point_error_px')} "
                    f"| {worst('max_projection_diff_px')} "
                    f"| {rms['rms_px']:.3g} ({rms['name']}) "
                    f"| {', '.join(wrong_models) or 'none'} "
                    f"| {', '.join(codes) or 'none'} |")
        print(f"{preset} ({case}): offsets ms {', '.join(f'{o:.1f}' for o in offsets)}; "
              f"line delays us {', '.join(f'{d:.1f}' for d in delays)}")
with open(os.path.join(results, "time_model.md"), "w") as table:
    table.write("\n".join(rows) + "\n")
print("\n".join(rows))
EOF
