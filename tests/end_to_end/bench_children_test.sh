#!/bin/bash
# `tessera bench` with hostile COLMAP binaries (fake ones, shell scripts written here) beside
# one small Tessera row (ORB, 5 images at 512 px):
#  1. a 30,000-character version line, and a version "3.8/../../../outside/pwn": the rows run,
#     named and foldered in [A-Za-z0-9._-], nothing written outside OUTPUT;
#  2. a COLMAP silent on -h, and one sleeping in feature_extractor: --child-timeout 2 ends
#     them (exit 2 naming the binary; a row "timed out after 2 s" with the Tessera row and
#     the table still there), and no process of theirs is left;
#  3. 20 MB on one line and binary bytes from -h: one short error line, bytes escaped;
#  4. a garbage database, a garbage model, a mapper that removes its output, a mapper that
#     crashes: each a row with its error in the table and the JSON, the Tessera row kept,
#     exit 2;
#  5. a manifest named colmap-3.8-incremental.json and two --colmap of one binary: distinct
#     rows and folders, the Tessera row's workspace intact;
#  6. SIGINT to the bench while COLMAP sleeps: exit 130 within seconds, "interrupted", the
#     sleeping child gone.
# usage: bench_children_test.sh TESSERA DOWNSCALE SOURCE_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/all" "$work/images"
"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/all" 512 90 > /dev/null ||
  fail "downscale"
for i in 3 4 5 6 7; do cp "$work/all/000$i.jpg" "$work/images/"; done
python3 - "$source_dir/manifests/fast.json" "$work/orb.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["pipeline"]["detector"]["options"] = {"max_num_features": 1500}
m["pipeline"]["exporters"] = [{"plugin": "colmap_binary"}]
json.dump(m, open(sys.argv[2], "w"))
PY
# A database COLMAP's steps "make": a Tessera run's (COLMAP's schema).
"$tessera" -q run --images "$work/images" --output "$work/fixture" --manifest "$work/orb.json" \
  --threads 2 > "$work/fixture.log" 2>&1 || { cat "$work/fixture.log"; fail "the fixture run"; }

# fake NAME HELP EXTRACT MAPPER: a COLMAP whose -h, feature_extractor and mapper run those
# shell lines ($db, $out: its --database_path and --output_path).
fake() {
  cat > "$work/$1" <<SH
#!/bin/bash
args=("\$@")
get() { local i; for ((i = 0; i < \${#args[@]}; i++)); do [ "\${args[i]}" = "\$1" ] && echo "\${args[i+1]}"; done; }
db=\$(get --database_path); out=\$(get --output_path)
case "\$1" in
  -h) $2 ;;
  feature_extractor) $3 ;;
  exhaustive_matcher) : ;;
  mapper|global_mapper) $4 ;;
esac
SH
  chmod +x "$work/$1"
}
help='echo "COLMAP 3.8 -- Structure-from-Motion"; echo "  mapper"'
copy_db="cp '$work/fixture/database.db' \"\$db\""
fake good "$help" "$copy_db" ":"
fake long_version 'printf "COLMAP 3.8"; head -c 30000 /dev/zero | tr "\\0" x; echo' "$copy_db" ":"
fake dotdot 'echo "COLMAP 3.8/../../../../outside/pwn"' "$copy_db" ":"
fake silent 'exec sleep 600' "$copy_db" ":"
fake slow_extract "$help" "echo \$\$ > '$work/sleep.pid'; exec sleep 600" ":"
fake huge 'head -c 20000000 /dev/zero | tr "\\0" x' "$copy_db" ":"
fake binary 'printf "\\001\\002\\033[31m\\377\\376 not colmap\\n"' "$copy_db" ":"
fake garbage_db "$help" "head -c 5000 /dev/urandom > \"\$db\"" ":"
fake garbage_model "$help" "$copy_db" 'mkdir -p "$out/0"; for f in cameras images points3D; do head -c 300 /dev/urandom > "$out/0/$f.bin"; done'
fake removes_output "$help" "$copy_db" 'rm -rf "$out"'
fake crashes "$help" "$copy_db" 'kill -SEGV $$'

mkdir -p "$work/outside"
# bench_case NAME EXPECTED_CODE [BENCH ARGS...]: a bench with --json; its log and table kept.
bench_case() {
  local name=$1 expected=$2
  shift 2
  timeout 120 "$tessera" bench --images "$work/images" --output "$work/runs/$name/out" --threads 2 \
    --json "$work/$name.json" "$@" > "$work/$name.md" 2> "$work/$name.log"
  local code=$?
  [ "$code" = 124 ] && fail "$name: the bench hung (killed after 120 s)"
  [ "$code" = "$expected" ] || { cat "$work/$name.log"; fail "$name: exit code $code, not $expected"; }
  [ -z "$(ls -A "$work/outside")" ] || fail "$name: wrote outside its output: $(ls -A "$work/outside")"
}
# rows NAME PYTHON: checks the JSON rows (list `rows`, dict `by` by name) of case NAME.
rows() {
  python3 - "$work/$1.json" <<PY || fail "$1: the rows"
import json, os, re, sys
rows = json.load(open(sys.argv[1]))["rows"]
by = {r["manifest"]: r for r in rows}
assert "orb" in by and by["orb"]["exit_code"] == 0 and by["orb"]["error"] is None, rows
for r in rows:
    assert re.fullmatch(r"[A-Za-z0-9._-]+", r["manifest"]), r["manifest"]
$2
PY
}

# 1. Versions.
bench_case long_version 0 --colmap "$work/long_version" "$work/orb.json"
rows long_version 'assert len(rows) == 2 and len(rows[1]["manifest"]) < 100 and rows[1]["exit_code"] == 0, rows'
# (OUT/colmap-3.8/../../../../outside/pwn is $work/outside/pwn.)
bench_case dotdot 0 --colmap "$work/dotdot" "$work/orb.json"
rows dotdot 'assert rows[1]["manifest"] == "colmap-3.8_.._.._.._.._outside_pwn-incremental", rows
assert rows[1]["workspace"].startswith(sys.argv[1][:-len("dotdot.json")] + "runs/dotdot/out/colmap/"), rows[1]'
echo "1. a 30,000-character version and a version with ../: rows named safely, nothing outside"

# 2. Timeouts.
start=$SECONDS
bench_case silent 2 --child-timeout 2 --colmap "$work/silent" "$work/orb.json"
grep -q "silent: no answer to -h (its version) within 2 s (named by --colmap)" "$work/silent.log" ||
  { cat "$work/silent.log"; fail "a COLMAP silent on -h is not named"; }
bench_case slow_extract 2 --child-timeout 10 --colmap "$work/slow_extract" "$work/orb.json"
[ $((SECONDS - start)) -lt 60 ] || fail "the two timeouts (2 s, 10 s) took $((SECONDS - start)) s"
rows slow_extract 'assert rows[1]["error"].startswith("COLMAP'"'"'s feature_extractor timed out after 10 s"), rows[1]'
grep -q "^| orb |" "$work/slow_extract.md" && grep -q "timed out after 10 s" "$work/slow_extract.md" ||
  fail "the table lacks a row"
sleep_pid=$(cat "$work/sleep.pid")
! kill -0 "$sleep_pid" 2> /dev/null || fail "the timed-out COLMAP ($sleep_pid) still runs"
echo "2. a COLMAP silent on -h and one sleeping in feature_extractor: timed out, nothing left"

# 3. Output.
for name in huge binary; do
  bench_case $name 2 --colmap "$work/$name" "$work/orb.json"
  line=$(grep "\[error\]" "$work/$name.log")
  [ "${#line}" -lt 1000 ] || fail "$name: an error line of ${#line} characters"
  grep -q "$name: does not say it is COLMAP (its -h begins '" <<< "$line" || fail "$name: $line"
  ! LC_ALL=C grep -q $'[\x01\x02\x1b\xfe\xff]' "$work/$name.log" || fail "$name: raw bytes in the log"
done
grep -qF '(its -h begins '"'"'\x01\x02\x1b[31m\xff\xfe not colmap'"'"')' "$work/binary.log" ||
  { cat "$work/binary.log"; fail "the binary output is not escaped"; }
echo "3. 20 MB and binary output on -h: one short line, escaped"

# 4. Rows that fail.
for name in garbage_db garbage_model removes_output crashes; do
  bench_case $name 2 --colmap "$work/$name" "$work/orb.json"
  grep -q "^| orb |" "$work/$name.md" || fail "$name: the Tessera row is not in the table"
  grep -q "^| colmap-3.8-incremental |" "$work/$name.md" || fail "$name: no COLMAP row in the table"
done
rows garbage_db 'assert "database.db" in rows[1]["error"], rows[1]'
rows garbage_model 'assert "images.bin" in rows[1]["error"] or "cameras.bin" in rows[1]["error"], rows[1]'
rows removes_output 'assert "sparse: COLMAP" in rows[1]["error"] and "output folder is gone" in rows[1]["error"], rows[1]'
rows crashes 'assert rows[1]["error"].startswith("COLMAP'"'"'s mapper crashed (signal 11)"), rows[1]'
echo "4. a garbage database, a garbage model, a removed output, a crash: rows with their errors"

# 5. Names.
cp "$work/orb.json" "$work/colmap-3.8-incremental.json"
PATH="$work:$PATH" bench_case names 0 --colmap "$work/good" --colmap good "$work/orb.json" \
  "$work/colmap-3.8-incremental.json"
rows names 'names = [r["manifest"] for r in rows]
assert names == ["orb", "colmap-3.8-incremental", "colmap-3.8-2-incremental", "colmap-3.8-3-incremental"], names
assert len({r["workspace"] for r in rows}) == 4, rows
kept = by["colmap-3.8-incremental"]  # the manifest row, its workspace whole
assert kept["exit_code"] == 0 and os.path.exists(kept["workspace"] + "/database.db"), kept
assert kept["workspace"].endswith("/tessera/colmap-3.8-incremental"), kept'
echo "5. a manifest named as a COLMAP row, one binary named twice: distinct rows and folders"

# 6. SIGINT while COLMAP sleeps.
rm -f "$work/sleep.pid"
"$tessera" bench --images "$work/images" --output "$work/int/out" --threads 2 \
  --colmap "$work/slow_extract" "$work/orb.json" > "$work/int.md" 2> "$work/int.log" &
bench=$!
for _ in $(seq 1 600); do [ -s "$work/sleep.pid" ] && break; sleep 0.1; done
[ -s "$work/sleep.pid" ] || { cat "$work/int.log"; fail "COLMAP's extraction never started"; }
sleep_pid=$(cat "$work/sleep.pid")
start=$SECONDS
kill -INT "$bench"
for _ in $(seq 1 200); do kill -0 "$bench" 2> /dev/null || break; sleep 0.1; done
kill -0 "$bench" 2> /dev/null && { kill -9 "$bench"; fail "SIGINT: the bench still runs 20 s later"; }
wait "$bench"
code=$?
[ "$code" = 130 ] || { cat "$work/int.log"; fail "SIGINT: exit code $code, not 130"; }
grep -q "bench: interrupted" "$work/int.log" || { cat "$work/int.log"; fail "SIGINT: no word 'interrupted'"; }
! grep -q "crashed" "$work/int.log" || fail "SIGINT reported as a crash"
grep -q "^| orb |" "$work/int.md" || fail "SIGINT: the finished row is not printed"
! kill -0 "$sleep_pid" 2> /dev/null || fail "SIGINT: COLMAP ($sleep_pid) still runs"
echo "6. SIGINT: exit 130 in $((SECONDS - start)) s, interrupted, COLMAP ended"
echo "PASS"
