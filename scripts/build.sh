#!/usr/bin/env bash
# Sets up the dependencies (scripts/setup_deps.sh) and builds rig_calibrator into
# build/ (or $RIG_CALIBRATOR_BUILD_DIR). The executables are build/colmap
# (COLMAP 3.8's command line plus `colmap rig_calibrator`),
# build/rig_calibrator (the same rig_calibrator commands on their own) and
# build/rig_calibrator_lab (the lab: synthetic data, rendering, benchmarks).
set -euo pipefail

log_tag=build
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cache="${RIG_CALIBRATOR_CACHE:-$HOME/.cache/rig_calibrator}"
jobs="$(nproc 2>/dev/null || echo 2)"

bash "$repo/scripts/setup_deps.sh"

# ccache (when installed) keeps compiled objects in the cache folder, keyed by
# paths relative to the checkout, so a fresh clone elsewhere reuses them.
export CCACHE_DIR="${CCACHE_DIR:-$cache/ccache}"
export CCACHE_BASEDIR="$repo"

echo "[build] configuring and building rig_calibrator in $build"
cmake -S "$repo" -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$cache/colmap-3.8" > /dev/null \
  || { echo "[build] ERROR: configuring failed (run cmake in $build to see why)" >&2; exit 1; }
cmake --build "$build" -j"$jobs" \
  || { echo "[build] ERROR: compiling failed (see the messages above)" >&2; exit 1; }
echo "[build] done: $build/colmap, $build/rig_calibrator, $build/rig_calibrator_lab"
