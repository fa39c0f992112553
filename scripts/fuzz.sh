#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz (one per reader and one of the
# whole calibrate command, with AddressSanitizer and
# UndefinedBehaviorSanitizer; clang) into build-fuzz/
# (or $RIG_CALIBRATOR_FUZZ_BUILD_DIR) and runs each for SECONDS seconds,
# starting from its seed corpus tests/fuzz/corpus/<target>/ and the inputs it
# kept from earlier runs (build-fuzz/corpus/<target>/). Prints per target the
# executions, coverage (libFuzzer's cov: edges, ft: features) and the corpus
# size; a crash, sanitizer report, leak, timeout (10 s per input) or
# out-of-memory (2 GB) stops the target, keeps the input in
# build-fuzz/artifacts/ and makes the script fail.
#
# Usage: scripts/fuzz.sh [SECONDS [TARGET...]]   (default 20 s, all targets)
#   RIG_CALIBRATOR_FUZZ_SEED=N  libFuzzer's -seed: the same mutations on every
#                               run (.ci/run sets 1), starting
#                               from the seed corpus alone (the kept inputs
#                               differ between machines, and libFuzzer runs all
#                               of them before it looks at the time: 165 s for
#                               the pipeline target's 850 after 30 minutes);
#                               unset, a new random seed per run, starting from
#                               the kept inputs too
#   Reproduce a crash: build-fuzz/tests/fuzz/<target>_fuzzer <input file>
set -euo pipefail

log_tag=fuzz
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
check_arguments 0 "" "$@"
seconds="${1:-20}"
shift || true
[[ "$seconds" =~ ^[0-9]+$ && "$seconds" -gt 0 ]] ||
  die "SECONDS must be a positive integer, got '$seconds'"
all_targets=(correspondence rig_config camchain rig_layout model rigs_frames
  database_file database_blob pipeline)
targets=("$@")
[[ ${#targets[@]} -gt 0 ]] || targets=("${all_targets[@]}")
cache="${RIG_CALIBRATOR_CACHE:-$HOME/.cache/rig_calibrator}"
jobs="$(nproc 2>/dev/null || echo 2)"
fuzz_build="${RIG_CALIBRATOR_FUZZ_BUILD_DIR:-$repo/build-fuzz}"
start=$SECONDS

bash "$repo/scripts/setup_deps.sh"
export CCACHE_DIR="${CCACHE_DIR:-$cache/ccache}"
export CCACHE_BASEDIR="$repo"

echo "[$log_tag] building the fuzz targets in $fuzz_build (clang, ASan + UBSan)"
cmake -S "$repo" -B "$fuzz_build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER=clang++ -DRIG_CALIBRATOR_FUZZ=ON \
  -DRIG_CALIBRATOR_BUILD_TESTS=OFF -DCMAKE_PREFIX_PATH="$cache/colmap-3.8" \
  > /dev/null || die "configuring $fuzz_build failed (run cmake there to see why)"
cmake --build "$fuzz_build" -j"$jobs" --target "${targets[@]/%/_fuzzer}" \
  || die "building the fuzz targets failed (see the messages above)"

export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}"
mkdir -p "$fuzz_build/artifacts"
summary=()
failed=()
for target in "${targets[@]}"; do
  binary="$fuzz_build/tests/fuzz/${target}_fuzzer"
  seeds="$repo/tests/fuzz/corpus/$target"
  corpus="$fuzz_build/corpus/$target"
  if [[ -n "${RIG_CALIBRATOR_FUZZ_SEED:-}" ]]; then
    corpus="$fuzz_build/corpus-fixed-seed/$target"
    rm -rf "$corpus"
  fi
  log="$fuzz_build/${target}_fuzzer.log"
  [[ -d "$seeds" ]] || die "no seed corpus $seeds"
  mkdir -p "$corpus"
  echo "[$log_tag] $target: fuzzing for $seconds s (log: $log)"
  status=0
  "$binary" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    ${RIG_CALIBRATOR_FUZZ_SEED:+-seed="$RIG_CALIBRATOR_FUZZ_SEED"} \
    -print_final_stats=1 -artifact_prefix="$fuzz_build/artifacts/$target-" \
    "$corpus" "$seeds" > "$log" 2>&1 || status=$?
  execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
  last="$(grep -E '^#[0-9]+' "$log" | tail -1)"
  cov="$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<< "$last")"
  ft="$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<< "$last")"
  units="$(sed -n 's/.* corp: \([0-9]*\)\/.*/\1/p' <<< "$last")"
  result=ok
  if [[ $status -ne 0 ]]; then
    result="FAILED (exit $status): $(grep -m1 -E 'ERROR|runtime error|Timeout|out-of-memory' "$log" || echo "see $log")"
    failed+=("$target")
  fi
  summary+=("$(printf '%-16s %12s %7s %7s %7s  %s' "$target" "${execs:-?}" \
    "${cov:-?}" "${ft:-?}" "${units:-?}" "$result")")
done

echo
echo "[$log_tag] === $seconds s per target"
printf '  %-16s %12s %7s %7s %7s  %s\n' target executions cov ft corpus result
printf '  %s\n' "${summary[@]}"
echo "[$log_tag] total $((SECONDS - start)) s"
if [[ ${#failed[@]} -gt 0 ]]; then
  die "${failed[*]} failed: the inputs are in $fuzz_build/artifacts/; reproduce with $fuzz_build/tests/fuzz/<target>_fuzzer <input>"
fi
echo "[$log_tag] done: no crash in ${#targets[@]} targets"
