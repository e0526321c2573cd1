#!/bin/bash
# Retrieval against exhaustive pairs on one unordered folder mixing five scenes: every
# image of ../shared/datasets (fountain-P11 11, Herz-Jesus-P8 8, fox 50, sceaux-castle
# 11, lego-100 100: 180 images) copied under shuffled names (a fixed hash of scene and
# name, so the same on every run) and downscaled to MAX_SIZE px (default 800; exhaustive
# at full size takes hours on 2 cores). `tessera bench` runs the manifests given
# (default: manifests/default.json, exhaustive, and manifests/large_unordered.json,
# retrieval) on shared features; then benchmarks/mixed_set_report.py prints for each pairs
# matched, models and registered images per scene, position/rotation errors per scene
# against ground truth (sceaux-castle has none), its end-to-end time against the first
# manifest's and the share of the first's verified pairs it found.
# usage: benchmarks/mixed_set.sh [MAX_SIZE [THREADS [MANIFEST...]]]
#   benchmarks/mixed_set.sh 800 2 manifests/default.json manifests/global.json
set -euo pipefail
max_size=${1:-800}
threads=${2:-2}
shift $(($# < 2 ? $# : 2))
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

manifests=("$@")
[ ${#manifests[@]} -gt 0 ] ||
  manifests=("$root/manifests/default.json" "$root/manifests/large_unordered.json")
"$tessera" -q bench --images "$work/mixed" --output "$work/bench" --threads "$threads" \
  --json "$work/bench.json" "${manifests[@]}"
workspaces=$(/usr/bin/python3 -c '
import json, os, sys
rows = json.load(open(sys.argv[1]))["rows"]
print(" ".join(r["workspace"] for r in rows))
# Features are detected once and shared: charge that time to every run.
extract = rows[0]["extract_seconds"]
first = extract + rows[0]["match_seconds"] + rows[0]["map_seconds"]
for row in rows:
    total = extract + row["match_seconds"] + row["map_seconds"]
    print("end-to-end: %s %.0f s (extract %.0f, match %.0f, map %.0f): %.2f of %s'"'"'s time"
          % (os.path.basename(row["workspace"]), total, extract, row["match_seconds"],
             row["map_seconds"], total / first, os.path.basename(rows[0]["workspace"])),
          file=sys.stderr)' "$work/bench.json")
/usr/bin/python3 "$root/benchmarks/mixed_set_report.py" "$work/names.txt" "$datasets" $workspaces
