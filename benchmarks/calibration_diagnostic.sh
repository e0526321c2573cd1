#!/bin/bash
# Where self-calibration loses accuracy (issue 62): for each set, the mapper's camera
# against the true K, and the position error against gt/, after every stage of the
# manifest's mapper (build/bin/calibration_diagnostic, eval/calibration_diagnostic.h), as
# one Markdown table per set. The mapper, its options, the adjuster's and the seed are the
# manifest's; the features and matches too (`tessera extract` and `tessera match` into
# OUT/SET once, reused by later runs on the same set: delete the folder to make them again).
# A manifest that requires a calibration (calibrated.json: K given and held) gets the true
# one: the set's K.txt (--camera-K, its own workspace OUT/SET-K), or the synthetic truth
# (--given-K): the reference self-calibration is to reach.
# usage: benchmarks/calibration_diagnostic.sh OUT MANIFEST SET [SET ...]
#   SET: a folder of ../shared/datasets with images/, gt/ (*.camera, metric) and K.txt, or
#   synthetic:N, a synthetic arc of N views with known K (calibration_diagnostic's header),
#   every view seeing the whole scene; synthetic:N:A, each point seen only from within A
#   degrees of its outward normal (partial overlap, as around an object).
#   RECORD=benchmarks/results/NAME.json: the tables are also added to that record, as one
#   run (benchmarks/benchmarks_doc.py).
#   e.g. benchmarks/calibration_diagnostic.sh /tmp/diag manifests/global.json fountain-P11 synthetic:12
set -uo pipefail
[ $# -ge 3 ] || { sed -n 's/^# usage: /usage: /p' "$0" >&2; exit 2; }
command_line="TESSERA_THREADS=${TESSERA_THREADS:-2} benchmarks/calibration_diagnostic.sh $*"
out=$1
manifest=$2
shift 2
root=$(cd "$(dirname "$0")/.." && pwd)
[ -f "$manifest" ] || { echo "calibration_diagnostic: $manifest: not found" >&2; exit 2; }
manifest=$(readlink -f "$manifest")
out=$(mkdir -p "$out" && cd "$out" && pwd)
cd "$root" || exit 2
tessera=$(readlink -f "${TESSERA:-build/bin/tessera}")
diagnostic=$(readlink -f "${DIAGNOSTIC:-build/bin/calibration_diagnostic}")
threads=${TESSERA_THREADS:-2}
for need in "$tessera" "$diagnostic"; do
  [ -x "$need" ] || { echo "calibration_diagnostic: $need: not found (build it)" >&2; exit 2; }
done
given_k=""
grep -q '"require_calibration": *true' "$manifest" && given_k=yes
tables=$(mktemp)
table=$(mktemp)
trap 'rm -f "$tables" "$table"' EXIT
status=0
for set_name in "$@"; do
  if [[ "$set_name" == synthetic:* ]]; then
    scene=${set_name#synthetic:}
    arguments=(--synthetic "${scene%%:*}" ${given_k:+--given-K})
    [[ "$scene" == *:* ]] && arguments+=(--view-angle "${scene#*:}")
  else
    data=../shared/datasets/$set_name
    for need in "$data/images" "$data/gt" "$data/K.txt"; do
      [ -e "$need" ] || { echo "calibration_diagnostic: $need: not found" >&2; exit 2; }
    done
    workspace=$out/$set_name${given_k:+-K}
    camera_k=(${given_k:+--camera-K "$data/K.txt"})
    if [ ! -f "$workspace/database.db" ] || [ ! -f "$workspace/matched" ]; then
      mkdir -p "$workspace"
      { "$tessera" extract --images "$data/images" --output "$workspace" --manifest "$manifest" \
          "${camera_k[@]}" --threads "$threads" &&
        "$tessera" match --images "$data/images" --output "$workspace" --manifest "$manifest" \
          "${camera_k[@]}" --threads "$threads"; } > "$workspace/match.log" 2>&1 ||
        { echo "calibration_diagnostic: $set_name: matching failed, see $workspace/match.log" >&2
          exit 1; }
      touch "$workspace/matched"
    fi
    arguments=(--database "$workspace/database.db" --true-K "$data/K.txt" --gt "$data/gt" --mm)
  fi
  echo "### $set_name, $(basename "$manifest")"
  echo
  "$diagnostic" --manifest "$manifest" --threads "$threads" "${arguments[@]}" > "$table"
  code=$?
  cat "$table"
  [ "$code" = 0 ] || { echo "calibration_diagnostic: $set_name: exit code $code" >&2; status=$code; }
  # For the record: each row tagged with its set.
  sed "s/^/$set_name\t/" "$table" >> "$tables"
  echo
done
if [ -n "${RECORD:-}" ]; then
  python3 - "$tables" "$RECORD" "$command_line" "$(basename "$manifest")" <<'EOF'
import datetime, json, os, sys
tables, record_path, command, manifest = sys.argv[1:5]
record = {"columns": [], "runs": [], "rows": []}
if os.path.exists(record_path):
    record = json.load(open(record_path))
run = len(record["runs"]) + 1
for line in open(tables).read().splitlines():
    name, row = line.split("\t", 1)
    cells = [c.strip() for c in row.strip().strip("|").split("|")]
    if cells[0].startswith("---"):
        continue
    if cells[0].endswith("mapper: stage"):
        columns = ["set", "manifest (mapper)", "stage"] + cells[1:]
        if record["columns"] and record["columns"] != columns:
            sys.exit("calibration_diagnostic: %s: other columns" % record_path)
        record["columns"] = columns
        mapper = "%s (%s)" % (manifest, cells[0].split(" ")[0])
        continue
    record["rows"].append({"run": run, "cells": [name, mapper] + cells})
date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
record["runs"].append({"date": date, "command": command,
                       "conditions": "%s thread(s), 2-core machine" % os.environ.get("TESSERA_THREADS", "2")})
json.dump(record, open(record_path, "w"), indent=1)
EOF
fi
exit $status
