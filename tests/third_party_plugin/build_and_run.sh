#!/bin/bash
# Installs Tessera from BUILD_DIR into a temporary prefix, builds this folder's plugin
# against the installed SDK alone, then lists and runs it through a manifest, and
# compares it with the bundled ORB detector in a `tessera bench` run (everything else
# the same): both rows register all 11 images of the small fountain sample.
# usage: build_and_run.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build_dir=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake --install "$build_dir" --prefix "$work/prefix" > "$work/install.log"
# Only the installed tree: no path into the Tessera sources or build.
cmake -S "$source_dir" -B "$work/build" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$work/prefix" > "$work/configure.log"
cmake --build "$work/build" -j2 > "$work/build.log"

cat > "$work/manifest.json" <<JSON
{
  "plugin_paths": ["build/plugins"],
  "pipeline": {
    "detector": {"plugin": "akaze", "options": {"max_num_features": 500}},
    "pair_selector": {"plugin": "exhaustive"},
    "matcher": {"plugin": "brute_force"}
  }
}
JSON
tessera="$work/prefix/bin/tessera"
listing=$("$tessera" plugins --json --manifest "$work/manifest.json")
echo "$listing" | grep -q '"name": "akaze"' || { echo "akaze not listed:"; echo "$listing"; exit 1; }
echo "$listing" | grep -q '"name": "sift"' || { echo "bundled sift not found by the installed binary"; exit 1; }

mkdir -p "$work/images"
examples="$source_dir/../../examples/fountain-P11-small/images"
cp "$examples/0004.jpg" "$examples/0005.jpg" "$examples/0006.jpg" "$work/images/"
{ "$tessera" extract --images "$work/images" --output "$work/out" --manifest "$work/manifest.json" &&
  "$tessera" match --output "$work/out" --manifest "$work/manifest.json"; } \
  2> "$work/run.log" || { cat "$work/run.log"; exit 1; }
cat "$work/run.log"
grep -q "3 detected with" "$work/run.log" || { echo "akaze did not detect 3 images"; exit 1; }
grep -Eq "3 pairs, 3 matched now" "$work/run.log" || { echo "pairs were not matched"; exit 1; }

# A bench row next to a bundled detector, all else equal.
for detector in akaze orb; do
  cat > "$work/$detector.json" <<JSON
{
  "plugin_paths": ["build/plugins"],
  "pipeline": {
    "detector": {"plugin": "$detector", "options": {"max_num_features": 4000}},
    "pair_selector": {"plugin": "exhaustive"},
    "matcher": {"plugin": "brute_force"},
    "bundle_adjuster": {"plugin": "ceres"}
  }
}
JSON
done
"$tessera" bench --images "$examples" --output "$work/bench" --json "$work/bench.json" \
  "$work/orb.json" "$work/akaze.json" 2> "$work/bench.log" || { cat "$work/bench.log"; exit 1; }
python3 - "$work/bench.json" <<'PY' || exit 1
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
assert [r["plugins"].split(" / ")[0] for r in rows] == ["orb", "akaze"], rows
for r in rows:
    assert r["exit_code"] == 0 and r["num_registered"] == 11, r
    print("%s: %d of 11 registered, %d points, %.3f px" % (
        r["manifest"], r["num_registered"], r["num_points3D"], r["mean_reprojection_error_px"]))
PY
echo "third-party plugin built against the installed SDK, ran, and has its bench row"
