#!/bin/bash
# The `spatial` pair selector on a geotagged copy of fountain-P11 (downscaled here to
# 1024 px; GPS tags written by tessera_test_geotag from the ground-truth camera centres,
# taken as east/north/up metres about 48.8566 N 2.3522 E, with 1.5 m of horizontal and
# 3 m of vertical noise; 0005.jpg left untagged). The manifest unites `spatial` (4
# nearest within 50 m, no-GPS fallback window 2) with `sequential` (overlap 1):
#  1. `tessera run` registers all 11 images; run_summary.json gives each selector's pair
#     count and the union; the log names the untagged image once; the workspace stores
#     10 GPS positions;
#  2. `tessera match` needs no image folder (it is moved away), and a workspace without
#     metadata rows (made before they were stored) still matches: every image falls back
#     to the window.
# usage: spatial_test.sh TESSERA DOWNSCALE GEOTAG SHARED_DIR SOURCE_DIR
set -uo pipefail
source "$(dirname "$0")/common.sh"
start_fountain_gps_test "$@"

"$downscale" "$dataset/images" "$work/images" 1024 95 > /dev/null || fail "downscale"
"$geotag" "$work/images" "$dataset/gt" 48.8566 2.3522 35 --noise 1.5 --altitude-noise 3 \
  --seed 1 --skip 0005.jpg > "$work/geotag.txt" || fail "geotag"
[ "$(wc -l < "$work/geotag.txt")" -eq 10 ] || fail "geotag tagged $(wc -l < "$work/geotag.txt") images, not 10"

python3 - "$source_dir/manifests/fast.json" "$work" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["pipeline"]["pair_selector"] = [
    {"plugin": "spatial", "options": {"num_neighbors": 4, "max_distance": 50, "fallback_window": 2}},
    {"plugin": "sequential", "options": {"overlap": 1, "quadratic_overlap": False}}]
m["pipeline"]["exporters"] = []
json.dump(m, open(sys.argv[2] + "/spatial.json", "w"))
m["pipeline"]["pair_selector"] = {"plugin": "spatial", "options": {"fallback_window": 2}}
json.dump(m, open(sys.argv[2] + "/spatial_only.json", "w"))
PY

# 1. The run.
out="$work/out"
"$tessera" run --images "$work/images" --output "$out" --manifest "$work/spatial.json" \
  --threads 2 2> "$work/run.log" || { tail -20 "$work/run.log"; fail "tessera run"; }
grep "spatial:" "$work/run.log"
[ "$(grep -c "no GPS position" "$work/run.log")" -eq 1 ] || fail "expected one no-GPS warning"
grep -q "spatial: 1 of 11 images have no GPS position (0005.jpg)" "$work/run.log" ||
  fail "the warning does not name 0005.jpg"
geotagged=$(sqlite3 "$out/database.db" \
  "SELECT COUNT(*) FROM tessera_image_metadata WHERE json_extract(metadata, '$.gps') IS NOT NULL")
[ "$geotagged" = "10" ] || fail "the workspace stores $geotagged GPS positions, not 10"
python3 - "$out/run_summary.json" <<'PY' || fail "run_summary.json"
import json, sys
match = json.load(open(sys.argv[1]))["match"]
selectors = [(s["plugin"], s["json_path"], s["num_pairs"]) for s in match["pairs_per_selector"]]
print("pairs:", selectors, "united:", match["num_pairs"])
assert [s[:2] for s in selectors] == [("spatial", "pipeline.pair_selector[0]"),
                                      ("sequential", "pipeline.pair_selector[1]")], selectors
spatial, sequential = selectors[0][2], selectors[1][2]
assert sequential == 10, sequential
# 10 geotagged images with 4 neighbours each (20 to 40 pairs) plus the untagged image's
# window of 2 on each side (4 pairs): fewer than the 55 of exhaustive matching.
assert 20 + 4 <= spatial <= 40 + 4, spatial
assert max(spatial, sequential) <= match["num_pairs"] <= spatial + sequential, match
PY
scores=$(model_scores "$tessera" "$out/sparse/0" "$dataset/gt") || fail "tessera eval"
read -r registered rel reproj <<< "$scores"
echo "spatial + sequential: $registered of 11 registered, mean position error $rel of the" \
  "scene extent, mean reprojection error $reproj px"
[ "$registered" = "11" ] || fail "registered $registered of 11 images"

# 2. Matching without the image folder, and without stored metadata.
mv "$work/images" "$work/images.moved"
sqlite3 "$out/database.db" "DELETE FROM tessera_image_metadata;" || fail "sqlite3"
"$tessera" match --output "$out" --manifest "$work/spatial_only.json" --threads 2 \
  2> "$work/match.log" || { tail -20 "$work/match.log"; fail "tessera match without metadata"; }
grep -q "spatial: 11 of 11 images have no GPS position" "$work/match.log" ||
  { cat "$work/match.log"; fail "no fallback warning for a workspace without metadata"; }
# The window of 2 on each side: 10 + 9 pairs.
grep -q "match: 19 pairs from 'spatial'," "$work/match.log" ||
  { cat "$work/match.log"; fail "expected the 19 pairs of the fallback window"; }
echo "PASS"
