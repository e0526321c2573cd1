#!/bin/bash
# Bad GPS tags and partitioned mapping with use_gps_prior (issue 47, items 4 and 5) on a
# geotagged copy of fountain-P11 (512 px; tags written by tessera_test_geotag from the
# ground-truth centres about 46.52 N 6.57 E 400 m, 0.25 m of noise), two of its 11
# images tagged 0,0,0 as a phone without a fix writes. With both mappers, mapping the
# whole set and `map --hierarchical` (clusters of at most 9 images):
#  - a warning names each image whose tag is set aside;
#  - sparse/0/georeference.json's origin is the median of the good tags (within 1 m);
#  - the camera centres lie within 1 m of their good tags, with no alignment;
#  - mapping_summary.json's georeference is filled, the PLY says ENU;
#  - `eval --no-align --gt-origin` accepts the model and scores it within 0.5 m.
# Prints the figures (gps_figures.py: origin to the good tags' median, centres to tags).
# usage: gps_outlier_test.sh TESSERA DOWNSCALE GEOTAG SHARED_DIR SOURCE_DIR
set -uo pipefail
source "$(dirname "$0")/common.sh"
start_fountain_gps_test "$@"
figures="$(dirname "$0")/gps_figures.py"

"$downscale" "$dataset/images" "$work/images" 512 90 > /dev/null || fail "downscale"
"$geotag" "$work/images" "$dataset/gt" 46.52 6.57 400 --noise 0.25 --altitude-noise 0.25 \
  --seed 2 --tag 0002.jpg=0,0,0 --tag 0007.jpg=0,0,0 > "$work/tags.txt" || fail "geotag"
for mapper in incremental global; do
  cat > "$work/$mapper.json" <<JSON
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 2000}},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "mapper": {"plugin": "$mapper", "options": {"use_gps_prior": true,
                         "gps_horizontal_sigma": 0.25, "gps_vertical_sigma": 0.25}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": [{"plugin": "colmap_text"}, {"plugin": "ply"}]},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15},
 "distributed": {"cluster_max_images": 9, "cluster_overlap": 3}}
JSON
done
"$tessera" extract --images "$work/images" --output "$work/base" --manifest "$work/incremental.json" \
  --threads 2 2> "$work/extract.log" || { tail "$work/extract.log"; fail "extract"; }
"$tessera" match --output "$work/base" --manifest "$work/incremental.json" --threads 2 \
  2> "$work/match.log" || { tail "$work/match.log"; fail "match"; }

check() {  # check NAME LOG: the model in $work/NAME, mapped with the log LOG
  local out="$work/$1" log=$2
  for image in 0002.jpg 0007.jpg; do
    grep -q "\[warning\] .*image '$image': its GPS tag 0.0000000, 0.0000000, 0 m is set aside: 0, 0 (null island" \
      "$log" || { grep "GPS\|georef" "$log"; fail "$1: no warning naming $image"; }
  done
  python3 "$figures" "$out" "$work/tags.txt" --label "$1" --set-aside 0002.jpg,0007.jpg \
    > "$work/$1.figures" || { cat "$work/$1.figures"; grep "GPS\|georef" "$log"; fail "$1: figures"; }
  cat "$work/$1.figures"
  python3 - "$work/$1.figures" "$out" <<'PY' || fail "$1: the anchored model"
import json, os, sys
values = dict(kv.split("=") for kv in open(sys.argv[1]).read().split("FIGURES")[1].split()[1:])
assert float(values["origin_to_median_m"]) < 1, values
assert float(values["mean_centre_to_tag_m"]) < 1 and float(values["max_centre_to_tag_m"]) < 2, values
summary = json.load(open(os.path.join(sys.argv[2], "mapping_summary.json")))
assert summary["models"][0]["georeference"]["frame"] == "ENU", summary["models"][0]
assert b"comment frame: ENU metres" in open(os.path.join(sys.argv[2], "sparse/0/points3D.ply"), "rb").read(600)
PY
  "$tessera" eval "$out/sparse/0" "$dataset/gt" --no-align --gt-origin 46.52,6.57,400 --json \
    > "$work/$1.eval.json" 2> "$work/$1.eval.log" || { cat "$work/$1.eval.log"; fail "$1: eval --no-align"; }
  python3 - "$work/$1.eval.json" "$1" <<'PY' || fail "$1: eval --no-align figures"
import json, sys
r = json.load(open(sys.argv[1]))
print("%s: eval --no-align: %d registered, position error mean %.3f m" % (sys.argv[2], r["registered"], r["pos_mean"]))
assert r["registered"] >= 9 and r["pos_mean"] < 0.5 and r["alignment_scale"] == 1, r
PY
}

for mapper in incremental global; do
  # The whole set.
  mkdir -p "$work/whole-$mapper" && cp "$work/base/database.db" "$work/whole-$mapper/" || fail "copy"
  "$tessera" map --output "$work/whole-$mapper" --images "$work/images" --manifest "$work/$mapper.json" \
    --threads 2 2> "$work/whole-$mapper.log" || { tail -20 "$work/whole-$mapper.log"; fail "$mapper: map"; }
  check "whole-$mapper" "$work/whole-$mapper.log"
  # Hierarchically: the clusters, then the merge, which anchors the merged model.
  mkdir -p "$work/hier-$mapper" && cp "$work/base/database.db" "$work/hier-$mapper/" || fail "copy"
  "$tessera" map --hierarchical --jobs 2 --threads 1 --output "$work/hier-$mapper" \
    --images "$work/images" --manifest "$work/$mapper.json" > "$work/hier-$mapper.log" 2>&1 ||
    { tail -20 "$work/hier-$mapper.log"; fail "$mapper: map --hierarchical"; }
  grep -q "merge: model 0: anchored to the GPS" "$work/hier-$mapper.log" ||
    { grep "merge:" "$work/hier-$mapper.log"; fail "$mapper: the merged model is not anchored"; }
  check "hier-$mapper" "$work/hier-$mapper.log"
done
echo "PASS"
