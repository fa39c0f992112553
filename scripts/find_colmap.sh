# Sourced by the pipeline scripts (after common.sh): sets
#   colmap_extended  the build's colmap: COLMAP 3.8's command line plus
#                    `colmap rig_calibrator` (README, "The extended colmap
#                    command"); the scripts calibrate with it;
#   colmap           the colmap of the COLMAP steps (feature_extractor,
#                    mapper, ...): $COLMAP if set (another COLMAP 3.8 CLI),
#                    else the build's.
# Needs a `die` function.
colmap_extended="$build/colmap"
[[ -x "$colmap_extended" ]] ||
  die "no $colmap_extended: build it (scripts/build.sh) or set RIG_CALIBRATOR_BUILD_DIR"
colmap="${COLMAP:-$colmap_extended}"
[[ -x "$colmap" ]] || die "COLMAP=$colmap is not executable"
