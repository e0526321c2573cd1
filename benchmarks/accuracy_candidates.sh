#!/bin/bash
# What each candidate for the accuracy record (issue 49) gives on one set with ground
# truth: a recipe (default manifests/global.json) run once, then each candidate as a
# change to that recipe, and a Markdown table of the mean camera position error (after a
# similarity alignment, `tessera eval`) and the time of each.
#  - Candidates of the map stage (bundle adjustment's loss, the final filter's threshold,
#    the final adjustment run to convergence) map a copy of the first run's database
#    (`tessera map`): same features and matches.
#  - Candidates of the features or the camera (more features, full resolution, another
#    matcher ratio, another camera model, the set's K.txt given and held) run the whole
#    pipeline (`tessera run`).
# A recipe that requires a calibration (camera.require_calibration, calibrated.json) gets
# the set's K.txt in every run, and the camera candidates are left out: it holds K.
# usage: benchmarks/accuracy_candidates.sh OUT SET [MANIFEST]
#   SET: a folder of ../shared/datasets with images/, gt/ (*.camera) and K.txt
#   (fountain-P11, Herz-Jesus-P8). One thread per run (TESSERA_THREADS to change it).
set -uo pipefail
out=$1
set_name=$2
root=$(cd "$(dirname "$0")/.." && pwd)
manifest=$(readlink -f "${3:-$root/manifests/global.json}")
out=$(mkdir -p "$out" && cd "$out" && pwd)
cd "$root"
tessera=$(readlink -f "${TESSERA:-build/bin/tessera}")
threads=${TESSERA_THREADS:-1}
data=../shared/datasets/$set_name
for need in "$data/images" "$data/gt" "$data/K.txt" "$manifest" "$tessera"; do
  [ -e "$need" ] || { echo "accuracy_candidates: $need: not found" >&2; exit 2; }
done

# The recipe with `key=json` changes (dotted keys) written to OUT/NAME.json.
variant() {
  local name=$1
  shift
  python3 - "$manifest" "$out/$name.json" "$@" <<'PY'
import json, sys
recipe = json.load(open(sys.argv[1]))
for change in sys.argv[3:]:
    key, value = change.split("=", 1)
    node = recipe
    *parents, leaf = key.split(".")
    for parent in parents:
        node = node.setdefault(parent, {})
    node[leaf] = json.loads(value)
json.dump(recipe, open(sys.argv[2], "w"), indent=1)
PY
}

# One table row: NAME STAGE SECONDS EXIT_CODE, scored from OUT/NAME/sparse/0.
row() {
  local name=$1 stage=$2 seconds=$3 code=$4 error="-" rotation="-"
  if [ "$code" = 0 ]; then
    local scores
    scores=$("$tessera" eval "$out/$name/sparse/0" "$data/gt" 2> /dev/null)
    error=$(sed -n 's/^position error (ground-truth units): mean \([^,]*\),.*/\1/p' <<< "$scores")
    error=$(python3 -c "print(f'{1000 * float(\"$error\"):.2f}')" 2> /dev/null || echo "-")
    rotation=$(sed -n 's/^rotation error (deg): mean \([^,]*\),.*/\1/p' <<< "$scores")
  fi
  echo "| $set_name | $recipe | $name | $stage | $seconds | $error | $rotation | $code |"
}

# Runs `tessera VERB` into OUT/NAME and prints its row.
timed() {
  local name=$1 stage=$2
  shift 2
  local start end code
  start=$(date +%s.%N)
  "$tessera" "$@" --threads "$threads" "${given_K[@]}" > "$out/$name.log" 2>&1
  code=$?
  end=$(date +%s.%N)
  row "$name" "$stage" "$(python3 -c "print(f'{$end - $start:.1f}')")" "$code"
}

whole() {  # NAME [tessera run options...] with OUT/NAME.json
  local name=$1
  shift
  rm -rf "${out:?}/$name"
  timed "$name" "run" run --images "$data/images" --output "$out/$name" \
    --manifest "$out/$name.json" "$@"
}

map_only() {  # NAME with OUT/NAME.json, on a copy of the recipe's database
  local name=$1
  rm -rf "${out:?}/$name"
  mkdir -p "$out/$name"
  cp "$out/recipe/database.db" "$out/$name/"
  timed "$name" "map" map --output "$out/$name" --manifest "$out/$name.json"
}

given_K=()
if python3 -c 'import json, sys; sys.exit(not json.load(open(sys.argv[1])).get("camera", {}).get("require_calibration", False))' "$manifest"; then
  given_K=(--camera-K "$data/K.txt")
fi
mapper=pipeline.mapper.options
adjuster=pipeline.bundle_adjuster.options
detector=pipeline.detector.options
recipe=$(basename "$manifest" .json)
echo "| set | recipe | candidate | stage run | seconds | position error mm | rotation deg | exit code |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
variant recipe && whole recipe
variant recipe-map && map_only recipe-map
variant loss-trivial "$adjuster.loss=\"trivial\"" && map_only loss-trivial
variant huber-2px "$adjuster.loss_scale=2" && map_only huber-2px
variant huber-4px "$adjuster.loss_scale=4" && map_only huber-4px
variant filter-2px "$mapper.filter_max_reproj_error=2" "$mapper.tri_max_error=2" &&
  map_only filter-2px
plugin=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["pipeline"]["mapper"]["plugin"])' "$manifest")
if [ "$plugin" = global ]; then
  converged=("$mapper.final_ba_function_tolerance=1e-6" "$mapper.ba_function_tolerance=1e-6")
else
  converged=("$mapper.ba_global_function_tolerance=1e-6")
fi
variant final-ba-converged "${converged[@]}" && map_only final-ba-converged
variant features-24000 "$detector.max_num_features=24000" && whole features-24000
variant full-resolution "$detector.max_image_size=3072" && whole full-resolution
variant ratio-0.85 "pipeline.matcher.options.ratio=0.85" && whole ratio-0.85
[ ${#given_K[@]} -gt 0 ] && exit 0  # the camera is given and held
for model in SIMPLE_PINHOLE PINHOLE RADIAL OPENCV; do
  variant "camera-$model" "camera.model=\"$model\"" && whole "camera-$model"
done
variant known-K-held "camera.model=\"PINHOLE\"" "$mapper.ba_refine_focal_length=false" \
  "$mapper.ba_refine_principal_point=false" "$mapper.ba_refine_extra_params=false" &&
  whole known-K-held --camera-K "$data/K.txt"
