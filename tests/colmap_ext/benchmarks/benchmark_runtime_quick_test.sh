#!/usr/bin/env bash
# The quick mode of scripts/benchmark_runtime.sh (BENCHMARK_QUICK=1), so that
# the benchmark command and its reports cannot rot: it must succeed and write
# the calibration and localization tables, the CSV files and the before/after
# table (this build against itself), and the comparison with COLMAP's
# rig_bundle_adjuster (its table and CSV). No time is asserted.
# Usage: benchmark_runtime_quick_test.sh BUILD_DIR
set -euo pipefail
build="$1"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

BENCHMARK_QUICK=1 RIG_CALIBRATOR_BUILD_DIR="$build" \
  bash "$repo/scripts/benchmark_runtime.sh" "$work/out" > "$work/log.txt" 2>&1 ||
  { cat "$work/log.txt"; echo "FAIL: benchmark_runtime.sh quick mode failed"; exit 1; }

fail=0
check() {  # check DESCRIPTION COMMAND...
  local what="$1"
  shift
  if "$@"; then echo "ok: $what"; else echo "FAIL: $what"; fail=1; fi
}
for file in runtime.md runtime_calibration.csv runtime_calibration_before.csv \
            runtime_calibration.svg runtime_localization.csv; do
  check "$file written" test -s "$work/out/$file"
done
# Header + 2 runs (10 and 20 framesets x 5 cameras), before and after.
check "2 calibration runs in the CSV" test "$(wc -l < "$work/out/runtime_calibration.csv")" -eq 3
check "2 baseline runs in the CSV" test "$(wc -l < "$work/out/runtime_calibration_before.csv")" -eq 3
check "iteration columns" grep -q '"Final bundle adjustment iterations"' "$work/out/runtime_calibration.csv"
check "before/after table" grep -q '^| \*\*total\*\* |' "$work/out/runtime.md"
check "medians of the 2 repeats" grep -q '2 times alternating; every time is the median' "$work/out/runtime.md"
check "core count and load noted" grep -q 'cores online; load average' "$work/out/runtime.md"
for file in colmap_rig_ba.md colmap_rig_ba.csv; do
  check "$file written" test -s "$work/out/$file"
done
# Header + ours and COLMAP at 10 framesets x 5 cameras.
check "2 solver rows in the COLMAP comparison CSV" test "$(wc -l < "$work/out/colmap_rig_ba.csv")" -eq 3
check "COLMAP's row" grep -q 'COLMAP 3.8 rig_bundle_adjuster' "$work/out/colmap_rig_ba.csv"
check "ratio row" grep -q '| \*\*COLMAP / ours\*\* |' "$work/out/colmap_rig_ba.md"
check "load noted in the comparison" grep -q 'cores online; load average' "$work/out/colmap_rig_ba.md"
check "every calibration succeeded" bash -c "! grep -q FAILED '$work/log.txt'"
if [[ "$fail" -ne 0 ]]; then
  cat "$work/log.txt"
  exit 1
fi
echo "benchmark_runtime quick mode: ok"
