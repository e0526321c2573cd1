#!/bin/bash
# `tessera bench --colmap-mapper-only` with COLMAP 4 (../shared/anchors/colmap-4, with
# its global mapper) on the sample at 512 px, COLMAP 4 named by TESSERA_COLMAP:
#  1. rows for COLMAP 4's global_mapper and mapper on the Tessera row's matches (and for
#     COLMAP 3.8's mapper where `colmap` on the PATH runs), each labelled with COLMAP's
#     version, every image registered and scored;
#  2. COLMAP maps copies: the Tessera row's database.db is byte-identical before, between
#     and after COLMAP's runs, and keeps its 3.8 schema, while COLMAP 4's copy was
#     upgraded (so mapping the original would have changed it);
#  3. a COLMAP binary that is missing, not executable, crashing, not COLMAP or too old is
#     exit 2 with one error line naming it, before any row runs;
#  4. COLMAP 4's whole pipeline (--colmap, at 320 px): extraction and matching once, both
#     mappers' rows with those seconds and their figures read from COLMAP's own database.
# Without a COLMAP 4 that runs (scripts/install_dependencies.sh installs its libraries)
# it skips, and fails under CI=true.
# usage: colmap4_bench_test.sh TESSERA DOWNSCALE SOURCE_DIR SHARED_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
shared=${TESSERA_SHARED_DIR:-$4}
source "$(dirname "$0")/common.sh"
colmap4="$shared/anchors/colmap-4/bin/colmap"
gt="$shared/datasets/fountain-P11/gt"
[ -d "$gt" ] || skip_or_fail "$gt not found"
[ -x "$colmap4" ] || skip_or_fail "$colmap4 not found"
"$colmap4" -h > /dev/null 2>&1 ||
  skip_or_fail "$colmap4 does not run (scripts/install_dependencies.sh installs its libraries)"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/images" 512 90 > /dev/null ||
  fail "downscale"

# COLMAP 4 behind a wrapper that notes the Tessera row's database checksum at each call.
cat > "$work/colmap4" <<EOF
#!/bin/bash
sha256sum "$work/out/tessera/global/database.db" >> "$work/sums.txt" 2> /dev/null
exec "$colmap4" "\$@"
EOF
chmod +x "$work/colmap4"

# 1. The mapper rows.
TESSERA_COLMAP="$work/colmap4" "$tessera" bench --images "$work/images" --gt "$gt" \
  --output "$work/out" --threads 2 --json "$work/1.json" --with-colmap --colmap-mapper-only \
  "$source_dir/manifests/global.json" > "$work/1.md" 2> "$work/1.log" ||
  { cat "$work/1.log"; fail "tessera bench exited $?"; }
cat "$work/1.md"
sha256sum "$work/out/tessera/global/database.db" >> "$work/sums.txt"
with_colmap3=0
if have_colmap; then with_colmap3=1; else
  skip_part_or_fail "colmap (3.8) is not installed: its row is not tested"; fi
python3 - "$work/1.json" "$with_colmap3" <<'PY' || fail "the COLMAP rows"
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
names = [r["manifest"] for r in rows]
version = names[1][len("colmap-"):-len("-global")]
assert version.startswith("4."), names
expected = ["global", "colmap-%s-global" % version, "colmap-%s-incremental" % version]
if sys.argv[2] == "1":
    expected.append("colmap-3.8-incremental")
assert names == expected, names
tessera = rows[0]
for r in rows[1:]:
    assert r["plugins"].startswith("COLMAP %s: " % r["manifest"].split("-")[1]), r["plugins"]
    assert r["matches_of"] == "global", r
    assert r["exit_code"] == 0 and r["map_seconds"] > 0, r
    # The same matches as the Tessera row's.
    assert r["num_verified_pairs"] == tessera["num_verified_pairs"] > 0, r
    assert r["num_registered"] == r["num_images"] == 11, r
    assert r["position_error_mean_relative"] < 0.01 and r["num_wrongly_registered"] == 0, r
print("COLMAP rows:", ", ".join(names[1:]))
PY
grep -q "^| colmap-4\.[^ ]*-global | COLMAP 4\.[^ ]*: global_mapper on global's matches | - (matches of global) |" \
  "$work/1.md" || fail "the table has no COLMAP 4 global_mapper row on global's matches"

# 2. Copies: the original unchanged at every COLMAP call and after.
[ "$(wc -l < "$work/sums.txt")" -ge 3 ] || fail "the wrapper saw fewer than two mapper runs"
[ "$(cut -d' ' -f1 "$work/sums.txt" | sort -u | wc -l)" -eq 1 ] ||
  { cat "$work/sums.txt"; fail "the Tessera row's database changed while COLMAP ran"; }
python3 - "$work/out" <<'PY' || fail "database schemas"
import glob, sqlite3, sys
def schema(path):
    db = sqlite3.connect("file:%s?mode=ro" % path, uri=True)
    tables = {row[0] for row in db.execute("select name from sqlite_master where type='table'")}
    return db.execute("pragma user_version").fetchone()[0], tables
version, tables = schema(sys.argv[1] + "/tessera/global/database.db")
assert "frames" not in tables and "rigs" not in tables, tables
copy = glob.glob(sys.argv[1] + "/colmap/colmap-4.*/global/database.db")[0]
copy_version, copy_tables = schema(copy)
assert "frames" in copy_tables and copy_version > version, (copy_version, version, copy_tables)
print("original schema %d, COLMAP 4's copy upgraded to %d" % (version, copy_version))
PY

# 3. Binaries that cannot be used.
touch "$work/not_executable"
printf '#!/bin/bash\necho hello\n' > "$work/not_colmap"
printf '#!/bin/bash\nkill -SEGV $$\n' > "$work/crashing"
printf '#!/bin/bash\necho "COLMAP 3.6 -- Structure-from-Motion"\n' > "$work/old_colmap"
chmod +x "$work/not_colmap" "$work/crashing" "$work/old_colmap"
check_refused() {  # BINARY EXPECTED_TEXT
  local out="$work/refused_$(basename "$1")"
  "$tessera" bench --images "$work/images" --output "$out" --colmap "$1" \
    "$source_dir/manifests/global.json" > /dev/null 2> "$out.log"
  local code=$?
  [ "$code" -eq 2 ] || { cat "$out.log"; fail "--colmap $1 gave exit code $code, not 2"; }
  grep -q -- "$1: $2" "$out.log" || { cat "$out.log"; fail "--colmap $1: no line '$1: $2'"; }
  [ "$(grep -c . "$out.log")" -eq 1 ] || { cat "$out.log"; fail "--colmap $1: not one line"; }
  [ ! -d "$out/tessera/global" ] || fail "--colmap $1: a row ran before the binary was refused"
}
check_refused "$work/missing" "no such file (named by --colmap)"
check_refused "$work/not_executable" "not executable"
check_refused "$work/not_colmap" "does not say it is COLMAP"
check_refused "$work/crashing" "crashed (signal 11)"
check_refused "$work/old_colmap" "is COLMAP 3.6; tessera bench needs COLMAP 3.8 or later"

# 4. The whole pipeline.
"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/small" 320 90 > /dev/null ||
  fail "downscale to 320 px"
"$tessera" bench --images "$work/small" --gt "$gt" --output "$work/out4" --threads 2 \
  --json "$work/4.json" --colmap "$colmap4" "$source_dir/manifests/fast.json" \
  > "$work/4.md" 2> "$work/4.log"
code=$?
[ "$code" -eq 0 ] || { cat "$work/4.md" "$work/4.log"; fail "the whole pipeline: exit $code"; }
python3 - "$work/4.json" <<'PY' || { cat "$work/4.md"; fail "COLMAP 4's whole pipeline"; }
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
assert [r["manifest"].split("-")[-1] for r in rows] == ["fast", "global", "incremental"], rows
glob, incr = rows[1], rows[2]
for r in (glob, incr):
    assert r["exit_code"] == 0 and r["matches_of"] == "", r
    assert r["plugins"].startswith("COLMAP 4.") and "sift / exhaustive" in r["plugins"], r
    assert r["num_pairs"] == 55 and r["num_verified_pairs"] > 0 and r["num_registered"] >= 9, r
    assert r["total_seconds"] >= r["extract_seconds"] + r["match_seconds"] > 0, r
assert (glob["extract_seconds"], glob["match_seconds"]) == (incr["extract_seconds"], incr["match_seconds"])
assert glob["num_verified_pairs"] == incr["num_verified_pairs"]
print("whole pipeline: %d/%d and %d/%d registered" % (
    glob["num_registered"], glob["num_images"], incr["num_registered"], incr["num_images"]))
PY
echo "PASS"
