#!/usr/bin/env bash
# The test command: sets up dependencies, builds, and runs the whole suite with
# ctest, then every fuzz target for a short time (scripts/fuzz.sh,
# $RIG_CALIBRATOR_FUZZ_SECONDS seconds each, default 15; 0 skips it).
set -euo pipefail

log_tag=run_tests
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
jobs="$(nproc 2>/dev/null || echo 2)"

bash "$repo/scripts/build.sh"
cd "$build"
ctest --output-on-failure -j"$jobs" "$@"
fuzz_seconds="${RIG_CALIBRATOR_FUZZ_SECONDS:-15}"
if [[ "$fuzz_seconds" != 0 ]]; then
  # A fixed seed: the short pass is the same on every run, so a crash it
  # finds is one of the commit, not of the draw; longer runs of
  # scripts/fuzz.sh draw their own.
  RIG_CALIBRATOR_FUZZ_SEED="${RIG_CALIBRATOR_FUZZ_SEED:-1}" \
    bash "$repo/scripts/fuzz.sh" "$fuzz_seconds"
fi
