#!/bin/bash
# How the position error of calibrated.json (the intrinsics given and held) depends on the
# focal lengths held: the set is mapped once per pair of focal lengths, with the principal
# point of the set's K.txt, and every model is scored with `tessera eval` against gt/.
# A diagnostic of the ground truth's calibration, not a way to choose one: scoring a K
# against the ground truth it is then compared with is tuning to it.
# Each run after the first starts from the first run's workspace (same features; the
# cameras, and so the matches' geometry, are made again for the new K).
# usage: benchmarks/held_calibration_sweep.sh OUT SET FX:FY [FX:FY ...]
#   SET: a folder of ../shared/datasets with images/, gt/ (*.camera) and K.txt.
#   e.g. benchmarks/held_calibration_sweep.sh /tmp/sweep Herz-Jesus-P8 2759.48:2764.16 2764.16:2759.48
set -uo pipefail
[ $# -ge 3 ] || { sed -n 's/^# usage: /usage: /p' "$0" >&2; exit 2; }
out=$1
set_name=$2
shift 2
root=$(cd "$(dirname "$0")/.." && pwd)
out=$(mkdir -p "$out" && cd "$out" && pwd)
cd "$root"
tessera=$(readlink -f "${TESSERA:-build/bin/tessera}")
data=../shared/datasets/$set_name
for need in "$data/images" "$data/gt" "$data/K.txt" "$tessera"; do
  [ -e "$need" ] || { echo "held_calibration_sweep: $need: not found" >&2; exit 2; }
done
read -r cx cy <<< "$(python3 -c 'import sys; K = open(sys.argv[1]).read().split(); print(K[2], K[5])' "$data/K.txt")"
echo "| set | fx held | fy held | position error mm: mean | median | rotation deg | exit code |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
first=""
for focal in "$@"; do
  fx=${focal%%:*}
  fy=${focal##*:}
  name="fx$fx-fy$fy"
  rm -rf "${out:?}/$name"
  mkdir -p "$out/$name"
  printf '%s 0 %s\n0 %s %s\n0 0 1\n' "$fx" "$cx" "$fy" "$cy" > "$out/$name.K.txt"
  [ -n "$first" ] && cp "$out/$first/database.db" "$out/$name/"
  "$tessera" run --images "$data/images" --output "$out/$name" \
    --manifest manifests/calibrated.json --camera-K "$out/$name.K.txt" \
    --threads "${TESSERA_THREADS:-2}" > "$out/$name.log" 2>&1
  code=$?
  scores="- | - | -"
  if [ "$code" = 0 ]; then
    [ -z "$first" ] && first=$name
    scores=$("$tessera" eval --json "$out/$name/sparse/0" "$data/gt" 2> /dev/null | python3 -c '
import json, sys
e = json.load(sys.stdin)
print("%.2f | %.2f | %.4f" % (1000 * e["pos_mean"], 1000 * e["pos_median"], e["rot_mean_deg"]))')
  fi
  echo "| $set_name | $fx | $fy | $scores | $code |"
done
