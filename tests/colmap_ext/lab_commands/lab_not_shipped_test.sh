#!/usr/bin/env bash
# The shipped executables hold none of the lab's code: no function that a lab
# library defines (an external symbol of rig_calibrator's namespace, type T
# in `nm`) is in colmap or rig_calibrator, and rig_calibrator_lab holds them,
# among them a few distinctive ones by name (the lab's command table, the
# renderer, the synthetic rigs, an experiment, the runtime benchmark).
# Usage: lab_not_shipped_test.sh COLMAP RIG_CALIBRATOR RIG_CALIBRATOR_LAB
#                                LAB_LIBRARY...
set -euo pipefail
[[ $# -ge 4 ]] || { echo "usage: $0 COLMAP RIG_CALIBRATOR RIG_CALIBRATOR_LAB LAB_LIBRARY..." >&2; exit 2; }
colmap="$1" rig_calibrator="$2" lab="$3"
shift 3
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# defined_functions FILE...: the external functions of rig_calibrator's
# namespace that the files define, demangled, one per line, sorted.
defined_functions() {
  nm -C --defined-only "$@" | sed -n 's/^[0-9a-f]* T \(rig_calibrator::.*\)$/\1/p' | sort -u
}

defined_functions "$@" > "$work/lab"
defined_functions "$lab" > "$work/lab_executable"
fail=0
echo "$(wc -l < "$work/lab") functions defined by the lab's libraries"
for name in 'rig_calibrator::RunRigCalibratorLab(' 'rig_calibrator::RenderImage(' \
            'rig_calibrator::GenerateSyntheticRig(' \
            'rig_calibrator::RunShortSequenceExperiment(' \
            'rig_calibrator::RunRuntimeBenchmarkParent('; do
  if ! grep -qF "$name" "$work/lab"; then
    echo "FAIL: no $name in the lab's libraries"
    fail=1
  fi
  if ! grep -qF "$name" "$work/lab_executable"; then
    echo "FAIL: no $name in $lab"
    fail=1
  fi
done
for executable in "$colmap" "$rig_calibrator"; do
  defined_functions "$executable" > "$work/shipped"
  [[ -s "$work/shipped" ]] || { echo "FAIL: no symbols read from $executable"; fail=1; }
  comm -12 "$work/lab" "$work/shipped" > "$work/common"
  if [[ -s "$work/common" ]]; then
    echo "FAIL: $executable holds $(wc -l < "$work/common") of the lab's functions, e.g.:"
    head -n 10 "$work/common"
    fail=1
  else
    echo "ok: $executable holds none of them ($(wc -l < "$work/shipped") of its own)"
  fi
done
exit "$fail"
