#!/usr/bin/env bash
# The test command: sets up the dependencies, builds, and runs the whole suite
# with ctest (arguments go to ctest, e.g. -R Pipeline or -L unit). The fuzz
# pass is not part of it: CI (.ci/run) runs it after this command
# (scripts/fuzz.sh).
set -euo pipefail

log_tag=run_tests
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
jobs="$(nproc 2>/dev/null || echo 2)"

bash "$repo/scripts/build.sh"
cd "$build"
ctest --output-on-failure -j"$jobs" "$@"
