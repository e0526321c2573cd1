#!/bin/bash
# Partitioned mapping on the 11 images of the sample examples/fountain-P11-small at 512 px
# (ORB for speed), clusters of at most 9 images sharing 3 with each neighbour:
#  1. a cluster size below 3 overlaps is exit 2 naming distributed.cluster_max_images;
#  2. `partition` writes clusters.json (2 clusters at least) with the camera's focal
#     length, found once for every cluster; `map --cluster K` maps
#     each into OUTPUT/clusters/K, and a finished cluster is skipped when run again;
#     `--cluster` outside the clusters is exit 2;
#  3. `merge --stage map` merges them: one model with all 11 images, every merge
#     decision in mapping_summary.json;
#  3b. `map --hierarchical` does all three on one host, and reuses them when run again;
#  3c. so do `map --cluster-shard K/2` for K = 0, 1 and the merge (the Slurm array's tasks);
#  4. clusters.json of another manifest is exit 2 naming it; a truncated cluster model is
#     exit 2 naming its folder, and the merged model is left untouched; the command the
#     message gives sets the corrupt folder aside and maps the cluster again, and the
#     merge then succeeds;
#  5. clusters.json is input: a focal length of 1e300, an image that is not the
#     workspace's (../../etc/passwd), an image listed twice and an unknown camera are
#     exit 2 naming the file, the cluster and the entry, for map --hierarchical,
#     map --cluster and merge --stage map alike, and the merged model is left untouched;
#  6. SIGTERM or SIGINT to the process of map --hierarchical alone stops every cluster
#     process (gone within a generous 20 s), merges nothing and exits 130; after a kill -9
#     of it, no cluster process is left;
#  7. a hierarchical map in which every cluster fails (failing_mapper) exits 3 and leaves
#     the model that was there.
# usage: partition_test.sh TESSERA DOWNSCALE SOURCE_DIR [FAILING_PLUGINS_DIR]
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
failing_plugins=${4:-}
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
pid="" kids=""
trap '[ -n "$pid" ] && kill -9 $pid $kids 2> /dev/null; rm -rf "$work"' EXIT

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/images" 512 90 > /dev/null ||
  fail "downscale"
manifest() {  # manifest FILE MAX_IMAGES OVERLAP
  cat > "$1" <<JSON
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 2000}},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": [{"plugin": "colmap_binary"}]},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15},
 "distributed": {"cluster_max_images": $2, "cluster_overlap": $3}}
JSON
}
manifest "$work/m.json" 9 3
manifest "$work/small.json" 8 3
manifest "$work/other.json" 10 3
out=$work/out
expect_exit() {  # expect_exit CODE LOG TEXT COMMAND...: exit CODE and TEXT in the output
  local code=$1 log=$2 text=$3
  shift 3
  "$@" > "$log" 2>&1
  local got=$?
  [ "$got" = "$code" ] || { tail -20 "$log"; fail "$*: exit $got, expected $code"; }
  [ -z "$text" ] || grep -qF -- "$text" "$log" || { cat "$log"; fail "$*: no line with '$text'"; }
}
expect_exit 0 "$work/extract.log" "" "$tessera" extract --images "$work/images" --output "$out" \
  --manifest "$work/m.json" --threads 2
expect_exit 0 "$work/match.log" "" "$tessera" match --output "$out" --manifest "$work/m.json" \
  --threads 2

# 1. A cluster size below 3 overlaps.
expect_exit 2 "$work/small.log" "$work/small.json: distributed.cluster_max_images" \
  "$tessera" partition --output "$out" --manifest "$work/small.json"

# 2. Partition, then each cluster.
expect_exit 0 "$work/partition.log" "partition: cluster 0:" \
  "$tessera" partition --output "$out" --manifest "$work/m.json"
num_clusters=$(python3 -c '
import json, sys
c = json.load(open(sys.argv[1]))
assert all(len(k["images"]) <= 9 for k in c["clusters"]), "a cluster over 9 images"
print(len(c["clusters"]))' "$out/clusters.json") || fail "clusters.json"
[ "$num_clusters" -ge 2 ] || fail "clusters.json: $num_clusters clusters, expected 2 or more"
# The images have no EXIF: the camera is calibrated once, on the whole view graph, and
# every cluster maps with it (fountain-P11's focal length, 2759 px at 3072, is 460 px at 512).
python3 -c '
import json, sys
c = json.load(open(sys.argv[1]))["cameras"]
assert len(c) == 1 and abs(c[0]["focal_length"] - 460) < 0.1 * 460, c' "$out/clusters.json" ||
  fail "clusters.json: no calibration near 460 px"
grep -qE "partition: camera 1: focal length [0-9.]+ px .* for every cluster" "$work/partition.log" ||
  fail "partition: the calibration is not logged"
expect_exit 2 "$work/outside.log" "--cluster $num_clusters: " \
  "$tessera" map --output "$out" --manifest "$work/m.json" --cluster "$num_clusters"
for ((k = 0; k < num_clusters; ++k)); do
  expect_exit 0 "$work/map$k.log" "; focal lengths from clusters.json" \
    "$tessera" map --output "$out" --manifest "$work/m.json" --cluster "$k" --threads 2
  [ -f "$out/clusters/$k/sparse/0/images.bin" ] || fail "cluster $k: no model"
done
expect_exit 0 "$work/again.log" "map: cluster 0 is already mapped for this clusters.json" \
  "$tessera" map --output "$out" --manifest "$work/m.json" --cluster 0

# 3. The merge.
expect_exit 0 "$work/merge.log" "merge: $num_clusters clusters into 1 model(s), 11 of 11 images" \
  "$tessera" merge --stage map --output "$out" --manifest "$work/m.json"
python3 -c '
import json, sys
s = json.load(open(sys.argv[1]))
assert len(s["models"]) == 1 and s["models"][0]["num_images"] == 11, s["models"]
merges = s["partition"]["merges"]
assert len(merges) == int(sys.argv[2]) - 1 and all(m["merged"] for m in merges), merges
assert all(m["shared_images"] >= 3 for m in merges), merges' \
  "$out/mapping_summary.json" "$num_clusters" || fail "mapping_summary.json"
[ -f "$out/sparse/0/points3D.bin" ] || fail "no merged model in $out/sparse/0"

# 3b. The same on one host: `map --hierarchical` partitions, maps the clusters in a pool
# of 2 processes and merges them; run again, it reuses clusters.json and every cluster.
mkdir -p "$work/hier"
cp "$out/database.db" "$work/hier/"
expect_exit 0 "$work/hier.log" "merge: $num_clusters clusters into 1 model(s), 11 of 11 images" \
  "$tessera" map --hierarchical --jobs 2 --threads 1 --output "$work/hier" --manifest "$work/m.json"
expect_exit 0 "$work/hier2.log" "map: cluster 0 is already mapped for this clusters.json" \
  "$tessera" map --hierarchical --jobs 2 --threads 1 --output "$work/hier" --manifest "$work/m.json"
grep -qF "clusters.json is current: $num_clusters clusters" "$work/hier2.log" ||
  fail "map --hierarchical again: clusters.json not reused"

# 3c. As `tessera slurm --partitioned` runs it: partition, a mapping array of 2 shards
# (--cluster-shard K/2), the merge.
mkdir -p "$work/sharded"
cp "$out/database.db" "$work/sharded/"
expect_exit 0 "$work/sharded-partition.log" "" \
  "$tessera" partition --output "$work/sharded" --manifest "$work/m.json"
for k in 0 1; do
  expect_exit 0 "$work/sharded$k.log" "map: shard $k/2: " \
    "$tessera" map --output "$work/sharded" --manifest "$work/m.json" --threads 2 --cluster-shard "$k/2"
done
expect_exit 0 "$work/sharded-merge.log" "merge: $num_clusters clusters into 1 model(s), 11 of 11 images" \
  "$tessera" merge --stage map --output "$work/sharded" --manifest "$work/m.json"

# 4. Bad input.
expect_exit 2 "$work/foreign.log" "$out/clusters.json: made with another manifest" \
  "$tessera" map --output "$out" --manifest "$work/other.json" --cluster 0
before=$(cat "$out"/sparse/0/*.bin | md5sum)
size=$(stat -c %s "$out/clusters/1/sparse/0/points3D.bin")
truncate -s $((size / 2)) "$out/clusters/1/sparse/0/points3D.bin"
expect_exit 2 "$work/corrupt.log" "$out/clusters/1: corrupt or truncated cluster folder" \
  "$tessera" merge --stage map --output "$out" --manifest "$work/m.json"
[ "$(cat "$out"/sparse/0/*.bin | md5sum)" = "$before" ] || fail "the merged model changed"
# 4b. The advice works: the command the message gives maps the cluster again.
advice=$(grep -o 'run `tessera map --cluster 1 [^`]*`' "$work/corrupt.log" | head -1 |
  sed 's/^run `tessera //; s/`$//')
[ -n "$advice" ] || { cat "$work/corrupt.log"; fail "merge: no command that maps cluster 1 again"; }
# shellcheck disable=SC2086  # the command as the message gives it (no spaces in $work)
expect_exit 0 "$work/remap.log" "moved aside to $out/clusters/1.corrupt-1, the cluster is mapped again" \
  "$tessera" $advice --threads 2
[ -f "$out/clusters/1.corrupt-1/mapping_summary.json" ] || fail "the corrupt folder was not kept"
expect_exit 0 "$work/merge2.log" "merge: $num_clusters clusters into 1 model(s), 11 of 11 images" \
  "$tessera" merge --stage map --output "$out" --manifest "$work/m.json"

# 5. A forged clusters.json.
cp "$out/clusters.json" "$work/clusters.good.json"
model=$(cat "$out"/sparse/0/*.bin "$out/mapping_summary.json" | md5sum)
forge() {  # forge PYTHON: edits clusters.json, loaded as c
  python3 -c "
import json, sys
c = json.load(open(sys.argv[1]))
$1
json.dump(c, open(sys.argv[1], 'w'))" "$out/clusters.json" || fail "forge: $1"
}
refused() {  # refused NAME TEXT: each command that reads clusters.json is exit 2 with TEXT
  local name=$1 text=$2
  expect_exit 2 "$work/$name-h.log" "$text" "$tessera" map --hierarchical --jobs 2 --threads 1 \
    --output "$out" --manifest "$work/m.json"
  expect_exit 2 "$work/$name-c.log" "$text" "$tessera" map --cluster 0 --output "$out" \
    --manifest "$work/m.json"
  expect_exit 2 "$work/$name-m.log" "$text" "$tessera" merge --stage map --output "$out" \
    --manifest "$work/m.json"
  [ "$(cat "$out"/sparse/0/*.bin "$out/mapping_summary.json" | md5sum)" = "$model" ] ||
    fail "$name: the model that was there changed"
  cp "$work/clusters.good.json" "$out/clusters.json"
}
forge 'c["cameras"][0]["focal_length"] = 1e300'
refused focal "$out/clusters.json: cameras: camera 1: focal_length 1e+300 px gives a field of view of "
forge 'c["clusters"][0]["images"].append("../../etc/passwd")'
refused name "$out/clusters.json: cluster 0: image '../../etc/passwd' is not an image of the workspace ($out/database.db)"
forge 'c["clusters"][1]["images"].append(c["clusters"][1]["images"][0])'
first=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["clusters"][1]["images"][0])' "$out/clusters.json")
refused twice "$out/clusters.json: cluster 1: images: image '$first' is listed twice"
forge 'c["cameras"][0]["camera_id"] = 99'
refused camera "$out/clusters.json: cameras: camera 99: not a camera of the workspace ($out/database.db)"

# 6. Signals to the process of map --hierarchical alone (as a scheduler or `timeout`
# sends them), and kill -9 of it. One cluster process at a time, on a workspace whose
# clusters.json is current and whose clusters are not mapped yet.
alive() { [ -r "/proc/$1/status" ] && ! grep -q '^State:[[:space:]]*Z' "/proc/$1/status"; }
start_hierarchical() {  # start_hierarchical DIR: sets pid, and kids once a cluster runs
  mkdir -p "$1"
  cp "$out/database.db" "$work/clusters.good.json" "$1/"
  mv "$1/clusters.good.json" "$1/clusters.json"
  "$tessera" map --hierarchical --jobs 1 --threads 1 --output "$1" --manifest "$work/m.json" \
    > "$1.log" 2>&1 &
  pid=$!
  kids=""
  local deadline=$((SECONDS + 60))
  while [ -z "$kids" ] && [ "$SECONDS" -lt "$deadline" ] && kill -0 "$pid" 2> /dev/null; do
    kids=$(pgrep -P "$pid" -f -- "--cluster")  # not the plugin probe's child
    sleep 0.05
  done
  [ -n "$kids" ] || { cat "$1.log"; fail "map --hierarchical: no cluster process started"; }
}
all_gone_within_20s() {  # the bound is generous: the test waits on an event, never times it
  local deadline=$((SECONDS + 20)) kid
  for kid in $kids; do
    while alive "$kid"; do
      [ "$SECONDS" -lt "$deadline" ] || return 1
      sleep 0.1
    done
  done
}
for signal in TERM INT; do
  start_hierarchical "$work/sig$signal"
  kill -"$signal" "$pid"
  wait "$pid"
  code=$?
  pid=""
  [ "$code" = 130 ] || { tail -5 "$work/sig$signal.log"; fail "SIG$signal: exit $code, not 130"; }
  all_gone_within_20s || fail "SIG$signal: a cluster process ($kids) outlived its parent by 20 s"
  ! grep -q "merge: " "$work/sig$signal.log" || fail "SIG$signal: the clusters were merged"
  grep -q "map: stopped: " "$work/sig$signal.log" || fail "SIG$signal: no line saying it stopped"
done
# Stopped first, as a cluster busy in a long step is: only a death signal ends them now.
start_hierarchical "$work/kill9"
# shellcheck disable=SC2086
kill -STOP $kids
kill -9 "$pid"
wait "$pid" 2> /dev/null
pid=""
all_gone_within_20s || fail "kill -9: cluster processes ($kids) outlived their parent"
kids=""

# 7. Every cluster fails (the mapper maps nothing): exit 3, the model that was there kept.
if [ -n "$failing_plugins" ]; then
  sed 's/"bundle_adjuster"/"mapper": {"plugin": "failing_mapper"}, "bundle_adjuster"/' \
    "$work/m.json" > "$work/failing.json"
  expect_exit 3 "$work/failing.log" "map --hierarchical: no cluster of $out holds a model" \
    env TESSERA_PLUGIN_PATH="$failing_plugins" "$tessera" map --hierarchical --jobs 2 \
    --threads 1 --output "$out" --manifest "$work/failing.json"
  [ "$(cat "$out"/sparse/0/*.bin "$out/mapping_summary.json" | md5sum)" = "$model" ] ||
    fail "a failed hierarchical map changed the model that was there"
fi
echo "PASS: partition, $num_clusters clusters mapped and merged into one model of 11 images;" \
  "a corrupt cluster mapped again on the message's advice; forged clusters.json refused;" \
  "cluster processes stop with their parent"
