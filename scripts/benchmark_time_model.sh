#!/usr/bin/env bash
# Today's calibration on data from unsynchronized cameras and rolling
# shutters (docs/time_model.md, "without a time model"): per preset,
# `rig_calibrator_lab synthetic` with the time model (FRAMESETS framesets at
# 5 Hz, the rig at 1.5 m/s turning at up to 60 degrees/s, the default noise,
# wrong matches and missing images) in four cases, (a) synchronized global
# shutters, (b) capture-time offsets in +-50 ms, (c) line delays of 20-30
# microseconds per row, (d) both; each calibrated by `rig_calibrator` with
# its defaults and evaluated against the ground truth: without frameset
# times (out_before: today's calibration, no time model) and with them
# (out_after: --RigCalibrator.timestamp_unit_s 1/rate turns the frameset
# indices into the frameset times, so the final adjustment's capture-time model
# runs, time_offsets and rolling_shutter auto).
#
# Usage: scripts/benchmark_time_model.sh RESULTS_DIR [FRAMESETS]
#   RESULTS_DIR  created if needed; gets time_model.md (the table), and per
#                preset and case the data, the output, its log and errors
#   FRAMESETS    framesets per data set (default 100)
# Environment:
#   RIG_CALIBRATOR_BUILD_DIR  build folder (default: build/)
#   TIME_MODEL_PRESETS        presets (default: ring5 fisheye_helmet5
#                             car_surround4)
#   FRAMESET_RATE_HZ          frameset rate (default 5)
#   IMAGE_HEIGHT              every camera scaled to this many rows (default
#                             0: the presets' 480-600; 1080: the rows of a
#                             1080p rolling shutter, the issue's case)
set -euo pipefail

log_tag=benchmark_time_model
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

check_arguments 1 2 "$@"
results="$1"
framesets="${2:-100}"
rate_hz="${FRAMESET_RATE_HZ:-5}"
unit_s="$(/usr/bin/python3 -c "print(1 / $rate_hz)")"
image_height="${IMAGE_HEIGHT:-0}"
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
      --num_framesets "$framesets" --frameset_rate_hz "$rate_hz" --speed_m_s 1.5 \
      --max_turn_rate_deg_s 60 --image_height "$image_height" ${case_options[$case_name]} \
      >"$dir/synthetic.log" || die "generating $dir failed; see $dir/synthetic.log"
    # A calibration that reports an error still writes its outputs; the
    # table says so.
    for run in before after; do
      times=()
      [[ $run == after ]] && times=(--RigCalibrator.timestamp_tolerance 0.5
                                    --RigCalibrator.timestamp_unit_s "$unit_s")
      "$rig_calibrator" --correspondences_path "$dir/data/correspondences.txt" \
        --output_path "$dir/out_$run" "${times[@]}" >"$dir/calibration_$run.log" 2>&1 ||
        echo "exit $?" >"$dir/calibration_$run.failed"
      "$rig_calibrator" evaluate --reference_path "$dir/data/ground_truth/camchain.yaml" \
        --calibration_path "$dir/out_$run" --output_path "$dir/errors_$run.json" >/dev/null ||
        die "evaluating $dir ($run) failed"
    done
  done
done

/usr/bin/python3 - "$results" "${presets[@]}" <<'EOF'
import json, os, re, sys

results, presets = sys.argv[1], sys.argv[2:]
cases = {"a": "synchronized, global shutter", "b": "offsets in +-50 ms",
         "c": "line delays 20-30 us/row", "d": "offsets and line delays"}
rows = ["| preset | case | rotation (deg) | centre (mm) | focal (%) | projection, max (px) "
        "| RMS (px) | kept | offset error, max (ms) | line delay error, max (%) "
        "| wrong model | diagnostics |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|"]
for preset in presets:
    for case, label in cases.items():
        folder = os.path.join(results, f"{preset}_{case}")
        truth = json.load(open(os.path.join(folder, "data", "ground_truth",
                                            "time_model.json")))["cameras"]
        log = open(os.path.join(folder, "synthetic.log")).read()
        true_models = dict(item.split(":") for item in
                           re.search(r"camera_model (\S+)", log).group(1).split(","))
        columns = {}
        for run in ("before", "after"):
            errors = json.load(open(os.path.join(folder, f"errors_{run}.json")))["cameras"]
            summary = json.load(open(os.path.join(folder, f"out_{run}",
                                                  "calibration_summary.json")))
            def worst(key, scale=1.0):
                return max(c[key] for c in errors) * scale
            columns.setdefault("rotation", []).append(f"{worst('rotation_deg'):.3g}")
            columns.setdefault("centre", []).append(f"{worst('center_error', 1e3):.3g}")
            columns.setdefault("focal", []).append(f"{worst('focal_error_percent'):.3g}")
            columns.setdefault("projection", []).append(
                f"{worst('max_projection_diff_px'):.3g}")
            columns.setdefault("rms", []).append(
                f"{max(c['rms_px'] for c in summary['cameras']):.3g}")
            wrong = [f"{c['name']} {c['model']}" for c in summary["cameras"]
                     if c["model"] != true_models[c["name"]]]
            found = set()
            for text in summary["diagnostics"]:
                head = text.partition(": ")[0]
                if head.split(" ")[0] in ("warning", "error"):
                    found.add(head.split(" ")[-1])
            if os.path.exists(os.path.join(folder, f"calibration_{run}.failed")):
                found.add("exit code != 0")
            columns.setdefault("wrong", []).append(", ".join(wrong) or "none")
            columns.setdefault("diagnostics", []).append(", ".join(sorted(found)) or "none")
            model = summary.get("capture_time_model")
        kept, offset_error, delay_error = "-", "-", "-"
        if model is not None:
            kept = "+".join(k for k, v in (("offsets", model["time_offsets_kept"]),
                                           ("line delays", model["line_delays_kept"])) if v) or "none"
            cams = model["cameras"]
            if model["time_offsets_kept"]:
                offset_error = f"{max(abs(c['time_offset_s'] - t['time_offset_s']) for c, t in zip(cams, truth)) * 1e3:.3g}"
            relative = [abs(c["line_delay_s"] - t["line_delay_s"]) / t["line_delay_s"] * 100
                        for c, t in zip(cams, truth) if t["line_delay_s"] > 0]
            if model["line_delays_kept"] and relative:
                delay_error = f"{max(relative):.3g}"
        def pair(key):
            return " → ".join(columns[key])
        rows.append(f"| {preset} | ({case}) {label} | {pair('rotation')} | {pair('centre')} "
                    f"| {pair('focal')} | {pair('projection')} | {pair('rms')} | {kept} "
                    f"| {offset_error} | {delay_error} | {columns['wrong'][1]} "
                    f"| {columns['diagnostics'][1]} |")
with open(os.path.join(results, "time_model.md"), "w") as table:
    table.write("\n".join(rows) + "\n")
print("\n".join(rows))
EOF
