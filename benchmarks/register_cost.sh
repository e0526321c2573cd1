#!/bin/bash
# What `tessera register` costs against mapping everything again (issue 58): a model of
# the first MAPPED images (natural order), then the other images added to the folder and
# either registered into it or the whole set run again in a copy of the same workspace
# (features and matches of the first images reused, as a user's re-run would). Prints one
# line per set: the wall time of register (extract + match + register of the new images)
# and of the re-map (extract + match of the new images + map of all), images registered
# by each, and, with ground truth, the mean position error of both models.
# usage: benchmarks/register_cost.sh [SET...]   (SET: sample, lego; default both)
#   sample: examples/fountain-P11-small, 8 mapped then 3 registered;
#   lego: ../shared/datasets/lego-100, 90 then 10 (skipped with a line when absent).
# TESSERA: the executable (default build/bin/tessera); MANIFEST: default manifests/default.json.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
tessera=${TESSERA:-$root/build/bin/tessera}
manifest=$(realpath "${MANIFEST:-$root/manifests/default.json}")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
score() {  # score MODEL GT: "registered pos_mean" of tessera eval, or "- -" without GT
  [ -e "$2" ] || { echo "- -"; return; }
  "$tessera" eval "$1" "$2" --json 2> /dev/null |
    python3 -c 'import json,sys; e=json.load(sys.stdin); print(e["registered"], e["pos_mean"])' ||
    echo "? ?"
}
measure() {  # measure NAME IMAGES MAPPED GT
  local name=$1 source=$2 mapped=$3 gt=$4 dir="$work/$1"
  mkdir -p "$dir/images"
  local all=() image
  while IFS= read -r image; do all+=("$image"); done < <(ls "$source" | sort -V)
  for image in "${all[@]:0:$mapped}"; do cp "$source/$image" "$dir/images/"; done
  "$tessera" run --images "$dir/images" --output "$dir/ws" --manifest "$manifest" \
    > "$dir/first.log" 2>&1 || { tail -20 "$dir/first.log"; echo "$name: the first map failed"; return 1; }
  for image in "${all[@]:$mapped}"; do cp "$source/$image" "$dir/images/"; done
  cp -r "$dir/ws" "$dir/remap"
  local t0 t1 t2 t3
  t0=$(now)
  "$tessera" register --output "$dir/ws" --manifest "$manifest" --json > "$dir/register.json" \
    2> "$dir/register.log" || { tail -20 "$dir/register.log"; echo "$name: register failed"; return 1; }
  t1=$(now)
  t2=$(now)
  "$tessera" run --images "$dir/images" --output "$dir/remap" --manifest "$manifest" \
    > "$dir/remap.log" 2>&1 || { tail -20 "$dir/remap.log"; echo "$name: the re-map failed"; return 1; }
  t3=$(now)
  local registered
  registered=$(python3 -c 'import json,sys; s=json.load(open(sys.argv[1])); print("%d/%d" % (s["num_registered"], s["num_new_images"]))' "$dir/register.json")
  read -r reg_n reg_err <<< "$(score "$dir/ws/sparse/0" "$gt")"
  read -r remap_n remap_err <<< "$(score "$dir/remap/sparse/0" "$gt")"
  printf '%s: %d mapped + %d new: register %.2f s (%s new registered; model 0: %s images, mean position error %s), re-map %.2f s (model 0: %s images, %s); register/re-map %.2f\n' \
    "$name" "$mapped" $((${#all[@]} - mapped)) "$(echo "$t1 - $t0" | bc)" "$registered" \
    "$reg_n" "$reg_err" "$(echo "$t3 - $t2" | bc)" "$remap_n" "$remap_err" \
    "$(echo "($t1 - $t0) / ($t3 - $t2)" | bc -l)"
}
sets=("$@")
[ ${#sets[@]} -gt 0 ] || sets=(sample lego)
for set in "${sets[@]}"; do
  case $set in
    sample) measure sample "$root/examples/fountain-P11-small/images" 8 \
              "$root/../shared/datasets/fountain-P11/gt" ;;
    lego) if [ -d "$root/../shared/datasets/lego-100/images" ]; then
            measure lego "$root/../shared/datasets/lego-100/images" 90 \
              "$root/../shared/datasets/lego-100/transforms.json"
          else
            echo "lego: ../shared/datasets/lego-100 not found; skipped"
          fi ;;
    *) echo "unknown set '$set' (sample, lego)"; exit 2 ;;
  esac
done
