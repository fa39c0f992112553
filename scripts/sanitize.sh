#!/usr/bin/env bash
# Builds rig_calibrator and its whole test suite with AddressSanitizer and
# UndefinedBehaviorSanitizer into build-sanitize/ (or
# $RIG_CALIBRATOR_SANITIZE_BUILD_DIR) and runs every test (unit and e2e) there.
# Any ASan or UBSan report fails the test that triggered it. Extra arguments go
# to ctest (e.g. -LE e2e for the unit tests only).
#   RIG_CALIBRATOR_SANITIZE_TARGETS="colmap_io_tests geometry_tests" builds
#   (and so runs) only those test executables (one per tested folder).
#
# Our code is instrumented; COLMAP's, Ceres' and the system's libraries are
# not, so a bug inside them is out of reach, but every access our code makes
# to their memory is checked.
set -euo pipefail

log_tag=sanitize
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
cache="${RIG_CALIBRATOR_CACHE:-$HOME/.cache/rig_calibrator}"
jobs="$(nproc 2>/dev/null || echo 2)"
sanitize_build="${RIG_CALIBRATOR_SANITIZE_BUILD_DIR:-$repo/build-sanitize}"
start=$SECONDS

bash "$repo/scripts/setup_deps.sh"
export CCACHE_DIR="${CCACHE_DIR:-$cache/ccache}"
export CCACHE_BASEDIR="$repo"

# halt_on_error / -fno-sanitize-recover: the first report ends the process
# with a non-zero status, so ctest marks the test failed. gtest_discover_tests
# runs the test executables while building, hence the options are exported
# before the build.
export ASAN_OPTIONS="${ASAN_OPTIONS:-halt_on_error=1:abort_on_error=0:detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
# Leaks of other people's code that we cannot fix (each explained there).
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$repo/scripts/lsan_suppressions.txt:print_suppressions=0}"
# Eigen assumes glibc's malloc is 16-byte aligned except under ASan
# (__SANITIZE_ADDRESS__, Eigen/src/Core/util/Memory.h), where it switches to
# its own offset allocation. COLMAP's uninstrumented code allocates Eigen
# storage with plain malloc and ours would free it with Eigen's offset free:
# a heap-buffer-overflow report on every such object (InputLimits.*,
# CameraUpgrader.*). ASan's malloc is 16-byte aligned too, so both sides are
# told the same.
flags="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
flags+=" -DEIGEN_MALLOC_ALREADY_ALIGNED=1"

run_step "configure ($sanitize_build)" \
  cmake -S "$repo" -B "$sanitize_build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_PREFIX_PATH="$cache/colmap-3.8" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined"
targets=()
for target in ${RIG_CALIBRATOR_SANITIZE_TARGETS:-}; do
  targets+=(--target "$target")
done
run_step "build (ASan + UBSan)" cmake --build "$sanitize_build" -j"$jobs" \
  "${targets[@]}"
run_step "ctest (ASan + UBSan)" \
  ctest --test-dir "$sanitize_build" --output-on-failure -j"$jobs" "$@"
print_timings "$start"
echo "[$log_tag] done: no sanitizer report, every test passed"
