#!/usr/bin/env bash
# Runtime benchmark: time and peak memory of the calibration core on
# synthetic rigs (10-500 framesets x 5 and 10 cameras, ~300 correspondences
# per image, map points with 5 mm error) and of the localization against a
# 300-image map (`rig_calibrator_lab benchmark_runtime`), optionally before and
# after (another build's runs of the same data, in the same run), and
# optionally the end-to-end time of the rendered demo (scripts/demo.sh)
# split into COLMAP's steps and ours, and optionally our final bundle
# adjustment side by side with COLMAP 3.8's rig_bundle_adjuster on the same
# problem (`rig_calibrator_lab benchmark_colmap_rig_ba`).
#
# Usage: scripts/benchmark_runtime.sh RESULTS_DIR [benchmark_runtime options...]
#   RESULTS_DIR  created if needed; gets runtime.md, runtime_calibration.csv,
#                runtime_calibration.svg, runtime_localization.csv,
#                with a baseline runtime_calibration_before.csv,
#                runtime_log.txt and, with the demo, runtime_demo.md and
#                runtime_demo_log.txt, with the COLMAP comparison
#                colmap_rig_ba.md, colmap_rig_ba.csv and colmap_rig_ba_log.txt
#                (other files are left alone)
#   options      passed to `rig_calibrator_lab benchmark_runtime`, e.g.
#                --framesets 10,50 --cameras 5 --localization 0
# Environment:
#   RIG_CALIBRATOR_BUILD_DIR  build folder with rig_calibrator_lab (default: build/)
#   RUNTIME_DEMO=1            also time the rendered demo (about 3-4 minutes on
#                             2 idle cores; DEMO_* variables apply)
#   RUNTIME_BASELINE=EXE      another build's rig_calibrator_lab (e.g. of the
#                             previous commit; before the lab, its
#                             rig_calibrator): every calibration run is made
#                             with it first, then with this build, and
#                             runtime.md gets the before/after table
#   RUNTIME_COLMAP_RIG_BA=1   also compare the final bundle adjustment with
#                             COLMAP 3.8's rig_bundle_adjuster (default 100
#                             and 500 framesets x 10 cameras, several minutes
#                             on 2 cores; RUNTIME_COLMAP_RIG_BA_OPTIONS, e.g.
#                             "--framesets 100", replaces the sizes)
#   BENCHMARK_QUICK=1         without options: a smoke run (10 and 20
#                             framesets x 5 cameras, a 30-image map, 4
#                             localized images, this build as its own
#                             baseline, the COLMAP comparison at 10 framesets
#                             x 5 cameras; ~20-40 s), which ctest runs
#                             (benchmark_runtime_quick) so that it cannot rot
set -euo pipefail

log_tag=benchmark_runtime
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

check_arguments 1 "" "$@"
results="$1"
shift

[[ -x "$rig_calibrator_lab" ]] || die "no $rig_calibrator_lab; build first (scripts/build.sh) or set RIG_CALIBRATOR_BUILD_DIR"
mkdir -p "$results" || die "cannot create $results"
results="$(cd "$results" && pwd)"

options=("$@")
if [[ "${BENCHMARK_QUICK:-0}" == 1 && $# -eq 0 ]]; then
  options=(--framesets 10,20 --cameras 5 --map_images 30 --rig_features 1000
           --rig_images 4 --retrieval_images 1 --repeats 2)
  RUNTIME_BASELINE="${RUNTIME_BASELINE:-$rig_calibrator_lab}"
  RUNTIME_COLMAP_RIG_BA="${RUNTIME_COLMAP_RIG_BA:-1}"
  RUNTIME_COLMAP_RIG_BA_OPTIONS="${RUNTIME_COLMAP_RIG_BA_OPTIONS:---quick 1}"
fi
if [[ -n "${RUNTIME_BASELINE:-}" ]]; then
  [[ -x "$RUNTIME_BASELINE" ]] || die "RUNTIME_BASELINE=$RUNTIME_BASELINE is not an executable rig_calibrator_lab"
  options+=(--baseline_executable "$RUNTIME_BASELINE")
fi

echo "[benchmark_runtime] $(nproc) cores, $(uptime)"
status=0
"$rig_calibrator_lab" benchmark_runtime --output_path "$results" "${options[@]}" 2>&1 |
  tee "$results/runtime_log.txt" || status=${PIPESTATUS[0]}
[[ "$status" -eq 0 ]] || die "rig_calibrator_lab benchmark_runtime failed with status $status (log: $results/runtime_log.txt)"

if [[ "${RUNTIME_COLMAP_RIG_BA:-0}" == 1 ]]; then
  # Word-split on purpose: a list of options.
  # shellcheck disable=SC2206
  colmap_ba_options=(${RUNTIME_COLMAP_RIG_BA_OPTIONS:-})
  echo "[benchmark_runtime] final bundle adjustment vs COLMAP's rig_bundle_adjuster ..."
  "$rig_calibrator_lab" benchmark_colmap_rig_ba --output_path "$results" \
    "${colmap_ba_options[@]}" 2>&1 | tee "$results/colmap_rig_ba_log.txt" ||
    status=${PIPESTATUS[0]}
  [[ "$status" -eq 0 ]] || die "rig_calibrator_lab benchmark_colmap_rig_ba failed with status $status (log: $results/colmap_rig_ba_log.txt)"
else
  echo "[benchmark_runtime] COLMAP rig_bundle_adjuster comparison skipped (RUNTIME_COLMAP_RIG_BA=1 runs it)"
fi

if [[ "${RUNTIME_DEMO:-0}" != 1 ]]; then
  echo "[benchmark_runtime] rendered demo skipped (RUNTIME_DEMO=1 times it)"
  exit 0
fi

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
demo_log="$results/runtime_demo_log.txt"
echo "[benchmark_runtime] rendered demo into $work (log: $demo_log) ..."
load_before="$(cut -d' ' -f1-3 /proc/loadavg)"
TIMEFORMAT='%R %U %S'
if ! { time DEMO_SKIP_BUILD=1 RIG_CALIBRATOR_BUILD_DIR="$build" \
    bash "$repo/scripts/demo.sh" "$work/demo" > "$demo_log" 2>&1; } \
    2> "$work/time.txt"; then
  tail -n 20 "$demo_log" >&2
  die "scripts/demo.sh failed (log: $demo_log)"
fi
read -r demo_wall demo_user demo_sys < "$work/time.txt"
load_after="$(cut -d' ' -f1-3 /proc/loadavg)"

# "[build_map] NAME: N s" and "[calibrate_rig] NAME: N s" lines -> rows.
step_rows() {
  local tag="$1" who="$2"
  sed -n "s/^\[$tag\] \(.*\): \([0-9][0-9]*\) s$/| $who | \1 | \2 |/p" "$demo_log"
}
# rig_calibrator's own lines: localization and the calibration core.
localization_s=$(sed -n 's/^  .* 2D-3D correspondences for .* in \([0-9.]*\) s$/\1/p' "$demo_log" | tail -n 1)
calibration_s=$(sed -n 's/^== Result (.*, \([0-9.]*\) s)$/\1/p' "$demo_log" | tail -n 1)
render_s=$(sed -n 's/^  render ([^)]*) *\([0-9][0-9]*\) s$/\1/p' "$demo_log")
total_s=$(sed -n 's/^  total *\([0-9][0-9]*\) s$/\1/p' "$demo_log")
timings_file="$work/demo/rig/calibration/timings.json"

{
  echo "# Rendered demo: end-to-end time"
  echo
  echo "\`DEMO_SKIP_BUILD=1 scripts/demo.sh\` (preset ${DEMO_PRESET:-ring5}, scene ${DEMO_SCENE:-room}," \
       "${DEMO_MAP_IMAGES:-60} map images, ${DEMO_FRAMESETS:-12} framesets)," \
       "load average $load_before before and $load_after after."
  echo "Whole demo: $demo_wall s wall, $demo_user s user + $demo_sys s system CPU."
  echo
  echo "| who | step | wall s |"
  echo "|---|---|---|"
  [[ -n "$render_s" ]] && echo "| ours | render the images (demo input) | $render_s |"
  step_rows build_map COLMAP
  sed -n 's/^\[calibrate_rig\] feature extraction: \([0-9][0-9]*\) s$/| COLMAP | feature extraction of the rig images | \1 |/p' "$demo_log"
  sed -n 's/^\[calibrate_rig\] rig_calibrator: \([0-9][0-9]*\) s$/| ours | rig_calibrator (read, localize, calibrate, write) | \1 |/p' "$demo_log"
  [[ -n "$localization_s" ]] && echo "| ours | of which localization against the map | $localization_s |"
  [[ -n "$calibration_s" ]] && echo "| ours | of which calibration core | $calibration_s |"
  [[ -n "$total_s" ]] && echo "| all | total (with evaluation) | $total_s |"
  if [[ -f "$timings_file" ]]; then
    echo
    echo "Calibration stages (wall s, from timings.json):"
    echo
    echo '```'
    sed -n '/"timings_s"/,/}/p' "$timings_file"
    echo '```'
  fi
} > "$results/runtime_demo.md"
cat "$results/runtime_demo.md"
echo "[benchmark_runtime] wrote $results/runtime_demo.md"
