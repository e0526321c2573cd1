#!/bin/bash
# End-to-end test of the pipeline on a downscaled copy of fountain-P11 (made here, in a
# temporary folder):
#  1. `tessera run` verifies all 55 pairs and maps all 11 images, with the mean camera
#     position error against the ground truth under 0.1% of the scene's extent
#     (full resolution gives 0.03%), and the model is the same with another thread count;
#  2. `colmap mapper` run on Tessera's database registers all 11 images (skipped, with a
#     message, when colmap is not installed; a failure under CI=true);
#  3. kill -9 during matching, then a re-run: the same database content as an
#     uninterrupted run, and nothing detected again;
#  4. unreadable files, and entries named like photos that are none (a folder, a dangling
#     link, a FIFO, a device), are each named in a warning and counted; none blocks.
# usage: pipeline_test.sh TESSERA DOWNSCALE SHARED_DIR
set -uo pipefail
tessera=$1
downscale=$2
shared=${TESSERA_SHARED_DIR:-$3}
dataset="$shared/datasets/fountain-P11"
source "$(dirname "$0")/common.sh"
require_dataset "$dataset"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# A copy at 1024 px: a third of full resolution; K scaled to match.
scale=$("$downscale" "$dataset/images" "$work/images" 1024 95) || fail "downscale"
awk -v s="$scale" 'NR<3 {printf "%.6f %.6f %.6f\n", $1*s, $2*s, $3*s} NR==3 {print}' \
  "$dataset/K.txt" > "$work/K.txt"
db_dump() {  # the matching results of a workspace, in a canonical order
  sqlite3 "$1" "SELECT pair_id, rows, hex(data) FROM matches ORDER BY pair_id;
                SELECT pair_id, rows, config, hex(data), hex(F), hex(E), hex(H), hex(qvec), hex(tvec)
                FROM two_view_geometries ORDER BY pair_id;"
}

# 1. Uninterrupted run.
"$tessera" run --images "$work/images" --output "$work/full" --camera-K "$work/K.txt" \
  --threads 2 2> "$work/full.log" || { cat "$work/full.log"; fail "tessera run"; }
verified=$(sqlite3 "$work/full/database.db" \
  "SELECT COUNT(*) FROM two_view_geometries WHERE rows >= 15 AND config NOT IN (0, 1)")
mean_inliers=$(sqlite3 "$work/full/database.db" \
  "SELECT CAST(AVG(rows) AS INTEGER) FROM two_view_geometries WHERE rows >= 15")
echo "verified pairs: $verified of 55, mean inliers per pair: $mean_inliers"
[ "$verified" -eq 55 ] || fail "expected 55 verified pairs, got $verified"
[ -f "$work/full/sparse/0/points3D.ply" ] || fail "the default manifest's PLY is missing"
scores=$(model_scores "$tessera" "$work/full/sparse/0" "$dataset/gt") || fail "tessera eval"
read -r registered rel reproj <<< "$scores"
echo "map: $registered of 11 registered, mean position error $rel of the scene extent," \
  "mean reprojection error $reproj px"
[ "$registered" = "11" ] || fail "registered $registered of 11 images"
awk -v r="$rel" 'BEGIN { exit !(r < 0.001) }' || fail "position error $rel >= 0.1% of the extent"
awk -v r="$reproj" 'BEGIN { exit !(r < 1.0) }' || fail "mean reprojection error $reproj >= 1 px"
# Determinism: the same workspace mapped with another thread count gives the same files.
cp -r "$work/full" "$work/again"
"$tessera" map --output "$work/again" --threads 1 2> "$work/again.log" ||
  { cat "$work/again.log"; fail "tessera map"; }
for file in cameras.bin images.bin points3D.bin; do
  cmp "$work/full/sparse/0/$file" "$work/again/sparse/0/$file" ||
    fail "$file differs between --threads 2 and --threads 1"
done
echo "map with --threads 1 and 2: identical models"

# 2. COLMAP maps Tessera's matches.
if have_colmap; then
  mkdir -p "$work/colmap_sparse"
  QT_QPA_PLATFORM=offscreen colmap mapper --database_path "$work/full/database.db" \
    --image_path "$work/images" --output_path "$work/colmap_sparse" > "$work/colmap.log" 2>&1 ||
    { tail -20 "$work/colmap.log"; fail "colmap mapper failed on Tessera's database"; }
  QT_QPA_PLATFORM=offscreen colmap model_analyzer --path "$work/colmap_sparse/0" \
    > "$work/analyzer.log" 2>&1 || fail "colmap model_analyzer"
  registered=$(grep -oE "Registered images: [0-9]+" "$work/analyzer.log" | grep -oE "[0-9]+")
  echo "colmap mapper on Tessera's database registered $registered of 11 images"
  [ "$registered" = "11" ] || { cat "$work/analyzer.log"; fail "colmap registered $registered"; }
else
  skip_part_or_fail "colmap is not installed; the COLMAP interoperability check did not run"
fi

# 3. kill -9 during matching, then resume.
"$tessera" extract --images "$work/images" --output "$work/killed" --camera-K "$work/K.txt" \
  2> "$work/extract.log" || { cat "$work/extract.log"; fail "extract"; }
TESSERA_TEST_PAUSE=match.pair_committed:5 "$tessera" match --output "$work/killed" --threads 1 \
  2> "$work/match1.log" &
pid=$!
wait_until_paused $pid
kill -9 $pid 2>/dev/null && killed=yes || killed=no
wait $pid 2>/dev/null
partial=$(sqlite3 "$work/killed/database.db" "SELECT COUNT(*) FROM two_view_geometries")
echo "killed: $killed after $partial of 55 pairs"
[ "$killed" = yes ] && [ "$partial" = 5 ] || fail "the match was not killed after its fifth pair ($partial of 55 kept)"
{ "$tessera" extract --images "$work/images" --output "$work/killed" --camera-K "$work/K.txt" &&
  "$tessera" match --output "$work/killed" --threads 2; } 2> "$work/resume.log" ||
  { cat "$work/resume.log"; fail "resume"; }
grep -q "0 to detect" "$work/resume.log" || { cat "$work/resume.log"; fail "features were detected again"; }
grep -q "$partial already done" "$work/resume.log" || { cat "$work/resume.log"; fail "finished pairs were redone"; }
cmp <(db_dump "$work/full/database.db") <(db_dump "$work/killed/database.db") ||
  fail "the resumed database differs from the uninterrupted one"
echo "resume after kill -9: identical matches and geometries"

# 4. Unreadable files are named and skipped.
cp -r "$work/images" "$work/bad_images"
: > "$work/bad_images/empty.jpg"
echo "not an image" > "$work/bad_images/notes.jpg"
head -c 20000 "$work/images/0003.jpg" > "$work/bad_images/truncated.jpg"
# Entries named like photos that are none: a folder, a dangling link, a FIFO (never
# opened: the extract would wait for a writer), a link to a device outside the folder.
mkdir "$work/bad_images/folder.jpg"
ln -s missing.jpg "$work/bad_images/dangling.jpg"
mkfifo "$work/bad_images/pipe.jpg"
ln -s /dev/null "$work/bad_images/device.jpg"
timeout 300 "$tessera" extract --images "$work/bad_images" --output "$work/bad" \
  --camera-K "$work/K.txt" 2> "$work/bad.log" || { cat "$work/bad.log"; fail "extract with bad files"; }
for name in empty.jpg notes.jpg truncated.jpg folder.jpg dangling.jpg pipe.jpg device.jpg; do
  grep "warning" "$work/bad.log" | grep -q "'$name'" || { cat "$work/bad.log"; fail "no warning names $name"; }
done
grep -q "11 images (7 skipped files)" "$work/bad.log" || { cat "$work/bad.log"; fail "bad files count"; }
echo "bad files and entries: each named in a warning, 11 images kept"
echo "PASS"
