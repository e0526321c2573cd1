#!/bin/bash
# Sharded extraction and matching against one process (issue 12's figures), on fox
# (../shared/datasets/fox/images, 50 images) with the default recipe; no cluster needed:
#  - single: `extract` then `match`, one process, one thread;
#  - N = 4 and N = 16: every shard of `extract --shard K/N`, then `merge`, then every
#    shard of `match --shard K/N`, then `merge`, one after the other, one thread each:
#    total shard work against the single run's (overhead), slowest shard against the
#    mean shard, and the speed-up projected for W = 8 and 32 workers from the N = 16
#    shard times (shards placed longest first on the least loaded worker, merges added);
#  - measured: N = 2 shards run side by side (2 workers on this machine), merges
#    included, against the single run's wall-clock time.
# Shard and single-run times are CPU seconds (user + system) of each process, one thread
# each (OpenCV's too), so that they add up to the work done; on a shared virtual machine
# they still vary by several percent between runs, and other work beside them inflates
# them. The two-worker figure is wall-clock time and needs an idle machine.
# All of fox takes about 11 minutes here; IMAGES may be a subset.
# usage: slurm_shards.sh TESSERA [IMAGES] [MANIFEST]
set -euo pipefail
tessera=$1
images=${2:-$(dirname "$0")/../../shared/datasets/fox/images}
manifest=${3:-$(dirname "$0")/../manifests/default.json}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
# timed FILE COMMAND...: runs COMMAND, appends its CPU seconds (user + system) to FILE.
timed() {
  local file=$1
  shift
  # `t ARGS` (below) as a plain command, which /usr/bin/time can run.
  [ "$1" = t ] && { shift; set -- "$tessera" "$@" --manifest "$manifest" --threads 1; }
  /usr/bin/time -f "%U %S" -o "$work/cpu" "$@" > /dev/null 2>> "$work/log" ||
    { tail -5 "$work/log"; echo "failed: $*"; exit 1; }
  awk '{ print $1 + $2 }' "$work/cpu" >> "$file"
}
run() { timed "$@" ; }
t() { "$tessera" "$@" --manifest "$manifest" --threads 1; }

echo "images: $images ($(ls "$images" | wc -l) files), manifest: $manifest, 1 thread per process"
single_start=$(now)
run "$work/single_extract" t extract --images "$images" --output "$work/single"
run "$work/single_match" t match --output "$work/single"
single_wall=$(echo "$(now) - $single_start" | bc -l)
single_e=$(cat "$work/single_extract")
single_m=$(cat "$work/single_match")
printf "single process: extract %.1f s, match %.1f s (CPU)\n" "$single_e" "$single_m"
# What a process costs before it does any work (loading libraries and plugins, scanning
# and ingesting the image list): an extraction shard that owns no image, the least of
# five runs.
for k in 1 2 3 4 5; do
  run "$work/startup" t extract --images "$images" --output "$work/startup$k" --shard 1023/1024
done
startup=$(sort -n "$work/startup" | head -1)
printf "one process with no work (extract --shard 1023/1024, least of 5): %.2f s (CPU)\n" "$startup"

for n in 4 16; do
  out=$work/n$n
  for k in $(seq 0 $((n - 1))); do
    run "$work/e$n" t extract --images "$images" --output "$out" --shard "$k/$n"
  done
  run "$work/me$n" "$tessera" merge --output "$out" --stage extract
  for k in $(seq 0 $((n - 1))); do run "$work/m$n" t match --output "$out" --shard "$k/$n"; done
  run "$work/mm$n" "$tessera" merge --output "$out" --stage match
  [ "$(sqlite3 "$work/single/database.db" "SELECT COUNT(*) FROM two_view_geometries")" = \
    "$(sqlite3 "$out/database.db" "SELECT COUNT(*) FROM two_view_geometries")" ] ||
    { echo "N=$n: not the single run's pairs"; exit 1; }
  python3 - "$n" "$single_e" "$single_m" "$work/e$n" "$work/m$n" "$work/me$n" "$work/mm$n" \
    "$startup" <<'PY'
import sys
n, single_e, single_m = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
read = lambda f: [float(x) for x in open(f)]
e, m, me, mm = read(sys.argv[4]), read(sys.argv[5]), read(sys.argv[6])[0], read(sys.argv[7])[0]
startup = float(sys.argv[8])
for name, shards, single, merge in (("extract", e, single_e, me), ("match", m, single_m, mm)):
    mean = sum(shards) / len(shards)
    # The same without each process's start-up (N of them against the single run's one).
    work = sum(shards) - n * startup
    print(f"N={n:2d} {name:7s}: shard work {sum(shards):7.1f} s vs single {single:7.1f} s CPU "
          f"(overhead {100 * (sum(shards) / single - 1):+.1f}%; without start-up "
          f"{100 * (work / (single - startup) - 1):+.1f}%), slowest/mean shard "
          f"{max(shards) / mean:.2f}, merge {merge:.2f} s")
def makespan(times, workers):
    loads = [0.0] * workers
    for t in sorted(times, reverse=True):
        loads[loads.index(min(loads))] += t
    return max(loads)
if n == 16:
    for w in (8, 32):
        projected = (single_e + single_m) / (makespan(e, w) + me + makespan(m, w) + mm)
        print(f"projected speed-up with {w} workers (from the N=16 shard times, merges "
              f"included{', at most 16 shards at once' if w > 16 else ''}): {projected:.1f}x")
PY
done

# Two workers side by side: N = 2, each stage's shards at once.
out=$work/n2
start=$(now)
t extract --images "$images" --output "$out" --shard 0/2 > /dev/null 2>> "$work/log" &
a=$!
t extract --images "$images" --output "$out" --shard 1/2 > /dev/null 2>> "$work/log" &
b=$!
wait $a && wait $b
"$tessera" merge --output "$out" --stage extract > /dev/null 2>> "$work/log"
t match --output "$out" --shard 0/2 > /dev/null 2>> "$work/log" &
a=$!
t match --output "$out" --shard 1/2 > /dev/null 2>> "$work/log" &
b=$!
wait $a && wait $b
"$tessera" merge --output "$out" --stage match > /dev/null 2>> "$work/log"
two=$(echo "$(now) - $start" | bc -l)
printf "measured with 2 workers (N=2 side by side, merges included): %.1f s vs single %.1f s wall-clock: speed-up %.2fx\n" \
  "$two" "$single_wall" "$(echo "$single_wall / $two" | bc -l)"
