#!/bin/bash
# The whole pipeline on one dataset, Tessera next to COLMAP 3.8 (CPU), on the same
# machine in the same run: seconds per stage (extract, match, map), verified pairs, mean
# inliers per verified pair, registered images and, with ground truth, the mean camera
# position error of each model by `tessera eval`. Ends with Tessera's times as a share
# of COLMAP's: extract+match (issue 3's target: at most 1/3) and end to end (issue 4's).
# usage: benchmarks/pipeline_vs_colmap.sh IMAGES [GT] [MANIFEST]
#   e.g. benchmarks/pipeline_vs_colmap.sh ../shared/datasets/fountain-P11/images \
#          ../shared/datasets/fountain-P11/gt
# Run it alone on the machine: both systems use every core.
set -euo pipefail
images=$1
gt=${2:-}
manifest=${3:-}
root=$(cd "$(dirname "$0")/.." && pwd)
tessera="$root/build/bin/tessera"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
stats() {  # verified pairs and mean inliers of a COLMAP-schema database
  sqlite3 "$1" "SELECT COUNT(*), COALESCE(CAST(AVG(rows) AS INTEGER), 0) FROM two_view_geometries
                WHERE rows >= 15 AND config NOT IN (0, 1)" | tr '|' ' '
}
num_images() {  # registered images of a binary model: the first 8 bytes of images.bin
  od -An -t u8 -N 8 "$1/images.bin" | tr -d ' '
}
position_error() {  # mean camera position error of a model in ground-truth units
  [ -n "$gt" ] || { echo "-"; return; }
  "$tessera" -q eval "$1" "$gt" --json |
    python3 -c 'import json, sys
e = json.load(sys.stdin)
print("%.5f (%.3f%% of the extent)" % (e["pos_mean"], 100 * e["pos_mean_rel"]))'
}
args=()
[ -n "$manifest" ] && args+=(--manifest "$manifest")

t0=$(now)
"$tessera" -q extract --images "$images" --output "$work/tessera" "${args[@]}"
t1=$(now)
"$tessera" -q match --output "$work/tessera" "${args[@]}"
t2=$(now)
"$tessera" -q map --images "$images" --output "$work/tessera" "${args[@]}"
t3=$(now)
read -r t_verified t_inliers < <(stats "$work/tessera/database.db")
t_extract=$(echo "$t1 - $t0" | bc); t_match=$(echo "$t2 - $t1" | bc)
t_map=$(echo "$t3 - $t2" | bc)
t_registered=$(num_images "$work/tessera/sparse/0")
t_error=$(position_error "$work/tessera/sparse/0")

have_colmap=0
if command -v colmap > /dev/null; then
  have_colmap=1
  export QT_QPA_PLATFORM=offscreen
  c0=$(now)
  colmap feature_extractor --database_path "$work/colmap.db" --image_path "$images" \
    --ImageReader.single_camera 1 --SiftExtraction.use_gpu 0 > "$work/colmap_extract.log" 2>&1
  c1=$(now)
  colmap exhaustive_matcher --database_path "$work/colmap.db" --SiftMatching.use_gpu 0 \
    > "$work/colmap_match.log" 2>&1
  c2=$(now)
  mkdir -p "$work/colmap_sparse"
  colmap mapper --database_path "$work/colmap.db" --image_path "$images" \
    --output_path "$work/colmap_sparse" > "$work/colmap_map.log" 2>&1
  c3=$(now)
  read -r c_verified c_inliers < <(stats "$work/colmap.db")
  c_extract=$(echo "$c1 - $c0" | bc); c_match=$(echo "$c2 - $c1" | bc)
  c_map=$(echo "$c3 - $c2" | bc)
  c_registered=$(num_images "$work/colmap_sparse/0")
  c_error=$(position_error "$work/colmap_sparse/0")
else
  echo "colmap is not installed: no COLMAP row"
fi

row() {  # system extract match map verified inliers registered error
  printf "| %s | %.1f | %.1f | %.1f | %.1f | %s | %s | %s | %s |\n" "$1" "$2" "$3" "$4" \
    "$(echo "$2 + $3 + $4" | bc)" "$5" "$6" "$7" "$8"
}
echo "| system | extract s | match s | map s | total s | verified pairs | mean inliers/pair" \
  "| registered | mean position error (ground-truth units) |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
row Tessera "$t_extract" "$t_match" "$t_map" "$t_verified" "$t_inliers" "$t_registered" "$t_error"
if [ "$have_colmap" = 1 ]; then
  row "COLMAP 3.8" "$c_extract" "$c_match" "$c_map" "$c_verified" "$c_inliers" \
    "$c_registered" "$c_error"
  printf "\nTessera / COLMAP: extract+match time %.2f, end-to-end time %.2f," \
    "$(echo "($t_extract + $t_match) / ($c_extract + $c_match)" | bc -l)" \
    "$(echo "($t_extract + $t_match + $t_map) / ($c_extract + $c_match + $c_map)" | bc -l)"
  printf " mean inliers per pair %.2f\n" "$(echo "$t_inliers / $c_inliers" | bc -l)"
fi
