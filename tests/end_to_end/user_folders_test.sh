#!/bin/bash
# The files Tessera makes in a user's folders, and the folders it reads (issue 60, items
# 2, 3 and 5). On a 512 px copy of examples/fountain-P11-small (11 images) and a COLMAP
# text model of them written here (no mapping: export and extract only, seconds):
#  1. a gaussian_splatting export put inside the image folder (export --output IMG/out)
#     is not read back as photos: `extract --images IMG` ingests 11 images, not 22, and
#     says in one line that it skipped the folder holding Tessera's outputs;
#  2. a model whose camera has fx = 0, exported with each format that writes intrinsics
#     (gaussian_splatting, transforms_json, colmap_text, colmap_binary): exit 2 naming
#     the camera and the focal length, nothing placed;
#  3. OUTPUT/.tessera.lock a hard link to a file elsewhere: exit 2 naming the lock, the
#     file as it was (it was truncated to 0 bytes);
#  4. files named like an interrupted write's temporary (.notes.tmp-999999 in OUTPUT,
#     sparse/0/.draft.tmp-999998, .x.tmp-N in a user folder that a forged ledger names)
#     survive an export into that folder.
# usage: user_folders_test.sh TESSERA DOWNSCALE SOURCE_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/img" 512 90 > /dev/null ||
  fail "downscale"
cat > "$work/m.json" <<'JSON'
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 500}}},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true}}
JSON
# The size of the copies, from the first JPEG's frame header.
read -r width height < <(python3 - "$work/img/0000.jpg" <<'PY'
import struct, sys
data = open(sys.argv[1], "rb").read()
i = 2
while i + 9 < len(data):
    marker = data[i + 1]
    if 0xC0 <= marker <= 0xC3:
        height, width = struct.unpack(">HH", data[i + 5:i + 9])
        print(width, height)
        break
    i += 2 + struct.unpack(">H", data[i + 2:i + 4])[0]
PY
)
[ -n "${width:-}" ] || fail "the size of the downscaled images"
# A COLMAP text model of the 11 images: one PINHOLE camera, poses along x, no points.
model() {  # model DIR FX
  mkdir -p "$1"
  echo "1 PINHOLE $width $height $2 460 $((width / 2)) $((height / 2))" > "$1/cameras.txt"
  : > "$1/images.txt"
  for i in $(seq 0 10); do
    printf '%d 1 0 0 0 %d 0 0 1 %04d.jpg\n\n' $((i + 1)) "$i" "$i" >> "$1/images.txt"
  done
  : > "$1/points3D.txt"
}
model "$work/model" 460
model "$work/model_fx0" 0

# 1. An export inside the image folder.
"$tessera" export --model "$work/model" --format gaussian_splatting --images "$work/img" \
  --output "$work/img/out" > "$work/e1.log" 2>&1 || { cat "$work/e1.log"; fail "export into IMG/out"; }
[ "$(ls "$work/img/out/gaussian_splatting/images" | wc -l)" = 11 ] || fail "the export has not 11 images"
"$tessera" extract --images "$work/img" --output "$work/w1" --manifest "$work/m.json" --threads 2 \
  > "$work/x1.log" 2>&1 || { cat "$work/x1.log"; fail "extract"; }
[ "$(grep -c "Skipped the folder 'out': it holds Tessera's outputs (.tessera_outputs.json), which are never read as input" "$work/x1.log")" = 1 ] ||
  { cat "$work/x1.log"; fail "no one line for the skipped export"; }
grep -q "extract: 11 images, " "$work/x1.log" || { cat "$work/x1.log"; fail "not 11 images ingested"; }
[ "$(sqlite3 "$work/w1/database.db" "SELECT COUNT(*) FROM images")" = 11 ] ||
  fail "the database holds $(sqlite3 "$work/w1/database.db" "SELECT COUNT(*) FROM images") images"
echo "an export inside the image folder: skipped with one line, 11 images ingested"

# 2. fx = 0, with each format that writes intrinsics.
for format in gaussian_splatting transforms_json colmap_text colmap_binary; do
  out="$work/fx0_$format"
  "$tessera" export --model "$work/model_fx0" --format "$format" --images "$work/img" \
    --output "$out" > "$work/f.log" 2>&1
  code=$?
  [ "$code" = 2 ] || { cat "$work/f.log"; fail "fx = 0 with $format: exit $code, expected 2"; }
  grep -q "^\[error\] .*'$format'.*camera 1: its focal length fx = 0 is not a positive finite number of pixels" "$work/f.log" ||
    { cat "$work/f.log"; fail "fx = 0 with $format: message"; }
  placed=$(cd "$out" 2> /dev/null && find . -mindepth 1 ! -path './.tessera_staging*' ! -name .tessera_outputs.json)
  [ -z "$placed" ] || fail "fx = 0 with $format: placed $placed"
done
echo "fx = 0: refused by each exporter naming the camera (exit 2), nothing placed"

# 3. The lock a hard link to a file elsewhere.
mkdir -p "$work/w3"
echo "precious" > "$work/victim.txt"
ln "$work/victim.txt" "$work/w3/.tessera.lock"
"$tessera" extract --images "$work/img" --output "$work/w3" --manifest "$work/m.json" --threads 2 \
  > "$work/x3.log" 2>&1
code=$?
[ "$code" = 2 ] || { cat "$work/x3.log"; fail "a hard-linked lock: exit $code, expected 2"; }
grep -qF "[error] $work/w3/.tessera.lock: is a file with 2 names (a hard link" "$work/x3.log" ||
  { cat "$work/x3.log"; fail "a hard-linked lock: message"; }
[ "$(cat "$work/victim.txt")" = precious ] || fail "the file behind the hard-linked lock changed"
[ ! -e "$work/w3/database.db" ] || fail "a hard-linked lock: the workspace was written"
echo "a hard-linked lock: refused naming it (exit 2), the file as it was"

# 4. Files named like temporaries, in OUTPUT, in a model folder, in a folder a forged
# ledger names.
out="$work/t4"
"$tessera" export --model "$work/model" --format colmap_text --output "$out" > "$work/t1.log" 2>&1 ||
  { cat "$work/t1.log"; fail "export colmap_text"; }
mkdir -p "$out/photos"
for f in .notes.tmp-999999 sparse/0/.draft.tmp-999998 photos/.x.tmp-999997 photos/.x.tmp-7; do
  echo mine > "$out/$f"
done
python3 - "$out/.tessera_outputs.json" <<'PY'
import json, sys
ledger = json.load(open(sys.argv[1]))
ledger["folders"].append("photos")
json.dump(ledger, open(sys.argv[1], "w"))
PY
"$tessera" export --model "$work/model" --format colmap_text --output "$out" > "$work/t2.log" 2>&1 ||
  { cat "$work/t2.log"; fail "export colmap_text again"; }
for f in .notes.tmp-999999 sparse/0/.draft.tmp-999998 photos/.x.tmp-999997 photos/.x.tmp-7; do
  [ "$(cat "$out/$f" 2> /dev/null)" = mine ] || { cat "$work/t2.log"; fail "$f was removed or changed"; }
done
leftovers=$(cd "$out" && find . -name '*tessera-tmp-*' -o -name .tessera_staging)
[ -z "$leftovers" ] || fail "Tessera's temporaries left: $leftovers"
echo "files named like temporaries: all kept"
echo "PASS"
