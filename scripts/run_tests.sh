#!/usr/bin/env bash
# The test command: sets up dependencies, builds, and runs the whole suite with ctest.
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${RIG_CALIBRATOR_BUILD_DIR:-$repo/build}"
jobs="$(nproc 2>/dev/null || echo 2)"

bash "$repo/scripts/build.sh"
cd "$build"
ctest --output-on-failure -j"$jobs" "$@"
