#!/bin/bash
# Tessera's recipes against COLMAP 4 (global and incremental mappers) and COLMAP 3.8, each
# whole pipeline on the same images in one `tessera bench --with-colmap` per set (so that
# every row of a set shares the machine's load), then the Markdown table of
# docs/benchmarks.md (benchmarks/bench_table.py), each row with its bench's date and
# command. Sets: fountain-P11, Herz-Jesus-P8 (default.json, global.json) and lego-100
# (large_unordered.json, large_unordered_global.json) of ../shared/datasets.
# usage: benchmarks/shared_sets_vs_colmap.sh OUT [SET...]   (default: all three)
# COLMAP 4 is found as `tessera bench` finds it (TESSERA_COLMAP, else
# ../shared/anchors/colmap-4/bin/colmap); COLMAP 3.8 is `colmap` on the PATH.
# To put a run in docs/benchmarks.md: copy OUT/SET.json and OUT/SET.command into
# benchmarks/results/shared_sets/ and run `python3 benchmarks/benchmarks_doc.py`.
set -uo pipefail
out=$1
shift
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
tessera=${TESSERA:-build/bin/tessera}
sets=("$@")
[ ${#sets[@]} -gt 0 ] || sets=(fountain-P11 Herz-Jesus-P8 lego-100)
mkdir -p "$out"
jsons=()
for set in "${sets[@]}"; do
  data=../shared/datasets/$set
  case $set in
    lego-100) gt=$data/transforms.json
              manifests=(manifests/large_unordered.json manifests/large_unordered_global.json) ;;
    fox) gt=$data/transforms.json; manifests=(manifests/default.json manifests/global.json) ;;
    *) gt=$data/gt; manifests=(manifests/default.json manifests/global.json) ;;
  esac
  command=("$tessera" bench --images "$data/images" --gt "$gt" --output "$out/$set"
           --json "$out/$set.json" --with-colmap "${manifests[@]}")
  { date -u +"%Y-%m-%d %H:%M UTC"; echo "${command[*]}"; } > "$out/$set.command"
  "${command[@]}" > "$out/$set.md" 2> "$out/$set.log" ||
    echo "shared_sets_vs_colmap: $set: tessera bench exited $? (see $out/$set.log)" >&2
  [ -f "$out/$set.json" ] && jsons+=("$out/$set.json")
done
[ ${#jsons[@]} -gt 0 ] && python3 benchmarks/bench_table.py "${jsons[@]}"
