#!/bin/bash
# Every recipe in manifests/ reconstructs a downscaled copy of fountain-P11 (made here, in
# a temporary folder, at 1024 px; no K given): all 11 images in model 0, a mean camera
# position error under 1% of the scene's extent, a mean reprojection error under 1 px.
# Prints, per recipe, verified pairs, registered images and the errors. The
# gaussian_splatting recipe's OUTPUT/gaussian_splatting must load as the 3DGS trainer
# loads a scene (tests/tools/check_3dgs_scene.py).
# usage: recipes_test.sh TESSERA DOWNSCALE SHARED_DIR MANIFEST_DIR
set -uo pipefail
tessera=$1
downscale=$2
shared=${TESSERA_SHARED_DIR:-$3}
manifests=$4
dataset="$shared/datasets/fountain-P11"
source "$(dirname "$0")/common.sh"
require_dataset "$dataset"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$downscale" "$dataset/images" "$work/images" 1024 95 > /dev/null || fail "downscale"
# The recipe run earlier whose detector and camera settings equal this one's, if any.
same_features_as() {
  python3 - "$1" "$manifests" "$done_recipes" << 'PY'
import json, sys
def key(path):
    manifest = json.load(open(path))
    return json.dumps([manifest["pipeline"]["detector"], manifest.get("camera")], sort_keys=True)
mine = key(sys.argv[1])
for recipe in sys.argv[3].split():
    if key(f"{sys.argv[2]}/{recipe}.json") == mine:
        print(recipe)
        break
PY
}
num_recipes=0
done_recipes=""
for manifest in "$manifests"/*.json; do
  recipe=$(basename "$manifest" .json)
  out="$work/$recipe"
  # A recipe with the detector and camera settings of one run before starts from that
  # one's workspace: the run checks what it reuses (features, and matches where the pairs
  # and matcher are the same too) and maps and exports again. Each detector setting is
  # extracted once, which saves minutes of CI time.
  earlier=$(same_features_as "$manifest")
  if [ -n "$earlier" ] && [ -f "$work/$earlier/database.db" ]; then
    mkdir -p "$out" && cp "$work/$earlier/database.db" "$out/"
    echo "$recipe: starts from the workspace of $earlier"
  fi
  "$tessera" run --images "$work/images" --output "$out" --manifest "$manifest" \
    --threads 2 2> "$out.log" || { tail -20 "$out.log"; fail "$recipe: tessera run"; }
  verified=$(sqlite3 "$out/database.db" \
    "SELECT COUNT(*) FROM two_view_geometries WHERE rows >= 15 AND config NOT IN (0, 1)")
  scores=$(model_scores "$tessera" "$out/sparse/0" "$dataset/gt") || fail "$recipe: tessera eval"
  read -r registered rel reproj <<< "$scores"
  echo "$recipe: $verified verified pairs, $registered of 11 registered," \
    "mean position error $rel of the scene extent, mean reprojection error $reproj px"
  [ "$registered" = "11" ] || fail "$recipe: registered $registered of 11 images"
  awk -v r="$rel" 'BEGIN { exit !(r < 0.01) }' || fail "$recipe: position error $rel >= 1%"
  awk -v r="$reproj" 'BEGIN { exit !(r < 1.0) }' || fail "$recipe: reprojection error $reproj px"
  if [ "$recipe" = gaussian_splatting ]; then  # the workspace loads as the 3DGS trainer's
    python3 "$(dirname "$0")/../tools/check_3dgs_scene.py" "$out/gaussian_splatting" 11 ||
      fail "$recipe: OUTPUT/gaussian_splatting does not load as a 3DGS scene"
    grep -q "run: model 0 (sparse/0) holds 11 of 11 images" "$out.log" ||
      fail "$recipe: the run did not say what model 0 holds"
  fi
  num_recipes=$((num_recipes + 1))
  done_recipes="$done_recipes $recipe"
done
[ "$num_recipes" -ge 5 ] || fail "expected at least 5 recipes in $manifests, found $num_recipes"
echo "PASS: $num_recipes recipes"
