#!/bin/bash
# Ctrl-C during `tessera run` stops cleanly and loses nothing. On a 512 px copy of the
# in-repository sample, one thread: SIGINT after matching has stored its third pair gives
# exit 130 and one line saying how to resume; the workspace keeps every image and every
# pair finished; the same command then completes (exit 0), detecting no image again and
# matching only the pairs left, and its model equals an uninterrupted run's. Then the
# same for the global mapper: SIGINT once rotation averaging is done (during global
# positioning or the adjustments after it) gives exit 130, and the same `tessera map`
# then gives an uninterrupted map's model. The signals are sent where the run pauses for
# the test (TESSERA_TEST_PAUSE), not on a timer.
# usage: interrupt_test.sh TESSERA DOWNSCALE SOURCE_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
pid=""
trap '[ -n "$pid" ] && kill -9 "$pid" 2> /dev/null; rm -rf "$work"' EXIT

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/images" 512 90 > /dev/null ||
  fail "downscale"
manifest="$source_dir/manifests/default.json"

TESSERA_TEST_PAUSE=match.pair_committed:3 "$tessera" run --images "$work/images" \
  --output "$work/ws" --manifest "$manifest" --threads 1 > "$work/first.log" 2>&1 &
pid=$!
wait_until_paused "$pid"
kill -INT "$pid"
kill -CONT "$pid"
wait "$pid"
code=$?
pid=""
[ "$code" -eq 130 ] || { tail -5 "$work/first.log"; fail "interrupted run: exit $code, not 130"; }
grep -q "run: interrupted; the images and pairs finished are kept" "$work/first.log" ||
  { tail -5 "$work/first.log"; fail "no line saying how to resume"; }
[ ! -f "$work/ws/run_summary.json" ] || fail "an interrupted run wrote run_summary.json"
pairs_done=$(sqlite3 "$work/ws/database.db" "SELECT COUNT(*) FROM two_view_geometries")
[ "$pairs_done" -ge 3 ] && [ "$pairs_done" -lt 55 ] ||
  fail "expected the 3 pairs stored before the interrupt kept, and fewer than 55, found $pairs_done"

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

# The global mapper, interrupted as it starts to position the cameras, rotations averaged
# (it pauses there for the test; SIGINT is delivered as it continues).
global_manifest="$source_dir/manifests/global.json"
TESSERA_TEST_PAUSE=global_map.positioning_part:1 "$tessera" map --output "$work/ws" \
  --manifest "$global_manifest" --threads 1 > "$work/global_first.log" 2>&1 &
pid=$!
wait_until_paused "$pid"
kill -INT "$pid"
kill -CONT "$pid"
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
