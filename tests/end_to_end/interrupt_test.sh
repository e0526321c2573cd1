#!/bin/bash
# Ctrl-C during `tessera run` stops cleanly and loses nothing. On a 512 px copy of the
# in-repository sample, one thread: SIGINT as soon as matching reports progress gives
# exit 130 and one line saying how to resume; the workspace keeps every image and every
# pair finished; the same command then completes (exit 0), detecting no image again and
# matching only the pairs left, and its model equals an uninterrupted run's. Then the
# same for the global mapper: SIGINT once rotation averaging has logged (during global
# positioning or the adjustments after it) gives exit 130, and the same `tessera map`
# then gives an uninterrupted map's model.
# usage: interrupt_test.sh TESSERA DOWNSCALE SOURCE_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
pid=""
trap '[ -n "$pid" ] && kill -9 "$pid" 2> /dev/null; rm -rf "$work"' EXIT

# Polls FILE every SECONDS until a line matches PATTERN or the process $pid has ended
# (at most 60 s).
wait_for_line() {
  local pattern=$1 file=$2 seconds=$3 deadline=$((SECONDS + 60))
  while [ "$SECONDS" -lt "$deadline" ]; do
    grep -q "$pattern" "$file" && return
    kill -0 "$pid" 2> /dev/null || return
    sleep "$seconds"
  done
}

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/images" 512 90 > /dev/null ||
  fail "downscale"
manifest="$source_dir/manifests/default.json"

"$tessera" run --images "$work/images" --output "$work/ws" --manifest "$manifest" \
  --threads 1 > "$work/first.log" 2>&1 &
pid=$!
wait_for_line "match: \[" "$work/first.log" 0.1
grep -q "match: \[" "$work/first.log" || { cat "$work/first.log"; fail "no match progress"; }
kill -INT "$pid"
wait "$pid"
code=$?
pid=""
[ "$code" -eq 130 ] || { tail -5 "$work/first.log"; fail "interrupted run: exit $code, not 130"; }
grep -q "run: interrupted; the images and pairs finished are kept" "$work/first.log" ||
  { tail -5 "$work/first.log"; fail "no line saying how to resume"; }
[ ! -f "$work/ws/run_summary.json" ] || fail "an interrupted run wrote run_summary.json"
pairs_done=$(sqlite3 "$work/ws/database.db" "SELECT COUNT(*) FROM two_view_geometries")
[ "$pairs_done" -ge 1 ] && [ "$pairs_done" -lt 55 ] ||
  fail "expected some of the 55 pairs kept, found $pairs_done"

"$tessera" run --images "$work/images" --output "$work/ws" --manifest "$manifest" \
  --threads 1 > "$work/second.log" 2>&1 || { tail -5 "$work/second.log"; fail "resumed run"; }
grep -q "extract: 11 images, 0 to detect with '[a-z]*' (11 already done)" "$work/second.log" ||
  { grep "extract:" "$work/second.log"; fail "the resumed run detected images again"; }
grep -q "$((55 - pairs_done)) to match with 'flann' ($pairs_done already done)" \
  "$work/second.log" || { grep "match:" "$work/second.log"; fail "the resumed run did not reuse the $pairs_done pairs"; }

"$tessera" run --images "$work/images" --output "$work/fresh" --manifest "$manifest" \
  --threads 1 > "$work/fresh.log" 2>&1 || fail "uninterrupted run"
for file in cameras.bin images.bin points3D.bin; do
  cmp -s "$work/ws/sparse/0/$file" "$work/fresh/sparse/0/$file" ||
    fail "sparse/0/$file differs from an uninterrupted run's"
done

# The global mapper, interrupted after rotation averaging: the log is polled every 10 ms,
# and what is left of the map (positioning, four adjustments) takes over a second here.
global_manifest="$source_dir/manifests/global.json"
"$tessera" map --output "$work/ws" --manifest "$global_manifest" --threads 1 \
  > "$work/global_first.log" 2>&1 &
pid=$!
wait_for_line "global map: 11 images, .* verified pairs" "$work/global_first.log" 0.01
kill -INT "$pid" 2> /dev/null
wait "$pid"
code=$?
pid=""
[ "$code" -eq 130 ] ||
  { tail -5 "$work/global_first.log"; fail "interrupted global map: exit $code, not 130"; }
grep -q "global map: stopped after" "$work/global_first.log" ||
  { tail -5 "$work/global_first.log"; fail "the global mapper did not say it stopped"; }
"$tessera" map --output "$work/ws" --manifest "$global_manifest" --threads 1 \
  > "$work/global_second.log" 2>&1 || { tail -5 "$work/global_second.log"; fail "resumed global map"; }
"$tessera" map --output "$work/fresh" --manifest "$global_manifest" --threads 1 \
  > "$work/global_fresh.log" 2>&1 || { tail -5 "$work/global_fresh.log"; fail "global map"; }
for file in cameras.bin images.bin points3D.bin; do
  cmp -s "$work/ws/sparse/0/$file" "$work/fresh/sparse/0/$file" ||
    fail "global: sparse/0/$file differs from an uninterrupted map's"
done

echo "PASS: interrupted after $pairs_done of 55 pairs (exit 130), resumed to the same model;" \
  "the global mapper interrupted (exit 130) and run again to the same model"
