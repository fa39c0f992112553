#!/usr/bin/env bash
# Builds a COLMAP sparse map from a folder of images with the colmap CLI (CPU;
# the build's colmap, COLMAP 3.8's commands, unless COLMAP says otherwise):
# feature_extractor, sequential (or exhaustive) matching, mapper, and, given
# reference camera positions, model_aligner, so the map is metric and in the
# reference frame.
#
# Usage: scripts/build_map.sh IMAGES_DIR WORK_DIR [REF_POSITIONS] [CAMERA_PARAMS]
#   IMAGES_DIR     the mapping images (one folder; names are the database names)
#   WORK_DIR       created if missing; gets database.db, sparse/0 (the map)
#   REF_POSITIONS  optional file, one "IMAGE_NAME X Y Z" line per image (camera
#                  centers, metric): the map is aligned to them (similarity,
#                  RANSAC with MAP_ALIGN_MAX_ERROR meters); "" to skip
#   CAMERA_PARAMS  optional "fx,fy,cx,cy": one PINHOLE camera with these known
#                  intrinsics (held fixed); otherwise one SIMPLE_RADIAL camera
#                  is estimated
# Environment:
#   COLMAP                 colmap 3.8 binary (default: build/colmap, the
#                          build's extended colmap)
#   MAP_MATCHER            sequential (default) or exhaustive
#   MAP_OVERLAP            sequential matching overlap (default 8)
#   MAP_MAX_FEATURES       SIFT features per image (default 4096)
#   MAP_MIN_REGISTERED     fraction of images the mapper must register
#                          (default 0.8)
#   MAP_ALIGN_MAX_ERROR    alignment inlier threshold in meters (default 0.1)
#   MAP_SCALE_DISTANCE     "IMAGE_A IMAGE_B DISTANCE": scale the map (about
#                          its origin) so that the camera centers of these two
#                          map images are DISTANCE apart (a measured distance,
#                          e.g. between two tripod positions); instead of
#                          REF_POSITIONS
#   MAP_NUM_THREADS        threads for every step (default: all cores)
set -euo pipefail

log_tag=build_map
# shellcheck source=common.sh
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

check_arguments 2 4 "$@"
images_dir="$1"
work_dir="$2"
ref_positions="${3:-}"
camera_params="${4:-}"

# shellcheck source=find_colmap.sh
source "$repo/scripts/find_colmap.sh"

matcher="${MAP_MATCHER:-sequential}"
overlap="${MAP_OVERLAP:-8}"
max_features="${MAP_MAX_FEATURES:-4096}"
min_registered="${MAP_MIN_REGISTERED:-0.8}"
align_max_error="${MAP_ALIGN_MAX_ERROR:-0.1}"
threads="${MAP_NUM_THREADS:--1}"

[[ -d "$images_dir" ]] || die "no image folder $images_dir"
num_images=$(find "$images_dir" -maxdepth 1 -type f \
  \( -iname '*.png' -o -iname '*.jpg' -o -iname '*.jpeg' -o -iname '*.pgm' \
     -o -iname '*.tif' -o -iname '*.tiff' -o -iname '*.bmp' \) | wc -l)
[[ "$num_images" -ge 3 ]] || die "$images_dir holds $num_images images; need at least 3"
[[ -z "$ref_positions" || -f "$ref_positions" ]] || die "no reference positions file $ref_positions"
if [[ -n "$camera_params" && ! "$camera_params" =~ ^[^,]+,[^,]+,[^,]+,[^,]+$ ]]; then
  die "CAMERA_PARAMS must be fx,fy,cx,cy (PINHOLE), got '$camera_params'"
fi
case "$matcher" in
  sequential|exhaustive) ;;
  *) die "MAP_MATCHER must be sequential or exhaustive, got '$matcher'" ;;
esac

mkdir -p "$work_dir"
database="$work_dir/database.db"
[[ ! -e "$database" ]] || die "$database exists; use a fresh WORK_DIR"
[[ ! -e "$work_dir/sparse" ]] || die "$work_dir/sparse exists; use a fresh WORK_DIR"
log="$work_dir/build_map.log"
: > "$log"
echo "[build_map] colmap: $colmap"

# Runs one colmap step, its output in the log, and prints its time.
step() {
  local name="$1"
  shift
  local start=$SECONDS
  echo "[build_map] $name ..."
  if ! "$colmap" "$@" >> "$log" 2>&1; then
    tail -n 20 "$log" >&2
    die "colmap $1 failed (full log: $log)"
  fi
  echo "[build_map] $name: $((SECONDS - start)) s"
}

camera_args=(--ImageReader.single_camera 1)
mapper_args=()
if [[ -n "$camera_params" ]]; then
  camera_args+=(--ImageReader.camera_model PINHOLE
                --ImageReader.camera_params "$camera_params")
  mapper_args+=(--Mapper.ba_refine_focal_length 0
                --Mapper.ba_refine_extra_params 0
                --Mapper.ba_refine_principal_point 0)
else
  camera_args+=(--ImageReader.camera_model SIMPLE_RADIAL)
fi

step "feature extraction ($num_images images)" feature_extractor \
  --database_path "$database" --image_path "$images_dir" "${camera_args[@]}" \
  --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads "$threads" \
  --SiftExtraction.max_num_features "$max_features"

if [[ "$matcher" == sequential ]]; then
  step "sequential matching (overlap $overlap)" sequential_matcher \
    --database_path "$database" --SiftMatching.use_gpu 0 \
    --SiftMatching.num_threads "$threads" \
    --SequentialMatching.overlap "$overlap" \
    --SequentialMatching.quadratic_overlap 0
else
  step "exhaustive matching" exhaustive_matcher \
    --database_path "$database" --SiftMatching.use_gpu 0 \
    --SiftMatching.num_threads "$threads"
fi

mkdir -p "$work_dir/mapper"
step "mapping" mapper --database_path "$database" --image_path "$images_dir" \
  --output_path "$work_dir/mapper" --Mapper.num_threads "$threads" \
  "${mapper_args[@]}"

# The mapper may leave several models (mapper/0, mapper/1, ...): keep the one
# with the most registered images.
best_model=""
best_count=0
for model in "$work_dir"/mapper/*/; do
  [[ -f "$model/images.bin" || -f "$model/images.txt" ]] || continue
  count=$("$colmap" model_analyzer --path "$model" 2>&1 |
          sed -n 's/.*Registered images: *\([0-9]*\).*/\1/p' | head -n 1)
  count="${count:-0}"
  if [[ "$count" -gt "$best_count" ]]; then
    best_count="$count"
    best_model="${model%/}"
  fi
done
[[ -n "$best_model" ]] || die "the mapper reconstructed nothing (log: $log)"
echo "[build_map] the mapper registered $best_count of $num_images images"
if ! awk -v n="$best_count" -v total="$num_images" -v min="$min_registered" \
    'BEGIN { exit !(n >= min * total) }'; then
  die "only $best_count of $num_images images registered (MAP_MIN_REGISTERED=$min_registered)"
fi

# The camera center of a map image, -R^T t, from a text model's images.txt
# (IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, then a line of points).
camera_center() {
  awk -v name="$2" '
    /^#/ { next }
    !odd && $10 == name {
      w = $2; x = $3; y = $4; z = $5; tx = $6; ty = $7; tz = $8
      # Rows of R; the center is -(R^T t), i.e. minus the columns of R dotted with t.
      r00 = 1 - 2*(y*y + z*z); r01 = 2*(x*y - w*z);     r02 = 2*(x*z + w*y)
      r10 = 2*(x*y + w*z);     r11 = 1 - 2*(x*x + z*z); r12 = 2*(y*z - w*x)
      r20 = 2*(x*z - w*y);     r21 = 2*(y*z + w*x);     r22 = 1 - 2*(x*x + y*y)
      printf "%.17g %.17g %.17g\n", -(r00*tx + r10*ty + r20*tz),
        -(r01*tx + r11*ty + r21*tz), -(r02*tx + r12*ty + r22*tz)
      found = 1
    }
    !/^#/ { odd = !odd }
    END { exit !found }' "$1/images.txt"
}

mkdir -p "$work_dir/sparse/0"
if [[ -n "${MAP_SCALE_DISTANCE:-}" ]]; then
  [[ -z "$ref_positions" ]] || die "give REF_POSITIONS or MAP_SCALE_DISTANCE, not both"
  read -r scale_a scale_b scale_distance extra <<< "$MAP_SCALE_DISTANCE"
  [[ -n "$scale_distance" && -z "${extra:-}" ]] ||
    die "MAP_SCALE_DISTANCE must be 'IMAGE_A IMAGE_B DISTANCE', got '$MAP_SCALE_DISTANCE'"
  text_model="$work_dir/scale_text"
  mkdir -p "$text_model"
  "$colmap" model_converter --input_path "$best_model" --output_path "$text_model" \
    --output_type TXT >> "$log" 2>&1 || die "colmap model_converter failed (log: $log)"
  center_a=$(camera_center "$text_model" "$scale_a") ||
    die "MAP_SCALE_DISTANCE: image $scale_a is not in the map"
  center_b=$(camera_center "$text_model" "$scale_b") ||
    die "MAP_SCALE_DISTANCE: image $scale_b is not in the map"
  rm -rf "$text_model"
  scale=$(awk -v a="$center_a" -v b="$center_b" -v d="$scale_distance" 'BEGIN {
    split(a, p, " "); split(b, q, " ")
    map_distance = sqrt((p[1]-q[1])^2 + (p[2]-q[2])^2 + (p[3]-q[3])^2)
    if (d + 0 <= 0 || map_distance < 1e-12) exit 1
    printf "%.17g", d / map_distance }') ||
    die "MAP_SCALE_DISTANCE: DISTANCE must be positive and the two images apart"
  printf '%s 0 0 0\n0 %s 0 0\n0 0 %s 0\n0 0 0 1\n' "$scale" "$scale" "$scale" \
    > "$work_dir/scale_transform.txt"
  step "scaling by $scale ($scale_a to $scale_b: $scale_distance)" model_transformer \
    --input_path "$best_model" --output_path "$work_dir/sparse/0" \
    --transform_path "$work_dir/scale_transform.txt"
elif [[ -n "$ref_positions" ]]; then
  step "alignment to the reference positions" model_aligner \
    --input_path "$best_model" --output_path "$work_dir/sparse/0" \
    --ref_images_path "$ref_positions" --ref_is_gps 0 \
    --alignment_type custom --robust_alignment 1 \
    --robust_alignment_max_error "$align_max_error"
  grep "Alignment error" "$log" | tail -n 1 | sed 's/^/[build_map] /'
else
  cp "$best_model"/* "$work_dir/sparse/0/"
fi
"$colmap" model_analyzer --path "$work_dir/sparse/0" 2>&1 |
  grep -E "Registered images|Points|Mean reprojection error" |
  sed 's/^.*\] //; s/^/[build_map]   /' || true
echo "[build_map] done: map $work_dir/sparse/0, database $database"
