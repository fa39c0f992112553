#!/usr/bin/env bash
# Localization benchmark: throughput of the localization against a real
# COLMAP map on real SIFT (the rendered demo's map and rig images), before
# (every feature searched in the index: --Localization.guided 0, the matching
# before issue 14) and after (--Localization.guided 1
# --Localization.guided_max_ratio 0.6, the defaults: strongest features first,
# then guided along radial lines with a stricter ratio test), alternated on
# the same data in one run; the
# calibration errors against the truth with each; and the index build time,
# memory and throughput on synthetic maps of 10^5 and 10^6 points.
#
# Usage: scripts/benchmark_localization.sh RESULTS_DIR
#   RESULTS_DIR  created if needed; gets localization.md, localization.csv
#                (one row per localization run), calibration_{before,after}/
#                and evaluate_{before,after}.txt, localization_log.txt
# Environment:
#   RIG_CALIBRATOR_BUILD_DIR  build folder with rig_calibrator and
#                             rig_calibrator_lab (default: build/)
#   LOCALIZATION_DEMO_DIR     an output of scripts/demo.sh to reuse (map/sparse/0,
#                             rig/database.db, dataset/); default: RESULTS_DIR/demo,
#                             made by scripts/demo.sh the first time (~4 min idle)
#   LOCALIZATION_REPEATS      before/after pairs of the throughput runs (default 2)
#   LOCALIZATION_SCALE_POINTS synthetic map sizes (default "100000 1000000";
#                             "" skips them)
#   LOCALIZATION_CALIBRATE    0: skip the two calibrations (default 1)
#   BENCHMARK_QUICK=1         a smoke run for CI: a synthetic map of 10 000
#                             points, 10 rig images (no demo, no calibration)
set -euo pipefail

log_tag=benchmark_localization
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

check_arguments 1 1 "$@"
results="$1"
[[ -x "$rig_calibrator" && -x "$rig_calibrator_lab" ]] ||
  die "no $rig_calibrator or $rig_calibrator_lab; build first (scripts/build.sh) or set RIG_CALIBRATOR_BUILD_DIR"
mkdir -p "$results" || die "cannot create $results"
results="$(cd "$results" && pwd)"
csv="$results/localization.csv"
log="$results/localization_log.txt"
rm -f "$csv"
: > "$log"

quick="${BENCHMARK_QUICK:-0}"
repeats="${LOCALIZATION_REPEATS:-2}"
scale_points="${LOCALIZATION_SCALE_POINTS-100000 1000000}"
calibrate="${LOCALIZATION_CALIBRATE:-1}"
scale_rig_images=40
if [[ "$quick" == 1 ]]; then
  repeats=1
  scale_points=10000
  scale_rig_images=10
  calibrate=0
fi
before_flags=(--Localization.guided 0)
after_flags=(--Localization.guided 1 --Localization.guided_max_ratio 0.6)

# bench LABEL DATABASE MODEL [options...]: one localization run, a CSV row.
bench() {
  local label="$1" database="$2" model="$3"
  shift 3
  "$rig_calibrator_lab" benchmark_localization --database_path "$database" \
    --input_path "$model" --label "$label" --csv_path "$csv" "$@" 2>> "$log" |
    tee -a "$log" || die "benchmark_localization $label failed (log: $log)"
}

echo "[benchmark_localization] $(nproc) cores; $(uptime)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

demo=""
if [[ "$quick" != 1 ]]; then
  demo="${LOCALIZATION_DEMO_DIR:-$results/demo}"
  if [[ ! -f "$demo/rig/database.db" ]]; then
    echo "[benchmark_localization] rendering the demo into $demo (scripts/demo.sh) ..."
    DEMO_SKIP_BUILD=1 RIG_CALIBRATOR_BUILD_DIR="$build" \
      bash "$repo/scripts/demo.sh" "$demo" > "$results/demo_log.txt" 2>&1 ||
      die "scripts/demo.sh failed (log: $results/demo_log.txt)"
  fi
  for file in map/sparse/0 rig/database.db dataset/rig_images dataset/ground_truth/rig_config.json; do
    [[ -e "$demo/$file" ]] || die "$demo has no $file: give LOCALIZATION_DEMO_DIR an output of scripts/demo.sh"
  done
  # Throughput on real SIFT, before and after alternated.
  for ((r = 1; r <= repeats; ++r)); do
    bench "demo_before" "$demo/rig/database.db" "$demo/map/sparse/0" "${before_flags[@]}"
    bench "demo_after" "$demo/rig/database.db" "$demo/map/sparse/0" "${after_flags[@]}"
  done
fi

# Index build, memory and throughput on synthetic maps.
for points in $scale_points; do
  map="$work/map_$points"
  "$rig_calibrator_lab" benchmark_localization --write_synthetic_map "$map" \
    --map_points "$points" --rig_images "$scale_rig_images" --rig_features 4096 2>> "$log" |
    tee -a "$log" || die "writing the synthetic map of $points points failed (log: $log)"
  bench "synthetic${points}_before" "$map/database.db" "$map/sparse" "${before_flags[@]}"
  bench "synthetic${points}_after" "$map/database.db" "$map/sparse" "${after_flags[@]}"
  rm -rf "$map"
done

# The calibration with each, against the truth.
if [[ "$calibrate" == 1 ]]; then
  models=$(awk '$1 == "camera_models" { print $2 }' "$demo/dataset/ground_truth/dataset.txt")
  for variant in before after; do
    flags_name="${variant}_flags[@]"
    out="$results/calibration_$variant"
    rm -rf "$out"
    echo "[benchmark_localization] calibration ($variant) ..."
    "$rig_calibrator" --database_path "$demo/rig/database.db" \
      --image_path "$demo/dataset/rig_images" --input_path "$demo/map/sparse/0" \
      --output_path "$out" --RigCalibrator.camera_model "$models" \
      "${!flags_name}" > "$results/calibration_${variant}_log.txt" 2>&1 ||
      die "calibration ($variant) failed (log: $results/calibration_${variant}_log.txt)"
    "$rig_calibrator" evaluate --reference_path "$demo/dataset/ground_truth/rig_config.json" \
      --calibration_path "$out" > "$results/evaluate_$variant.txt" 2>&1 ||
      die "evaluation ($variant) failed (log: $results/evaluate_$variant.txt)"
  done
fi

{
  echo "# Localization throughput"
  echo
  echo "\`scripts/benchmark_localization.sh\`, $(nproc) cores, load average before/after each run in the CSV."
  echo "before: \`${before_flags[*]}\`; after: \`${after_flags[*]}\` (the defaults)."
  echo
  echo "| run | threads | images | features/image | map points | index s (CPU s) | localize s | CPU s | images/s | CPU s/image | CPU utilization | correspondences | searched in index | guided | posed | radial inlier ratio | peak MB |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
  tail -n +2 "$csv" | awk -F, '{
    printf "| %s | %s | %s | %d | %s | %.2f (%.2f) | %.2f | %.2f | %.2f | %.3f | %.2f | %s | %s | %s | %s | %.4f | %.0f |\n",
      $1, $2, $6, $7 / $6, $4, $8, $9, $10, $11, $12, $11 / $6, $13, $14, $15, $16, $17, $18, $19 }'
  echo
  # CPU s per image, after against before, per data set (mean over repeats).
  tail -n +2 "$csv" | awk -F, '{
    split($1, parts, "_"); data = parts[1]; variant = parts[2];
    cpu[data "," variant] += $11 / $6; n[data "," variant] += 1; seen[data] = 1 }
    END { for (d in seen) if (n[d ",after"] > 0 && n[d ",before"] > 0)
      printf "%s: CPU s per image before / after = %.2fx\n", d,
        (cpu[d ",before"] / n[d ",before"]) / (cpu[d ",after"] / n[d ",after"]) }'
  if [[ "$calibrate" == 1 ]]; then
    for variant in before after; do
      echo
      echo "Calibration ($variant), \`rig_calibrator evaluate\` against the true rig:"
      echo
      echo '```'
      grep -E "2D-3D correspondences for|^== Result" "$results/calibration_${variant}_log.txt" || true
      cat "$results/evaluate_$variant.txt"
      echo '```'
    done
  fi
} > "$results/localization.md"
cat "$results/localization.md"
echo "[benchmark_localization] wrote $results/localization.md and $csv"
