# Sourced by the scripts, after `set -euo pipefail` and with `log_tag` set to
# the script's name (the prefix of its messages): the repository, the build
# folder, the rig_calibrator binary in it and the lab's (rig_calibrator_lab:
# synthetic data, rendering, benchmarks), and the helpers below.
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${RIG_CALIBRATOR_BUILD_DIR:-$repo/build}"
rig_calibrator="$build/rig_calibrator"
rig_calibrator_lab="$build/rig_calibrator_lab"
# New build folders (build/, the sanitizer's, the fuzzer's) use Ninja, which
# compiles the objects of a library while the libraries below it are still
# compiling; one made earlier keeps its generator.
if [[ -z "${CMAKE_GENERATOR:-}" ]] && command -v ninja > /dev/null 2>&1; then
  export CMAKE_GENERATOR=Ninja
fi

# Prints "[log_tag] ERROR: message" and exits 1.
die() { echo "[$log_tag] ERROR: $*" >&2; exit 1; }

# Prints the header comment of the running script: its usage.
usage() {
  sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'
}

# check_arguments MIN MAX "$@": prints the usage and exits 2 for -h/--help or
# fewer than MIN or more than MAX arguments (MAX empty: no limit).
check_arguments() {
  local min="$1" max="$2"
  shift 2
  if [[ $# -lt $min || (-n "$max" && $# -gt $max) || "${1:-}" == "-h" ||
    "${1:-}" == "--help" ]]; then
    usage >&2
    exit 2
  fi
}

# run_step NAME COMMAND...: runs a step (dies if it fails) and records its
# wall time in `timings`, the name padded to step_name_width characters.
step_name_width=40
timings=()
run_step() {
  local name="$1"
  shift
  local start=$SECONDS
  echo
  echo "[$log_tag] === $name"
  "$@" || die "step '$name' failed"
  timings+=("$(printf "%-${step_name_width}s %5d s" "$name" $((SECONDS - start)))")
}

# print_timings START: the recorded steps and the total since SECONDS was
# START.
print_timings() {
  echo
  echo "[$log_tag] === timings"
  printf '  %s\n' "${timings[@]}"
  printf "  %-${step_name_width}s %5d s\n" "total" $((SECONDS - $1))
}
