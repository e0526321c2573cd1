#!/bin/bash
# The four pair-selection strategies on one ordered image set, everything else fixed:
# pairs, matching time (match + verify), verified pairs; and, for 10, 25 and all
# images, the matching time of each strategy, to show which grow linearly.
# Features are detected once and shared by every strategy.
# usage: benchmarks/pair_strategies.sh IMAGES
#   e.g. benchmarks/pair_strategies.sh ../shared/datasets/fox/images
set -euo pipefail
images=$(cd "$1" && pwd)
root=$(cd "$(dirname "$0")/.." && pwd)
tessera="$root/build/bin/tessera"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
strategies=(exhaustive sequential window window_anchor)
manifest() {  # strategy -> manifest file
  cat > "$work/$1.json" <<JSON
{"pipeline": {"detector": {"plugin": "sift"}, "pair_selector": {"plugin": "$1"},
              "matcher": {"plugin": "flann"}}}
JSON
  echo "$work/$1.json"
}
total=$(ls "$images" | wc -l)
sizes=(10 25 "$total")
for n in "${sizes[@]}"; do
  mkdir -p "$work/images_$n"
  ls "$images" | sort | head -n "$n" | while read -r f; do ln -s "$images/$f" "$work/images_$n/$f"; done
  "$tessera" -q extract --images "$work/images_$n" --output "$work/features_$n" \
    --manifest "$(manifest exhaustive)"
done

echo "| strategy | images | pairs | match s | verified pairs |"
echo "| --- | --- | --- | --- | --- |"
for strategy in "${strategies[@]}"; do
  for n in "${sizes[@]}"; do
    rm -rf "$work/run"; cp -r "$work/features_$n" "$work/run"
    t0=$(now)
    "$tessera" -q match --output "$work/run" --manifest "$(manifest "$strategy")"
    t1=$(now)
    pairs=$(sqlite3 "$work/run/database.db" "SELECT COUNT(*) FROM matches")
    verified=$(sqlite3 "$work/run/database.db" \
      "SELECT COUNT(*) FROM two_view_geometries WHERE rows >= 15 AND config NOT IN (0, 1)")
    printf "| %s | %d | %d | %.1f | %d |\n" "$strategy" "$n" "$pairs" "$(echo "$t1 - $t0" | bc)" "$verified"
  done
done
