#!/bin/bash
# Extraction and matching on one dataset, Tessera next to COLMAP 3.8 (CPU), on the same
# machine in the same run. Prints seconds per stage, verified pairs and mean inliers
# per verified pair for both, and Tessera's time as a share of COLMAP's.
# usage: benchmarks/features_vs_colmap.sh IMAGES [MANIFEST] [K_FILE]
#   e.g. benchmarks/features_vs_colmap.sh ../shared/datasets/fountain-P11/images
set -euo pipefail
images=$1
manifest=${2:-}
k_file=${3:-}
root=$(cd "$(dirname "$0")/.." && pwd)
tessera="$root/build/bin/tessera"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
stats() {  # verified pairs and mean inliers of a COLMAP-schema database
  sqlite3 "$1" "SELECT COUNT(*), COALESCE(CAST(AVG(rows) AS INTEGER), 0) FROM two_view_geometries
                WHERE rows >= 15 AND config NOT IN (0, 1)" | tr '|' ' '
}
args=()
[ -n "$manifest" ] && args+=(--manifest "$manifest")
[ -n "$k_file" ] && args+=(--camera-K "$k_file")

t0=$(now)
"$tessera" -q extract --images "$images" --output "$work/tessera" "${args[@]}"
t1=$(now)
"$tessera" -q match --output "$work/tessera" ${manifest:+--manifest "$manifest"}
t2=$(now)
read -r t_verified t_inliers < <(stats "$work/tessera/database.db")
t_extract=$(echo "$t1 - $t0" | bc); t_match=$(echo "$t2 - $t1" | bc)

if command -v colmap > /dev/null; then
  export QT_QPA_PLATFORM=offscreen
  c0=$(now)
  colmap feature_extractor --database_path "$work/colmap.db" --image_path "$images" \
    --ImageReader.single_camera 1 --SiftExtraction.use_gpu 0 > "$work/colmap_extract.log" 2>&1
  c1=$(now)
  colmap exhaustive_matcher --database_path "$work/colmap.db" --SiftMatching.use_gpu 0 \
    > "$work/colmap_match.log" 2>&1
  c2=$(now)
  read -r c_verified c_inliers < <(stats "$work/colmap.db")
  c_extract=$(echo "$c1 - $c0" | bc); c_match=$(echo "$c2 - $c1" | bc)
else
  echo "colmap is not installed: COLMAP columns left empty"
  c_extract=""; c_match=""; c_verified=""; c_inliers=""
fi

printf "| system | extract s | match s | extract+match s | verified pairs | mean inliers/pair |\n"
printf "| --- | --- | --- | --- | --- | --- |\n"
printf "| Tessera | %.1f | %.1f | %.1f | %s | %s |\n" "$t_extract" "$t_match" \
  "$(echo "$t_extract + $t_match" | bc)" "$t_verified" "$t_inliers"
if [ -n "$c_extract" ]; then
  printf "| COLMAP 3.8 | %.1f | %.1f | %.1f | %s | %s |\n" "$c_extract" "$c_match" \
    "$(echo "$c_extract + $c_match" | bc)" "$c_verified" "$c_inliers"
  printf "\nTessera extract+match time / COLMAP's: %.2f; mean inliers / COLMAP's: %.2f\n" \
    "$(echo "($t_extract + $t_match) / ($c_extract + $c_match)" | bc -l)" \
    "$(echo "$t_inliers / $c_inliers" | bc -l)"
fi
