#!/bin/bash
# Outputs are as safe as inputs (issue 32): Tessera replaces or removes only what it
# wrote, places a model and its exports as one set, and never writes through a link. On
# a 512 px copy of the in-repository sample (5 images), with ORB for speed:
#  1. a COLMAP project's own sparse/1 (with notes) and sparse/2 are left, and named;
#  2. OUTPUT/sparse a link to another folder: exit 2 naming it, the folder untouched;
#  3. binary to text, and a dropped exporter: no stale .bin or PLY is left;
#  4. a full disk (ulimit -f) during a re-map: exit 2, the earlier model byte-identical;
#  5. kill -9 between two renames (strace fault injection): each entry is the old or the
#     new one whole, and a rerun completes and leaves no temporary;
#  6. exporter options naming workspace files, or two exporters writing one path: exit 2
#     before anything is replaced, the database intact;
#  7. a failing exporter stops the ones after it; the earlier set stays whole;
#  8. a rerun that builds no model (exit 3) leaves no model of an earlier run;
#  9. a gaussian_splatting re-export of a smaller model leaves none of the old images;
# 10. run_summary.json never describes models that are not there (issue 47): `map` with
#     another mapper, and a `map` that builds no model (exit 3), remove it; `run` writes
#     its own, naming its mapper and its models.
# 11. a forged ledger (issue 46): entries naming a file outside OUTPUT, database.db and an
#     input image, each with its real size and XXH3: exit 2 naming the ledger and the
#     entry, nothing deleted; a file Tessera wrote and the user edited is named as that.
# usage: outputs_test.sh TESSERA DOWNSCALE SOURCE_DIR FAILING_PLUGIN_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
failing_plugins=$4
make_image="python3 $source_dir/tests/tools/make_test_image.py"
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/all" 512 90 > /dev/null ||
  fail "downscale"
mkdir -p "$work/d"
for i in 3 4 5 6 7; do cp "$work/all/$(printf %04d "$i").jpg" "$work/d/"; done
manifest() {  # manifest FILE EXPORTERS_JSON
  cat > "$1" <<JSON
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 1500}},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": $2},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}}
JSON
}
manifest "$work/bin.json" '[{"plugin": "colmap_binary"}, {"plugin": "ply"}, {"plugin": "transforms_json"}]'
manifest "$work/text.json" '[{"plugin": "colmap_text"}, {"plugin": "transforms_json"}]'
tess() {  # tess LOG MANIFEST VERB ARGS...
  local log=$1 file=$2
  shift 2
  "$tessera" "$@" --manifest "$file" --threads 2 > "$log" 2>&1
}
digests() { (cd "$1" && find . -type f ! -name '.tessera_outputs.json' | sort | xargs -r sha1sum); }

# A finished workspace, copied for each case.
tess "$work/base.log" "$work/bin.json" run --images "$work/d" --output "$work/base" ||
  { cat "$work/base.log"; fail "the first run"; }
[ -f "$work/base/sparse/0/images.bin" ] && [ -f "$work/base/sparse/0/points3D.ply" ] ||
  fail "the first run wrote no binary model and PLY"
fresh() { rm -rf "$1"; cp -a "$work/base" "$1"; }

# 1. A COLMAP project's own models.
fresh "$work/p"
mkdir -p "$work/p/sparse/1" "$work/p/sparse/2"
echo "mine" > "$work/p/sparse/1/notes.txt"
echo "theirs" > "$work/p/sparse/2/images.bin"
tess "$work/p.log" "$work/bin.json" map --images "$work/d" --output "$work/p" ||
  { cat "$work/p.log"; fail "map beside a COLMAP project's models"; }
[ "$(cat "$work/p/sparse/1/notes.txt")" = mine ] && [ "$(cat "$work/p/sparse/2/images.bin")" = theirs ] ||
  fail "a COLMAP project's own sparse/1 or sparse/2 was changed"
grep -q "\[warning\] $work/p/sparse/1 was not written by Tessera" "$work/p.log" ||
  { cat "$work/p.log"; fail "sparse/1 not named in a warning"; }
echo "foreign models: left, and named"

# 2. OUTPUT/sparse a link.
fresh "$work/l"
mkdir -p "$work/elsewhere/0"
echo "precious" > "$work/elsewhere/0/images.bin"
rm -rf "$work/l/sparse"
ln -s "$work/elsewhere" "$work/l/sparse"
tess "$work/l.log" "$work/bin.json" map --images "$work/d" --output "$work/l"
code=$?
[ "$code" = 2 ] || { cat "$work/l.log"; fail "sparse a link: exit $code, expected 2"; }
grep -q "\[error\] $work/l/.tessera_outputs.json: the entry 'sparse/0/[a-zA-Z0-9]*\.[a-z]*' lies through $work/l/sparse, a symbolic link" "$work/l.log" ||
  { cat "$work/l.log"; fail "sparse a link: message"; }
[ "$(ls "$work/elsewhere")" = 0 ] && [ "$(cat "$work/elsewhere/0/images.bin")" = precious ] ||
  fail "the folder behind the link was changed"
echo "sparse a link: exit 2, nothing written or deleted through it"

# 3. Binary to text, PLY dropped.
fresh "$work/t"
tess "$work/t.log" "$work/text.json" map --images "$work/d" --output "$work/t" ||
  { cat "$work/t.log"; fail "re-map as text"; }
[ -f "$work/t/sparse/0/images.txt" ] || fail "no text model"
grep -q "\[info\] map: exporter 'colmap_text' wrote $work/t/sparse/0$" "$work/t.log" &&
  grep -q "\[info\] map: exporter 'transforms_json' wrote $work/t/transforms.json$" "$work/t.log" ||
  { cat "$work/t.log"; fail "the exporters' outputs were not logged"; }
stale=$(cd "$work/t" && find . -name '*.bin' -o -name '*.ply')
[ -z "$stale" ] || fail "stale outputs left beside the new ones: $stale"
echo "binary to text, PLY dropped: no stale output left"

# 4. A full disk during a re-map.
fresh "$work/g"
before=$(digests "$work/g/sparse")
( trap '' XFSZ; ulimit -f 40; exec "$tessera" map --images "$work/d" --output "$work/g" \
    --manifest "$work/text.json" --threads 2 ) > "$work/g.log" 2>&1
code=$?
[ "$code" = 2 ] || { cat "$work/g.log"; fail "disk full: exit $code, expected 2"; }
grep -q "disk full" "$work/g.log" || { cat "$work/g.log"; fail "disk full: message"; }
[ "$(digests "$work/g/sparse")" = "$before" ] || fail "disk full: the earlier model changed"
tess "$work/g2.log" "$work/text.json" map --images "$work/d" --output "$work/g" ||
  { cat "$work/g2.log"; fail "re-map after the full disk"; }
[ ! -e "$work/g/.tessera_staging" ] || fail "disk full: the staging folder was left"
echo "disk full: exit 2, the earlier model byte-identical, a rerun completes"

# 5. kill -9 between the renames that place the set (sparse, transforms.json, then the
# summary): at the second.
fresh "$work/k"
old_transforms=$(sha1sum < "$work/k/transforms.json")
strace -f -qq -e trace=renameat2 -e inject=renameat2:signal=SIGKILL:when=2 \
  -o /dev/null "$tessera" map --images "$work/d" --output "$work/k" --manifest "$work/text.json" \
  --threads 2 > "$work/k.log" 2>&1
code=$?
if [ "$code" = 137 ] || [ "$code" = 9 ]; then
  ls "$work/k/sparse/0" | grep -q '\.txt$' && ls "$work/k/sparse/0" | grep -q '\.bin$' &&
    fail "kill -9: sparse/0 mixes the old and the new model"
  [ -f "$work/k/sparse/0/images.txt" ] || fail "kill -9 after the first rename: sparse/0 is not the new model"
  [ "$(sha1sum < "$work/k/transforms.json")" = "$old_transforms" ] ||
    fail "kill -9 before the second rename: transforms.json is not the old one"
  tess "$work/k2.log" "$work/text.json" map --images "$work/d" --output "$work/k" ||
    { cat "$work/k2.log"; fail "rerun after kill -9"; }
  leftovers=$(cd "$work/k" && find . -name '.tessera_staging' -o -name '*tmp-*')
  [ -z "$leftovers" ] || fail "kill -9: leftovers after the rerun: $leftovers"
  echo "kill -9 between renames: each entry whole, a rerun completes, no leftovers"
else
  cat "$work/k.log"
  skip_part_or_fail "strace could not inject a kill (exit $code)"
fi

# 6. Exporter options that name workspace files, and two exporters writing one path.
fresh "$work/o"
manifest "$work/db.json" '[{"plugin": "transforms_json", "options": {"file": "database.db"}}]'
tess "$work/o.log" "$work/db.json" map --images "$work/d" --output "$work/o"
code=$?
[ "$code" = 2 ] || { cat "$work/o.log"; fail "file database.db: exit $code, expected 2"; }
grep -q "writes $work/o/database.db, a file of the workspace itself" "$work/o.log" ||
  { cat "$work/o.log"; fail "file database.db: message"; }
[ "$(head -c 15 "$work/o/database.db")" = "SQLite format 3" ] || fail "the database was overwritten"
manifest "$work/dot.json" '[{"plugin": "colmap_binary"}, {"plugin": "gaussian_splatting", "options": {"folder": "."}}]'
tess "$work/o2.log" "$work/dot.json" map --images "$work/d" --output "$work/o"
code=$?
[ "$code" = 2 ] || { cat "$work/o2.log"; fail "folder '.': exit $code, expected 2"; }
grep -q "exporters 'colmap_binary' and 'gaussian_splatting' both write sparse/0/" "$work/o2.log" ||
  { cat "$work/o2.log"; fail "folder '.': message"; }
[ "$(digests "$work/o/sparse")" = "$(digests "$work/base/sparse")" ] || fail "folder '.': sparse changed"
echo "exporter paths: workspace files and two writers of one path refused, nothing replaced"

# 7. A failing exporter stops the ones after it.
fresh "$work/f"
manifest "$work/fail.json" '[{"plugin": "colmap_text"}, {"plugin": "failing_exporter", "options": {"fail": "custom"}}, {"plugin": "gaussian_splatting"}]'
TESSERA_PLUGIN_PATH=$failing_plugins tess "$work/f.log" "$work/fail.json" map --images "$work/d" --output "$work/f"
code=$?
[ "$code" != 0 ] || { cat "$work/f.log"; fail "a failing exporter: exit 0"; }
grep -q "plugin 'failing_exporter' failed while exporting model 0" "$work/f.log" ||
  { cat "$work/f.log"; fail "a failing exporter: message"; }
[ "$(digests "$work/f/sparse")" = "$(digests "$work/base/sparse")" ] || fail "a failing exporter: the earlier set changed"
[ -z "$(find "$work/f" -path '*gaussian_splatting*')" ] || fail "the exporter after the failing one ran"
echo "a failing exporter: the ones after it not run, the earlier set whole (exit $code)"

# 8. A rerun that builds no model removes the earlier models.
fresh "$work/n"
rm -f "$work/n/mapping_summary.json.keep"
mkdir -p "$work/flat"
$make_image flat "$work/flat/a.png"
$make_image flat "$work/flat/b.png"
tess "$work/n.log" "$work/bin.json" run --images "$work/flat" --output "$work/n"
code=$?
[ "$code" = 3 ] || { cat "$work/n.log"; fail "no model: exit $code, expected 3"; }
[ ! -e "$work/n/sparse" ] && [ ! -e "$work/n/transforms.json" ] || fail "no model: an earlier model is left"
python3 -c 'import json,sys; assert json.load(open(sys.argv[1]))["models"] == []' "$work/n/mapping_summary.json" ||
  fail "no model: mapping_summary.json still lists the earlier models"
echo "no model: the earlier models removed, mapping_summary.json lists none"

# 9. A 3DGS re-export of a model of 4 of the 5 images into the same folder.
mkdir -p "$work/d4"
cp "$work"/d/000[3456].jpg "$work/d4/"
tess "$work/small.log" "$work/bin.json" run --images "$work/d4" --output "$work/small" ||
  { cat "$work/small.log"; fail "the run on 4 images"; }
"$tessera" export --model "$work/base/sparse/0" --format gaussian_splatting --images "$work/d" \
  --output "$work/gs" > "$work/gs1.log" 2>&1 || { cat "$work/gs1.log"; fail "the first 3DGS export"; }
[ "$(ls "$work/gs/gaussian_splatting/images" | wc -l)" = 5 ] || fail "the first 3DGS export has not 5 images"
"$tessera" export --model "$work/small/sparse/0" --format gaussian_splatting --images "$work/d4" \
  --output "$work/gs" > "$work/gs2.log" 2>&1 || { cat "$work/gs2.log"; fail "the second 3DGS export"; }
[ "$(ls "$work/gs/gaussian_splatting/images" | wc -l)" = 4 ] && [ ! -e "$work/gs/gaussian_splatting/images/0007.jpg" ] ||
  fail "the re-export of a smaller model left old images: $(ls "$work/gs/gaussian_splatting/images")"
echo "3DGS re-export of a smaller model: the old images gone"

# 10. run_summary.json follows the model set.
with_mapper() {  # with_mapper FILE MAPPER_JSON: bin.json with that mapper
  python3 - "$work/bin.json" "$1" "$2" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["pipeline"]["mapper"] = json.loads(sys.argv[3])
json.dump(m, open(sys.argv[2], "w"))
PY
}
summary_mapper() {  # summary_mapper RUN_SUMMARY: the mapper it names
  python3 -c 'import json,sys; print([p["plugin"] for p in json.load(open(sys.argv[1]))["plugins"] if p["slot"] == "mapper"][0])' "$1"
}
fresh "$work/s"
[ "$(summary_mapper "$work/s/run_summary.json")" = incremental ] || fail "run_summary.json of the first run"
with_mapper "$work/global.json" '{"plugin": "global"}'
tess "$work/s1.log" "$work/global.json" map --images "$work/d" --output "$work/s" ||
  { cat "$work/s1.log"; fail "map with the global mapper"; }
[ ! -e "$work/s/run_summary.json" ] ||
  fail "map with the global mapper: run_summary.json left, naming the $(summary_mapper "$work/s/run_summary.json") mapper"
with_mapper "$work/none.json" '{"plugin": "incremental", "options": {"init_min_num_inliers": 1000000}}'
tess "$work/s2.log" "$work/bin.json" run --images "$work/d" --output "$work/s" ||
  { cat "$work/s2.log"; fail "run again"; }
[ -f "$work/s/run_summary.json" ] || fail "run again: no run_summary.json"
tess "$work/s3.log" "$work/none.json" map --images "$work/d" --output "$work/s"
code=$?
[ "$code" = 3 ] || { cat "$work/s3.log"; fail "map with no initial pair: exit $code, expected 3"; }
[ ! -e "$work/s/sparse" ] || fail "map with no model: sparse/ left"
[ ! -e "$work/s/run_summary.json" ] ||
  fail "map with no model: run_summary.json left, saying $(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["map"]["num_models"])' "$work/s/run_summary.json") models"
tess "$work/s4.log" "$work/global.json" run --images "$work/d" --output "$work/s" ||
  { cat "$work/s4.log"; fail "run with the global mapper"; }
[ "$(summary_mapper "$work/s/run_summary.json")" = global ] || fail "run with the global mapper: run_summary.json"
python3 - "$work/s" <<'PY' || fail "run with the global mapper: run_summary.json and mapping_summary.json disagree"
import json, sys
run = json.load(open(sys.argv[1] + "/run_summary.json"))
mapping = json.load(open(sys.argv[1] + "/mapping_summary.json"))
assert run["map"]["num_models"] == len(mapping["models"]), (run["map"], len(mapping["models"]))
PY
echo "run_summary.json: removed by map (another mapper; no model, exit 3), rewritten by run"
# 11. A forged ledger.
forge() {  # forge OUTPUT ENTRY FILE: ENTRY added to OUTPUT's ledger with FILE's size and XXH3
  python3 - "$@" <<'PY'
import ctypes, ctypes.util, json, os, sys
out, entry, file = sys.argv[1:4]
path = os.path.join(out, ".tessera_outputs.json")
ledger = json.load(open(path))
data = open(file, "rb").read()
xxhash = ctypes.CDLL(ctypes.util.find_library("xxhash"))
xxhash.XXH3_64bits.restype = ctypes.c_uint64
xxhash.XXH3_64bits.argtypes = [ctypes.c_char_p, ctypes.c_size_t]
ledger["files"].append({"path": entry, "size": len(data),
                        "xxh3": "%016x" % xxhash.XXH3_64bits(data, len(data))})
json.dump(ledger, open(path, "w"))
PY
}
echo "precious" > "$work/victim.txt"
for entry in ../victim.txt "$work/victim.txt" sparse/0/../../../victim.txt database.db ../d/0003.jpg; do
  fresh "$work/x"
  case $entry in
    database.db) file="$work/x/database.db" ;;
    ../d/*) file="$work/d/0003.jpg" ;;
    *) file="$work/victim.txt" ;;
  esac
  forge "$work/x" "$entry" "$file" || fail "forging the ledger"
  before=$(sha1sum < "$file")
  tess "$work/x.log" "$work/bin.json" map --output "$work/x"
  code=$?
  [ "$code" = 2 ] || { cat "$work/x.log"; fail "forged entry $entry: exit $code, expected 2"; }
  grep -qF "[error] $work/x/.tessera_outputs.json: the entry '$entry'" "$work/x.log" ||
    { cat "$work/x.log"; fail "forged entry $entry: message"; }
  [ "$(sha1sum < "$file")" = "$before" ] || fail "forged entry $entry: $file was deleted"
  [ "$(digests "$work/x/sparse")" = "$(digests "$work/base/sparse")" ] ||
    fail "forged entry $entry: the earlier model changed"
done
fresh "$work/e"
echo '{"edited": true}' > "$work/e/transforms.json"
tess "$work/e.log" "$work/bin.json" map --output "$work/e"
code=$?
[ "$code" = 2 ] && grep -q "transforms.json is a file that Tessera wrote but that has changed since" "$work/e.log" ||
  { cat "$work/e.log"; fail "an edited output: exit $code or message"; }
[ "$(cat "$work/e/transforms.json")" = '{"edited": true}' ] || fail "an edited output was replaced"
echo "forged ledger: each entry refused by name (exit 2), nothing deleted; an edited output named so"
echo "PASS"
