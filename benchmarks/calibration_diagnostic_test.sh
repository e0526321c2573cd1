#!/bin/bash
# calibration_diagnostic's bad input: exit code 2 and one line on stderr naming the file.
# usage: benchmarks/calibration_diagnostic_test.sh DIAGNOSTIC
set -u
[ $# = 1 ] || { sed -n 's/^# usage: /usage: /p' "$0" >&2; exit 2; }
diagnostic=$1
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
# expect CODE MESSAGE ARGS...: the exit code and the whole of stderr.
expect() {
  local code=$1 message=$2
  shift 2
  "$diagnostic" "$@" > "$work/out" 2> "$work/err"
  local got=$?
  if [ "$got" != "$code" ] || [ "$(cat "$work/err")" != "$message" ]; then
    echo "FAIL: $*: exit code $got, stderr '$(cat "$work/err")'; expected $code, '$message'"
    failures=$((failures + 1))
  fi
}
usage="usage: calibration_diagnostic --manifest M (--database DB --true-K K.txt --gt GT [--mm] | --synthetic N [--scene-seed S] [--view-angle A] [--given-K]) [--threads T]"
manifest=$root/manifests/global.json
expect 2 "$usage"
expect 2 "$usage" --manifest "$manifest" --synthetic 8 --database x --true-K y --gt z
expect 2 "$usage" --manifest "$manifest" --database x --true-K y --gt z --given-K
expect 2 "calibration_diagnostic: $work/none.json: cannot be read" --manifest "$work/none.json" \
  --synthetic 8
echo '{"pipeline": {"mapper": {"plugin": "other"}}}' > "$work/other.json"
expect 2 "calibration_diagnostic: $work/other.json: pipeline.mapper.plugin 'other' is neither 'global' nor 'incremental'" \
  --manifest "$work/other.json" --synthetic 8
expect 2 "calibration_diagnostic: $work/none.db: not found" --manifest "$manifest" \
  --database "$work/none.db" --true-K "$work/K.txt" --gt "$work"
touch "$work/database.db"
printf '1 0 2\n0 1 3\n' > "$work/K.txt"
expect 2 "calibration_diagnostic: $work/K.txt: holds 6 numbers, not the 9 of a 3x3 K" \
  --manifest "$manifest" --database "$work/database.db" --true-K "$work/K.txt" --gt "$work"
expect 2 "calibration_diagnostic: --synthetic 0: not a whole number from 1 to 100000" \
  --manifest "$manifest" --synthetic 0
expect 2 "calibration_diagnostic: --view-angle x: not a whole number from 1 to 100000" \
  --manifest "$manifest" --synthetic 8 --view-angle x
[ "$failures" = 0 ] && echo "PASS"
exit $((failures > 0))
