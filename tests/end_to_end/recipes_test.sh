#!/bin/bash
# Every recipe in manifests/ reconstructs a downscaled copy of fountain-P11 (made here, in
# a temporary folder, at 1024 px; no K given, except to a recipe that requires one,
# `camera.require_calibration`: it must refuse to run without, and hold the set's K scaled
# to the copy): all 11 images in model 0, a mean camera position error under 1% of the
# scene's extent, a mean reprojection error under 1 px.
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

scale=$("$downscale" "$dataset/images" "$work/images" 1024 95) || fail "downscale"
# The set's K for the copy (the scale the tool printed; pixel centres at +0.5, as
# COLMAP's), written to $work/K.txt; prints fx fy cx cy.
python3 - "$dataset/K.txt" "$scale" "$work/K.txt" << 'PY' > "$work/K.params" ||
import sys
K = [float(v) for v in open(sys.argv[1]).read().split()]
s = float(sys.argv[2])
fx, fy = K[0] * s, K[4] * s
cx, cy = (K[2] + 0.5) * s - 0.5, (K[5] + 0.5) * s - 0.5
open(sys.argv[3], "w").write(f"{fx!r} 0 {cx!r}\n0 {fy!r} {cy!r}\n0 0 1\n")
print(fx, fy, cx, cy)
PY
  fail "scaling K.txt to the copy"
# The parameters of model 0's camera 1 (cameras.bin), as "fx fy cx cy" for a PINHOLE one.
camera_params() {
  python3 - "$1/cameras.bin" << 'PY'
import struct, sys
data = open(sys.argv[1], "rb").read()
camera_id, model, width, height = struct.unpack("<iiQQ", data[8:32])
if model != 1:
    sys.exit(f"camera {camera_id} is model {model}, not PINHOLE (1)")
print(*struct.unpack("<4d", data[32:64]))
PY
}
requires_calibration() {
  python3 -c 'import json, sys; sys.exit(not json.load(open(sys.argv[1])).get("camera", {}).get("require_calibration", False))' "$1"
}
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
  given_K=()
  if requires_calibration "$manifest"; then
    "$tessera" run --images "$work/images" --output "$work/$recipe-no-K" --manifest "$manifest" \
      --threads 2 2> "$out.no-K.log"
    code=$?
    [ "$code" = 2 ] || fail "$recipe without a K: exit $code, expected 2"
    grep -q "camera.require_calibration: this recipe holds the intrinsics, and none were given" \
      "$out.no-K.log" || { cat "$out.no-K.log"; fail "$recipe without a K: no clear error"; }
    echo "$recipe: refuses to run without a K: $(grep -o 'camera.require_calibration.*' "$out.no-K.log")"
    given_K=(--camera-K "$work/K.txt")
  fi
  "$tessera" run --images "$work/images" --output "$out" --manifest "$manifest" \
    --threads 2 "${given_K[@]}" 2> "$out.log" || { tail -20 "$out.log"; fail "$recipe: tessera run"; }
  if [ ${#given_K[@]} -gt 0 ]; then  # the K given is the model's, to the last digit written
    held=$(camera_params "$out/sparse/0") || fail "$recipe: reading its camera"
    python3 -c 'import sys; a, b = (list(map(float, x.split())) for x in sys.argv[1:]); sys.exit(max(abs(p - q) for p, q in zip(a, b)) > 1e-9)' \
      "$held" "$(cat "$work/K.params")" ||
      fail "$recipe: the camera ($held) is not the K given ($(cat "$work/K.params"))"
    echo "$recipe: holds the K given ($held)"
  fi
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
