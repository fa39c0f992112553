# Sourced by the pipeline scripts: sets `colmap` to the colmap 3.8 binary, in
# this order: $COLMAP, the one scripts/setup_deps.sh built into the cache,
# `colmap` on PATH. Needs a `die` function.
default_colmap="${RIG_CALIBRATOR_CACHE:-$HOME/.cache/rig_calibrator}/colmap-3.8/bin/colmap"
if [[ -n "${COLMAP:-}" ]]; then
  colmap="$COLMAP"
elif [[ -x "$default_colmap" ]]; then
  colmap="$default_colmap"
elif command -v colmap > /dev/null; then
  colmap="$(command -v colmap)"
else
  die "no colmap binary: set COLMAP or run scripts/setup_deps.sh"
fi
[[ -x "$colmap" ]] || die "COLMAP=$colmap is not executable"
