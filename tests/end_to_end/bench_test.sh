#!/bin/bash
# `tessera bench` on the small fountain sample that ships in examples/:
#  1. two ORB manifests that differ only in the pair selector: two rows, the second
#     reusing the first's features (and only those: 55 exhaustive pairs, then 40 pairs
#     of two selectors, window 40 united with sequential 19 that it contains, shown per
#     selector), every image registered, scored against the ground truth; the same rows in
#     --json and --csv, and an SVG chart of them; with colmap installed (a failure under
#     CI=true without it), a COLMAP 3.8 row (--colmap colmap: that binary alone, labelled
#     with its version) that registers every image;
#  2. the same command again gives the same pairs, registered counts and errors;
#  3. a manifest naming an unknown plugin gives its row an exit code of 2 and the bench
#     exit code 2, after the other rows are printed; a missing manifest file fails
#     before anything runs, naming the file.
# usage: bench_test.sh TESSERA SOURCE_DIR SHARED_DIR
set -uo pipefail
tessera=$1
source_dir=$2
shared=${TESSERA_SHARED_DIR:-$3}
source "$(dirname "$0")/common.sh"
images="$source_dir/examples/fountain-P11-small/images"
gt="$shared/datasets/fountain-P11/gt"
[ -d "$gt" ] || skip_or_fail "$gt not found"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

python3 - "$source_dir/manifests/fast.json" "$work" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["pipeline"]["matcher"] = {"plugin": "flann"}
json.dump(m, open(sys.argv[2] + "/orb_exhaustive.json", "w"))
m["pipeline"]["pair_selector"] = [
    {"plugin": "window", "options": {"window": 5}},
    {"plugin": "sequential", "options": {"overlap": 2, "quadratic_overlap": False}}]
json.dump(m, open(sys.argv[2] + "/orb_window.json", "w"))
m["pipeline"]["matcher"] = {"plugin": "no_such_matcher"}
json.dump(m, open(sys.argv[2] + "/broken.json", "w"))
PY

colmap_flag=()
if have_colmap; then colmap_flag=(--colmap colmap); else
  skip_part_or_fail "colmap is not installed: the COLMAP row is not tested"; fi

# 1. Two manifests, shared features, every output.
"$tessera" bench --images "$images" --gt "$gt" --output "$work/out1" --threads 2 \
  --json "$work/1.json" --csv "$work/1.csv" --chart "$work/1.svg" "${colmap_flag[@]}" \
  "$work/orb_exhaustive.json" "$work/orb_window.json" > "$work/1.md" 2> "$work/1.log" ||
  { cat "$work/1.log"; fail "tessera bench exited $?"; }
cat "$work/1.md"
grep -q "^| orb_window | orb 1.0.0 / window 1.0.0+sequential 1.0.0 / flann 1.0.0 / incremental 1.0.0 / ceres 1.0.0 / colmap_binary 1.0.0+ply 1.0.0 | 0.0 (features of orb_exhaustive) |" \
  "$work/1.md" || fail "orb_window's row does not say it reused orb_exhaustive's features"
grep -q "^| orb_window |.*| 40 | window 40 + sequential 19 = 40 |" "$work/1.md" ||
  fail "orb_window's row does not show the pairs of each selector"
python3 - "$work/1.json" "$work/1.csv" "${#colmap_flag[@]}" "$(colmap -h 2>/dev/null | head -1)" <<'PY' || fail "bench JSON/CSV"
import csv, json, sys
rows = json.load(open(sys.argv[1]))["rows"]
with_colmap = sys.argv[3] != "0"
colmap_row = "colmap-%s-incremental" % sys.argv[4].split()[1] if with_colmap else None
assert [r["manifest"] for r in rows] == ["orb_exhaustive", "orb_window"] + ([colmap_row] if with_colmap else []), rows
assert [r["num_pairs"] for r in rows[:2]] == [55, 40], [r["num_pairs"] for r in rows]
assert rows[1]["extract_shared_with"] == "orb_exhaustive"
assert rows[0]["pairs_per_selector"] == [
    {"plugin": "exhaustive", "json_path": "pipeline.pair_selector", "num_pairs": 55}], rows[0]
assert [(s["plugin"], s["json_path"], s["num_pairs"]) for s in rows[1]["pairs_per_selector"]] == [
    ("window", "pipeline.pair_selector[0]", 40), ("sequential", "pipeline.pair_selector[1]", 19)], rows[1]
for r in rows:
    if r["manifest"] == colmap_row:
        assert r["plugins"].startswith("COLMAP %s: sift / exhaustive" % sys.argv[4].split()[1]), r
        continue
    # Every plugin with its version, exporters included (fast.json's colmap_binary and ply).
    used = [(p["slot"], p["plugin"]) for p in r["plugins_used"]]
    assert used[-2:] == [("exporter", "colmap_binary"), ("exporter", "ply")], r
    assert all(p["version"] for p in r["plugins_used"]), r
    assert r["plugins"].endswith("colmap_binary %s+ply %s" % (
        r["plugins_used"][-2]["version"], r["plugins_used"][-1]["version"])), r
for r in rows:
    assert r["exit_code"] == 0 and r["num_registered"] == 11, r
    assert r["position_error_mean_relative"] is not None and r["position_error_mean_relative"] < 0.01, r
    assert r["num_wrongly_registered"] == 0, r
    assert r["peak_memory_mb"] > 0 and r["total_seconds"] > 0, r
table = list(csv.reader(open(sys.argv[2])))
assert len(table) == 1 + len(rows) and table[0][0] == "manifest", table
assert [line[0] for line in table[1:]] == [r["manifest"] for r in rows]
print("json and csv: %d rows" % len(rows))
PY

grep -q "<svg" "$work/1.svg" && grep -q "orb_exhaustive" "$work/1.svg" &&
  grep -q "orb_window" "$work/1.svg" || fail "the chart is not an SVG naming both rows"

# 2. Reproducible: the same figures from a second run (times and memory aside).
"$tessera" bench --images "$images" --gt "$gt" --output "$work/out2" --threads 2 \
  --json "$work/2.json" "$work/orb_exhaustive.json" "$work/orb_window.json" \
  > /dev/null 2> "$work/2.log" || { cat "$work/2.log"; fail "second tessera bench"; }
python3 - "$work/1.json" "$work/2.json" <<'PY' || fail "two bench runs differ"
import json, sys
keys = ["num_pairs", "num_verified_pairs", "num_registered", "num_points3D",
        "mean_reprojection_error_px", "position_error_mean", "rotation_error_mean_deg"]
a, b = (json.load(open(f))["rows"][:2] for f in sys.argv[1:3])
for ra, rb in zip(a, b):
    for k in keys:
        assert ra[k] == rb[k], (ra["manifest"], k, ra[k], rb[k])
print("second run: the same figures")
PY

# 3. Failures.
"$tessera" bench --images "$images" --output "$work/out3" --threads 2 \
  "$work/orb_exhaustive.json" "$work/broken.json" > "$work/3.md" 2> "$work/3.log"
code=$?
[ "$code" -eq 2 ] || { cat "$work/3.log"; fail "a broken manifest gave exit code $code, not 2"; }
grep -q "^| orb_exhaustive |.*| 0 | - |$" "$work/3.md" || fail "the good row is missing"
grep -q "^| broken |.*| 2 | exited with code 2: .*no_such_matcher.* |$" "$work/3.md" || fail "the broken row is missing"
grep -q "broken ended with exit code 2" "$work/3.log" || fail "no error line for the broken row"
"$tessera" bench --images "$images" --output "$work/out4" "$work/missing.json" \
  > /dev/null 2> "$work/4.log"
code=$?
[ "$code" -eq 2 ] || fail "a missing manifest gave exit code $code, not 2"
grep -q "missing.json" "$work/4.log" || { cat "$work/4.log"; fail "the error does not name the file"; }
[ ! -d "$work/out4" ] || fail "a missing manifest still started a run"
echo "PASS"
