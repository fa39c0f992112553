#!/usr/bin/env bash
# The paper's evaluation on synthetic rigs, on a built tree:
#   bash scripts/benchmark.sh [--quick] [RESULTS_DIR]
# writes into RESULTS_DIR (default: benchmark_results/ in the repository)
#  - accuracy.md, accuracy_summary.csv, accuracy_per_camera.csv (paper Table 1)
#  - robustness.md, robustness.csv, robustness_good.svg (paper Table 3) and
#    plots/initial_*.svg, plots/final_*.svg (error distributions, paper Fig. 6)
# then runs scripts/benchmark_runtime.sh RESULTS_DIR (run time, scaling,
# memory) if it exists. --quick: a smoke run of a minute or two.
# The build folder is $RIG_CALIBRATOR_BUILD_DIR, else build/ (scripts/build.sh).
set -euo pipefail

log_tag=benchmark
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
quick=0
if [[ "${1:-}" == "--quick" ]]; then
  quick=1
  shift
fi
[[ $# -le 1 ]] || die "usage: scripts/benchmark.sh [--quick] [RESULTS_DIR]"
results="${1:-$repo/benchmark_results}"
[[ -x "$rig_calibrator_lab" ]] ||
  die "$rig_calibrator_lab not found: build first (bash scripts/build.sh) or set RIG_CALIBRATOR_BUILD_DIR"
mkdir -p "$results" || die "cannot create the results folder $results"

start=$SECONDS
echo "== Accuracy and robustness (rig_calibrator_lab benchmark) into $results"
"$rig_calibrator_lab" benchmark --experiment all --quick "$quick" \
  --output_path "$results" || die "rig_calibrator_lab benchmark failed"
echo "== Accuracy and robustness took $((SECONDS - start)) s"

runtime_script="$repo/scripts/benchmark_runtime.sh"
if [[ -f "$runtime_script" ]]; then
  echo "== Run time, scaling and memory ($runtime_script)"
  BENCHMARK_QUICK="$quick" RIG_CALIBRATOR_BUILD_DIR="$build" \
    bash "$runtime_script" "$results" || die "$runtime_script failed"
fi
echo "Results in $results"
