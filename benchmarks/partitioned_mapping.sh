#!/bin/bash
# Partitioned mapping (`tessera map --hierarchical`) against one unpartitioned run, on a
# dataset with ground truth. `tessera run` maps the whole set once (extract, match, map)
# with MANIFEST; then for each SIZE a copy of that workspace (database.db and cache/: the
# same features and matches) is mapped by `tessera map --hierarchical --jobs JOBS` with
# MANIFEST plus "distributed": {"cluster_max_images": SIZE, "cluster_overlap": SIZE / 4
# (rounded down, at least 3)}. Each model 0 is scored by `tessera eval MODEL GT --json`,
# and one row per run is printed: clusters, registered images, models, mean and max
# rotation error, cameras over 5 degrees off, mean position error as a share of the
# extent, and the map seconds (whole: the map stage of `run`, from mapping_summary.json;
# partitioned: the whole `map --hierarchical` command, and of it the clusters' pool and
# the merge, from its log).
# usage: benchmarks/partitioned_mapping.sh DATASET MANIFEST SIZE [SIZE...]
#   DATASET holds images/ and transforms.json (../shared/datasets/lego-100, .../fox)
#   benchmarks/partitioned_mapping.sh ../shared/datasets/lego-100 manifests/large_unordered.json 30 50
# Environment: PARTITIONED_WORK keeps the work folder there (default: a temporary one,
# removed); PARTITIONED_JOBS (default 2) and PARTITIONED_THREADS (default 2: `run`'s
# threads; each cluster process gets its share).
set -euo pipefail
[ $# -ge 3 ] || { sed -n '13,15p' "$0"; exit 2; }
dataset=$(cd "$1" && pwd)
manifest=$(cd "$(dirname "$2")" && pwd)/$(basename "$2")
shift 2
sizes=("$@")
jobs=${PARTITIONED_JOBS:-2}
threads=${PARTITIONED_THREADS:-2}
root=$(cd "$(dirname "$0")/.." && pwd)
tessera="$root/build/bin/tessera"
gt="$dataset/transforms.json"
work=${PARTITIONED_WORK:-$(mktemp -d)}
mkdir -p "$work"
[ -n "${PARTITIONED_WORK:-}" ] || trap 'rm -rf "$work"' EXIT
rows="$work/rows.txt"
: > "$rows"

# row NAME WORKSPACE LOG MAP_SECONDS: scores model 0 and appends a row to $rows.
row() {
  local name=$1 out=$2 log=$3 seconds=$4
  "$tessera" eval "$out/sparse/0" "$gt" --json > "$out/eval.json" 2> "$out/eval.log" ||
    { cat "$out/eval.log"; echo "$name: eval failed"; exit 1; }
  /usr/bin/python3 - "$name" "$out" "$log" "$seconds" >> "$rows" <<'PY'
import json, os, re, sys
name, out, log, seconds = sys.argv[1:]
e = json.load(open(os.path.join(out, "eval.json")))
summary = json.load(open(os.path.join(out, "mapping_summary.json")))
text = open(log).read()
clusters = "-"
path = os.path.join(out, "clusters.json")
if os.path.exists(path):
    clusters = str(len(json.load(open(path))["clusters"]))
pool = re.findall(r"map: \d+ clusters mapped in ([0-9.]+) s", text)
merge = re.findall(r"merge: \d+ clusters into .* ([0-9.]+) s", text)
lost = summary.get("partition", {}).get("images_lost_in_final_adjustment", [])
refused = [m for m in summary.get("partition", {}).get("merges", []) if not m.get("merged", True)]
print("%s|%s|%d/%d|%d|%.3f|%.3f|%d|%.3f|%.1f|%s|%s|%d|%d" % (
    name, clusters, e["registered"], e["total"], len(summary["models"]), e["rot_mean_deg"],
    e["rot_max_deg"], e["wrongly_registered"], 100 * e["pos_mean_rel"], float(seconds),
    pool[-1] if pool else "-", merge[-1] if merge else "-", len(refused), len(lost)))
PY
}

# The whole set, unpartitioned.
whole="$work/whole"
echo "## $(basename "$dataset"), $(basename "$manifest"): tessera run (unpartitioned)"
"$tessera" run --images "$dataset/images" --output "$whole" --manifest "$manifest" \
  --threads "$threads" > "$work/whole.log" 2>&1 || { tail -20 "$work/whole.log"; exit 1; }
row whole "$whole" "$work/whole.log" \
  "$(/usr/bin/python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["seconds"])' \
    "$whole/mapping_summary.json")"

for size in "${sizes[@]}"; do
  overlap=$((size / 4 < 3 ? 3 : size / 4))
  [ "$size" -ge $((3 * overlap)) ] || { echo "SIZE $size: under 3 overlaps of $overlap"; exit 2; }
  out="$work/clusters_$size"
  rm -rf "$out" && mkdir -p "$out"
  cp "$whole/database.db" "$out/"
  [ ! -d "$whole/cache" ] || cp -r "$whole/cache" "$out/"
  /usr/bin/python3 - "$manifest" "$work/manifest_$size.json" "$size" "$overlap" <<'PY'
import json, sys
manifest = json.load(open(sys.argv[1]))
manifest["distributed"] = {"cluster_max_images": int(sys.argv[3]), "cluster_overlap": int(sys.argv[4])}
json.dump(manifest, open(sys.argv[2], "w"), indent=2)
PY
  echo "## clusters of at most $size sharing $overlap: tessera map --hierarchical --jobs $jobs"
  start=$(date +%s.%N)
  "$tessera" map --output "$out" --images "$dataset/images" --manifest "$work/manifest_$size.json" \
    --hierarchical --jobs "$jobs" > "$work/clusters_$size.log" 2>&1 ||
    { tail -20 "$work/clusters_$size.log"; exit 1; }
  row "clusters_$size" "$out" "$work/clusters_$size.log" "$(echo "$(date +%s.%N) - $start" | bc -l)"
  grep -E "left unmerged|undone|possibly_folded|remain unmerged" \
    "$work/clusters_$size.log" || true
done

echo
/usr/bin/python3 - "$rows" <<'PY'
import sys
head = ["run", "clusters", "registered", "models", "rot mean deg", "rot max deg", "> 5 deg",
        "pos mean % extent", "map s", "clusters s", "merge s", "merges refused", "lost in final BA"]
print("| " + " | ".join(head) + " |")
print("|" + " --- |" * len(head))
for line in open(sys.argv[1]):
    print("| " + " | ".join(line.rstrip("\n").split("|")) + " |")
PY
echo "map s: whole, the map stage of tessera run; clusters_N, the whole map --hierarchical command"
