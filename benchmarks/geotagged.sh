#!/bin/bash
# GPS pairing on geotagged copies of fountain-P11 and Herz-Jesus-P8: EXIF GPS written
# by tessera_test_geotag from the ground-truth camera centres plus NOISE metres of
# Gaussian noise in x and y (and NOISE/2 in altitude), seeded. One `tessera bench` per
# scene, on shared features, scored against the ground truth:
#   default.json      exhaustive pairs;
#   spatial           the spatial selector alone (6 nearest within 50 m);
#   aerial.json       the shipped recipe: spatial (20 within 150 m) + retrieval (10);
#   aerial_small_k    the same two selectors with 6 and 3 neighbours, so that on sets
#                     this small the united pairs are fewer than exhaustive's;
#   aerial_global.json  aerial.json with the global mapper, anchored to the GPS too.
# usage: benchmarks/geotagged.sh [NOISE [THREADS]]   (defaults: 3 m, all cores)
set -euo pipefail
noise=${1:-3}
threads=${2:-0}
root=$(cd "$(dirname "$0")/.." && pwd)
tessera="$root/build/bin/tessera"
geotag="$root/build/bin/tessera_test_geotag"
datasets="$root/../shared/datasets"
manifests="$root/manifests"
work=${GEOTAGGED_WORK:-$(mktemp -d)}
mkdir -p "$work"
[ -n "${GEOTAGGED_WORK:-}" ] || trap 'rm -rf "$work"' EXIT

# default.json with the spatial selector in place of exhaustive.
sed 's/"pair_selector": {"plugin": "exhaustive"}/"pair_selector": {"plugin": "spatial", "options": {"num_neighbors": 6, "max_distance": 50, "ignore_altitude": true}}/' \
  "$manifests/default.json" > "$work/spatial.json"
grep -q '"spatial"' "$work/spatial.json" || { echo "default.json has changed: no spatial.json"; exit 1; }
# aerial.json with fewer neighbours per selector.
sed -e 's/"num_neighbors": 20/"num_neighbors": 6/' -e 's/"num_neighbors": 10/"num_neighbors": 3/' \
  "$manifests/aerial.json" > "$work/aerial_small_k.json"

for scene in fountain-P11 Herz-Jesus-P8; do
  mkdir -p "$work/$scene"
  rm -rf "$work/$scene/images" && cp -r "$datasets/$scene/images" "$work/$scene/images"
  "$geotag" "$work/$scene/images" "$datasets/$scene/gt" 46.52 6.57 400 \
    --noise "$noise" --altitude-noise "$(echo "$noise / 2" | bc -l)" --seed 1 > /dev/null
  echo "## $scene: GPS from the ground truth plus $noise m of noise"
  "$tessera" -q bench --images "$work/$scene/images" --gt "$datasets/$scene/gt" \
    --output "$work/$scene/bench" --threads "$threads" \
    "$manifests/default.json" "$work/spatial.json" "$manifests/aerial.json" \
    "$work/aerial_small_k.json" "$manifests/aerial_global.json"
done
