#!/bin/bash
# How pair selection scales: pairs, pair-selection time and matching time (match +
# verify) against the number of images n, for the retrieval and spatial selectors and
# for exhaustive pairs, with the fitted exponent b of y = a n^b (least squares on
# log-log). Times are CPU seconds of the `tessera match` process (user + system, all
# threads, benchmarks/cpu_split.py), so that other work on the machine hardly changes
# them: selection runs from the start of the process to the log line that reports the
# chosen pairs (start-up included: loading the plugins and reading the image list, the
# whole of exhaustive's figure), matching from that line to the end.
# Images: every photo of ../shared/datasets (180) at MAX_SIZE px, plus a central 70% crop
# and a 60% rescale of each (tessera_image_variants): 540 real, distinct images, listed
# in a fixed shuffled order; the first n of them make the set of size n. For `spatial`
# the images are geotagged (tessera_test_geotag) on a synthetic survey grid, 20 images a
# row 15 m apart, in that order: positions unrelated to the content, so most of its
# pairs fail verification, but its pairs and costs grow as a flight's would. Exhaustive
# runs only up to EXHAUSTIVE_MAX images (default 100); past that its matching time is
# extrapolated from its fit. Features are detected once per size and shared.
# usage: benchmarks/pairs_vs_n.sh [SIZES...]   (default: 10 25 50 100 200 400)
#   env: MAX_SIZE (640), EXHAUSTIVE_MAX (100), THREADS (2), NUM_FEATURES (2000), POOL
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
tessera="$root/build/bin/tessera"
variants="$root/build/bin/tessera_image_variants"
geotag="$root/build/bin/tessera_test_geotag"
datasets="$root/../shared/datasets"
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(10 25 50 100 200 400)
max_size=${MAX_SIZE:-640}
exhaustive_max=${EXHAUSTIVE_MAX:-100}
threads=${THREADS:-2}
num_features=${NUM_FEATURES:-2000}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }

pool=${POOL:-$work/pool}  # POOL: a folder of such images made by an earlier run, reused
if [ ! -d "$pool" ]; then
  for scene in fountain-P11 Herz-Jesus-P8 fox sceaux-castle lego-100; do
    "$variants" "$datasets/$scene/images" "$pool" "$max_size" "$scene-" > /dev/null
  done
fi
# A fixed shuffle: by a hash of the name.
ls "$pool" | while read -r f; do echo "$(echo "$f" | sha1sum | cut -c1-12) $f"; done |
  sort | cut -d' ' -f2 > "$work/order.txt"
if [ ! -f "$pool/.geotagged" ]; then
  awk '{ i = NR - 1; printf "%s %d %d 0\n", $1, 15 * (i % 20), 15 * int(i / 20) }' \
    "$work/order.txt" > "$work/positions.txt"
  "$geotag" "$pool" "$work/positions.txt" 47.0 8.0 400 > /dev/null
  touch "$pool/.geotagged"
fi
echo "pool: $(wc -l < "$work/order.txt") images at most $max_size px"

manifest() {  # selector -> manifest file
  local selector='{"plugin": "exhaustive"}'
  [ "$1" = retrieval ] && selector='{"plugin": "retrieval", "options": {"num_neighbors": 20}}'
  [ "$1" = spatial ] && selector='{"plugin": "spatial", "options": {"num_neighbors": 20, "max_distance": 50}}'
  cat > "$work/$1.json" <<JSON
{"pipeline": {"detector": {"plugin": "sift", "options": {"max_num_features": $num_features}},
              "pair_selector": $selector, "matcher": {"plugin": "flann"}}}
JSON
  echo "$work/$1.json"
}

echo "| selector | images | pairs | selection CPU s | matching CPU s |"
echo "| --- | --- | --- | --- | --- |"
: > "$work/rows.txt"
for n in "${sizes[@]}"; do
  mkdir -p "$work/images_$n"
  head -n "$n" "$work/order.txt" | while read -r f; do ln -s "$pool/$f" "$work/images_$n/$f"; done
  "$tessera" -q extract --images "$work/images_$n" --output "$work/features_$n" \
    --threads "$threads" --manifest "$(manifest exhaustive)"
  for selector in retrieval spatial exhaustive; do
    [ "$selector" = exhaustive ] && [ "$n" -gt "$exhaustive_max" ] && continue
    rm -rf "$work/run"
    cp -r "$work/features_$n" "$work/run"
    read -r selection matching < <("$root/benchmarks/cpu_split.py" "pairs from '" \
      "$work/match.log" "$tessera" match --output "$work/run" --threads "$threads" \
      --manifest "$(manifest "$selector")")
    [ -n "${matching:-}" ] || { tail -5 "$work/match.log"; exit 1; }
    pairs=$(sqlite3 "$work/run/database.db" "SELECT COUNT(*) FROM matches")
    printf "| %s | %d | %d | %.3f | %.1f |\n" "$selector" "$n" "$pairs" "$selection" "$matching"
    echo "$selector $n $pairs $selection $matching" >> "$work/rows.txt"
  done
done

# y = a n^b by least squares on (log n, log y) over the rows with n >= FROM; prints b,
# and y at N from the fit.
fit() {  # selector column [FROM [N]]
  awk -v s="$1" -v c="$2" -v from="${3:-0}" -v N="${4:-0}" '
    $1 == s && $2 >= from && $c > 0 { x = log($2); y = log($c); n++; sx += x; sy += y; sxx += x*x; sxy += x*y }
    END { if (n < 2) { print "-"; exit } b = (n*sxy - sx*sy) / (n*sxx - sx*sx); a = (sy - b*sx) / n
          if (N > 0) printf "%.3g", exp(a + b*log(N)); else printf "%.2f", b }' "$work/rows.txt"
}
# Retrieval with num_neighbors 20 returns every pair up to 21 images, and spatial's grid
# has edge effects while the set is a few rows: their growth is fitted over all n and
# past those neighbourhoods (FIT_FROM, default 100).
fit_from=${FIT_FROM:-100}
echo
echo "| selector | fitted over | exponent of pairs | exponent of selection time | exponent of matching time |"
echo "| --- | --- | --- | --- | --- |"
for selector in retrieval spatial exhaustive; do
  echo "| $selector | all n | $(fit "$selector" 3) | $(fit "$selector" 4) | $(fit "$selector" 5) |"
  [ "$selector" = exhaustive ] ||
    echo "| $selector | n >= $fit_from | $(fit "$selector" 3 "$fit_from") | $(fit "$selector" 4 "$fit_from") | $(fit "$selector" 5 "$fit_from") |"
done
for n in "${sizes[@]}"; do
  if [ "$n" -gt "$exhaustive_max" ]; then
    echo "exhaustive at $n images (extrapolated): $((n * (n - 1) / 2)) pairs," \
      "matching $(fit exhaustive 5 0 "$n") s"
  fi
done
