#!/bin/bash
# kill -9 at random moments over a run, each followed by a rerun on the same
# workspace: every final model must be byte-identical to an uninterrupted run's, and
# the work redone is counted from the reruns' own log lines.
# For each of KILLS trials: a fresh workspace, `tessera run` killed with SIGKILL at a
# moment drawn uniformly over (2%, 98%) of the uninterrupted run's wall time (seeded:
# the same moments every time), then `tessera run` again to the end.
# Prints one row per trial (moment, what the killed run had committed, what the rerun
# did) and the totals:
#   re-detected / re-matched: the images detected and pairs matched by the rerun, i.e.
#     the work redone after the kill (what was in flight or not reached);
#   committed redone: rerun work beyond what the killed run left uncommitted, i.e.
#     committed work done twice (0 when resuming works).
# usage: benchmarks/kill_resume.sh [IMAGES] [KILLS] [MANIFEST] [MAX_SIZE]
#   defaults: examples/fountain-P11-small/images, 20, manifests/default.json, 0 (as is)
#   e.g. benchmarks/kill_resume.sh examples/fountain-P11-small/images 20 manifests/fast.json 512
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
images=$(cd "${1:-$root/examples/fountain-P11-small/images}" && pwd)
kills=${2:-20}
manifest=$(realpath "${3:-$root/manifests/default.json}")
max_size=${4:-0}
tessera=${TESSERA:-$root/build/bin/tessera}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
if [ "$max_size" != 0 ]; then
  "$root/build/bin/tessera_test_downscale" "$images" "$work/images" "$max_size" 95 > /dev/null ||
    { echo "downscale failed (build tessera_test_downscale)"; exit 1; }
  images=$work/images
fi
run() { "$tessera" run --images "$images" --output "$1" --manifest "$manifest" --threads 2; }
model_sum() { cat "$1"/sparse/0/cameras.bin "$1"/sparse/0/images.bin "$1"/sparse/0/points3D.bin | md5sum | cut -c1-32; }

t0=$(now)
run "$work/reference" > "$work/reference.log" 2>&1 || { cat "$work/reference.log"; exit 1; }
t1=$(now)
wall=$(echo "$t1 - $t0" | bc)
reference=$(model_sum "$work/reference")
num_images=$(sqlite3 "$work/reference/database.db" "SELECT COUNT(*) FROM images")
num_pairs=$(sqlite3 "$work/reference/database.db" "SELECT COUNT(*) FROM matches")
echo "uninterrupted: $num_images images, $num_pairs pairs, ${wall} s, model $reference"
echo "| trial | kill at s | committed images | committed pairs | re-detected images | re-matched pairs | committed images redone | committed pairs redone | identical |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
RANDOM=20261201
identical=0 redetected_total=0 rematched_total=0 detected_total=0 matched_total=0
for trial in $(seq 1 "$kills"); do
  moment=$(echo "scale=3; $wall * (0.02 + 0.96 * $RANDOM / 32767)" | bc)
  workspace="$work/trial_$trial"
  "$tessera" run --images "$images" --output "$workspace" --manifest "$manifest" --threads 2 > "$work/killed_$trial.log" 2>&1 &
  pid=$!
  sleep "$moment"
  kill -9 $pid 2> /dev/null
  wait $pid 2> /dev/null
  db="$workspace/database.db"
  committed_images=$(sqlite3 -cmd ".timeout 2000" "$db" "SELECT COUNT(*) FROM keypoints" 2> /dev/null || echo 0)
  committed_pairs=$(sqlite3 -cmd ".timeout 2000" "$db" "SELECT COUNT(*) FROM two_view_geometries" 2> /dev/null || echo 0)
  # What the killed run had started: detections logged (committed) plus those in flight,
  # which the log cannot show; the rerun's counts give the total redone.
  run "$workspace" > "$work/rerun_$trial.log" 2>&1 || { tail -5 "$work/rerun_$trial.log"; echo "trial $trial: the rerun failed"; }
  detected=$(grep -oE "extract: [0-9]+ images, [0-9]+ to detect" "$work/rerun_$trial.log" | grep -oE "[0-9]+ to detect" | grep -oE "[0-9]+")
  matched=$(grep -oE "match: [0-9]+ pairs from '[^']*', [0-9]+ to match" "$work/rerun_$trial.log" | grep -oE "[0-9]+ to match" | grep -oE "[0-9]+")
  detected=${detected:-0} matched=${matched:-0}
  # Redone: what the rerun did beyond what the killed run left undone. The killed run
  # had committed COMMITTED; the rest (total - committed) the rerun must do; anything more
  # would be committed work done twice.
  redetected=$((detected - (num_images - committed_images)))
  rematched=$((matched - (num_pairs - committed_pairs)))
  [ -f "$workspace/sparse/0/images.bin" ] && sum=$(model_sum "$workspace") || sum=none
  same=no
  [ "$sum" = "$reference" ] && { same=yes; identical=$((identical + 1)); }
  detected_total=$((detected_total + detected))
  matched_total=$((matched_total + matched))
  redetected_total=$((redetected_total + redetected))
  rematched_total=$((rematched_total + rematched))
  echo "| $trial | $moment | $committed_images | $committed_pairs | $detected | $matched | $redetected | $rematched | $same |"
  rm -rf "$workspace"
done
echo "identical final models: $identical of $kills"
echo "work redone after $kills kills: $detected_total images re-detected, $matched_total pairs re-matched (a restart from scratch: $((kills * num_images)) and $((kills * num_pairs)))"
echo "committed work done twice: $redetected_total images, $rematched_total pairs"
[ "$identical" = "$kills" ] && [ "$redetected_total" = 0 ] && [ "$rematched_total" = 0 ]
