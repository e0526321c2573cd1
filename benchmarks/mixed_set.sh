#!/bin/bash
# Retrieval against exhaustive pairs on one unordered folder mixing five scenes: every
# image of ../shared/datasets (fountain-P11 11, Herz-Jesus-P8 8, fox 50, sceaux-castle
# 11, lego-100 100: 180 images) copied under shuffled names (a fixed hash of scene and
# name, so the same on every run) and downscaled to MAX_SIZE px (default 800; exhaustive
# at full size takes hours on 2 cores). `tessera bench` runs manifests/default.json
# (exhaustive) and manifests/large_unordered.json (retrieval) on shared features; then
# benchmarks/mixed_set_report.py prints pairs matched, models and registered images per
# scene, position/rotation errors per scene against ground truth (sceaux-castle has
# none), the end-to-end time ratio and the share of exhaustive's verified pairs found.
# usage: benchmarks/mixed_set.sh [MAX_SIZE [THREADS]]
set -euo pipefail
max_size=${1:-800}
threads=${2:-2}
root=$(cd "$(dirname "$0")/.." && pwd)
tessera="$root/build/bin/tessera"
downscale="$root/build/bin/tessera_test_downscale"
datasets="$root/../shared/datasets"
work=${MIXED_SET_WORK:-$(mktemp -d)}
[ -n "${MIXED_SET_WORK:-}" ] || trap 'rm -rf "$work"' EXIT
scenes=(fountain-P11 Herz-Jesus-P8 fox sceaux-castle lego-100)

mkdir -p "$work/mixed"
: > "$work/names.txt"
for scene in "${scenes[@]}"; do
  "$downscale" "$datasets/$scene/images" "$work/small/$scene" "$max_size" 92 > /dev/null
  for file in "$work/small/$scene"/*; do
    name=$(basename "$file")
    shuffled=$(printf '%s/%s' "$scene" "$name" | sha1sum | cut -c1-12).${name##*.}
    cp "$file" "$work/mixed/$shuffled"
    echo "$shuffled $scene $name" >> "$work/names.txt"
  done
done
echo "mixed set: $(ls "$work/mixed" | wc -l) images at most ${max_size} px in $work/mixed"

"$tessera" -q bench --images "$work/mixed" --output "$work/bench" --threads "$threads" \
  --json "$work/bench.json" "$root/manifests/default.json" "$root/manifests/large_unordered.json"
workspaces=$(/usr/bin/python3 -c '
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
print(" ".join(r["workspace"] for r in rows))
e, r = rows
# Features are detected once and shared: charge that time to both runs.
extract = e["extract_seconds"]
total_e = extract + e["match_seconds"] + e["map_seconds"]
total_r = extract + r["match_seconds"] + r["map_seconds"]
print("end-to-end: exhaustive %.0f s (extract %.0f, match %.0f, map %.0f), retrieval %.0f s "
      "(match %.0f, map %.0f): time ratio retrieval/exhaustive %.2f"
      % (total_e, extract, e["match_seconds"], e["map_seconds"], total_r, r["match_seconds"],
         r["map_seconds"], total_r / total_e), file=sys.stderr)' "$work/bench.json")
/usr/bin/python3 "$root/benchmarks/mixed_set_report.py" "$work/names.txt" "$datasets" $workspaces
