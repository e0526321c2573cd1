#!/bin/bash
# `adjust` and `align` (issue 58, items 3 and 4) on a 640 px geotagged copy of fountain-P11
# (GPS tags from the ground-truth centres as east/north/up metres about 46.52 N 6.57 E
# 400 m, 0.25 m of noise per axis), mapped with fast.json:
#  1. align --gps: the centres lie within the tags' noise of their tags, in the frame of
#     the georeference.json it writes (images found as the workspace recorded them);
#  2. adjust on that metric model with every pose moved by 1 cm and turned by 0.5 deg:
#     the mean reprojection error comes back within 1.05x the unperturbed model's;
#     --hold poses keeps the poses as they were, byte for byte;
#  3. align --reference onto the model moved by a known similarity recovers it to 1e-6;
#  4. align --upright: the cameras' mean up direction within 2 deg of +Z (and on a
#     downscaled subset of fox);
#  5. bad input, exit 2 with one line: a model with no cameras, an unknown --hold block,
#     a reference sharing no image.
# usage: toolbox_adjust_align_test.sh TESSERA DOWNSCALE GEOTAG SHARED_DIR SOURCE_DIR
set -uo pipefail
source "$(dirname "$0")/common.sh"
start_fountain_gps_test "$@"
tool="python3 $(dirname "$0")/toolbox_model.py"

"$downscale" "$dataset/images" "$work/images" 640 95 > /dev/null || fail "downscale"
"$geotag" "$work/images" "$dataset/gt" 46.52 6.57 400 --noise 0.25 --altitude-noise 0.25 \
  --seed 3 > "$work/geotag.txt" || fail "geotag"
python3 - "$source_dir/manifests/fast.json" "$work/m.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["pipeline"]["exporters"] = [{"plugin": "colmap_text"}]
json.dump(m, open(sys.argv[2], "w"))
PY
"$tessera" run --images "$work/images" --output "$work/ws" --manifest "$work/m.json" \
  --threads 2 > "$work/run.log" 2>&1 || { tail -20 "$work/run.log"; fail "run"; }
model="$work/ws/sparse/0"
[ -f "$model/images.txt" ] || fail "no text model"

# 1. --gps, the images as the workspace recorded them.
"$tessera" align --model "$model" --output "$work/gps" --gps --gps-sigma 0.25 --json \
  > "$work/gps.json" ||
  fail "align --gps"
[ -f "$work/gps/georeference.json" ] && [ -f "$work/gps/alignment.json" ] ||
  fail "align --gps wrote no georeference.json or alignment.json"
read -r mean max < <($tool gps_distances "$work/gps" "$work/geotag.txt")
echo "align --gps: centres from their tags: mean $mean m, max $max m (tag noise 0.25 m per axis)"
python3 -c "import sys; sys.exit(0 if $mean < 0.6 and $max < 1.5 else 1)" ||
  fail "align --gps: centres $mean m (mean), $max m (max) from their tags"

# 2. adjust: the unperturbed model's error, then the perturbed one's after adjustment.
"$tessera" adjust --model "$work/gps" --output "$work/adj0" --manifest "$work/m.json" --json \
  > "$work/adj0.json" || fail "adjust (unperturbed)"
$tool perturb "$work/gps" "$work/perturbed" 0.01 0.5 1 || fail "perturb"
"$tessera" adjust --model "$work/perturbed" --output "$work/adj" --manifest "$work/m.json" \
  --json > "$work/adj.json" || fail "adjust"
python3 - "$work/adj0.json" "$work/adj.json" <<'PY' || fail "adjust did not bring the error back"
import json, sys
original = json.load(open(sys.argv[1]))["mean_reprojection_error_before"]
s = json.load(open(sys.argv[2]))
print(f"adjust: original {original:.4f} px, perturbed {s['mean_reprojection_error_before']:.4f} px"
      f" -> {s['mean_reprojection_error_after']:.4f} px ({s['num_points3D_filtered']} points"
      f" filtered)")
sys.exit(0 if s["mean_reprojection_error_before"] > 1.5 * original and
         s["mean_reprojection_error_after"] <= 1.05 * original else 1)
PY
[ -f "$work/adj/images.txt" ] && [ -f "$work/adj/georeference.json" ] ||
  fail "adjust: no text model with its georeference.json"
"$tessera" adjust --model "$work/perturbed" --output "$work/held" --hold poses \
  --manifest "$work/m.json" > "$work/held.log" 2>&1 || { cat "$work/held.log"; fail "--hold poses"; }
$tool same_poses "$work/perturbed" "$work/held" || fail "adjust --hold poses moved poses"
if $tool same_poses "$work/perturbed" "$work/adj"; then fail "adjust moved no pose"; fi

# 3. --reference onto a known similarity of the model.
$tool transform "$model" "$work/ref" || fail "transform"
"$tessera" align --model "$model" --output "$work/aligned" --reference "$work/ref" > /dev/null ||
  fail "align --reference"
$tool check_similarity "$work/aligned/alignment.json" 1e-6 || fail "align --reference: not recovered"

# 4. --upright.
"$tessera" align --model "$model" --output "$work/upright" --upright --json \
  > "$work/upright.json" || fail "align --upright"
angle=$($tool up_angle "$work/upright")
echo "align --upright (fountain-P11): mean camera up $angle deg from +Z (before: $($tool up_angle "$model"))"
python3 -c "import sys; sys.exit(0 if $angle < 2 else 1)" || fail "upright: $angle deg from +Z"
fox="$shared/datasets/fox/images"
if [ -d "$fox" ]; then
  mkdir -p "$work/fox_all" "$work/fox_images"
  "$downscale" "$fox" "$work/fox_all" 480 90 > /dev/null || fail "downscale fox"
  ls "$work/fox_all" | sort | awk 'NR % 2 == 1' | head -12 |
    while read -r f; do cp "$work/fox_all/$f" "$work/fox_images/"; done
  "$tessera" run --images "$work/fox_images" --output "$work/fox" --manifest "$work/m.json" \
    --threads 2 > "$work/fox.log" 2>&1 || { tail -20 "$work/fox.log"; fail "run fox"; }
  "$tessera" align --model "$work/fox/sparse/0" --output "$work/fox_up" --upright > /dev/null ||
    fail "align --upright fox"
  angle=$($tool up_angle "$work/fox_up")
  echo "align --upright (fox, 12 images): mean camera up $angle deg from +Z (before: $($tool up_angle "$work/fox/sparse/0"))"
  python3 -c "import sys; sys.exit(0 if $angle < 2 else 1)" || fail "fox upright: $angle deg"
else
  skip_part_or_fail "$fox not found: upright on fox"
fi

# 5. Bad input: exit 2, one line.
refused() {  # refused WHAT ARGS...: exit 2 and one line on stderr
  local what=$1
  shift
  "$tessera" "$@" > "$work/out.txt" 2> "$work/err.txt"
  local rc=$?
  [ "$rc" = 2 ] || { cat "$work/err.txt"; fail "$what: exit $rc, not 2"; }
  [ "$(wc -l < "$work/err.txt")" = 1 ] || { cat "$work/err.txt"; fail "$what: not one line"; }
  echo "$what: $(cat "$work/err.txt")"
}
mkdir -p "$work/empty"
: > "$work/empty/cameras.txt"
: > "$work/empty/images.txt"
: > "$work/empty/points3D.txt"
refused "no cameras" adjust --model "$work/empty" --output "$work/x1"
grep -q "has no cameras" "$work/err.txt" || fail "no cameras: not said"
refused "no cameras (align)" align --model "$work/empty" --output "$work/x2" --upright
refused "unknown --hold" adjust --model "$model" --output "$work/x3" --hold poses,focal
grep -q -- "--hold: unknown block 'focal'" "$work/err.txt" || fail "--hold: not named"
$tool rename "$model" "$work/renamed" || fail "rename"
refused "no shared image" align --model "$model" --output "$work/x4" --reference "$work/renamed"
grep -qF "$model and $work/renamed share 0" "$work/err.txt" || fail "not both models named"
[ ! -e "$work/x1" ] && [ ! -e "$work/x3" ] && [ ! -e "$work/x4" ] || fail "a refused verb wrote"
echo "PASS"
