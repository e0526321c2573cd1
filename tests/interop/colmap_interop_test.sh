#!/bin/bash
# COLMAP 3.8 opens Tessera's COLMAP exports unchanged. COLMAP's own fountain-P11 model is
# written by the colmap_binary and colmap_text exporters (`tessera export`), then:
#  1. `colmap model_analyzer` reports, for both, the images, points and observations
#     that Tessera reported when it wrote them;
#  2. `colmap model_converter` turns both into text, with identical results, and the
#     text export into binary, which the analyzer reads with the same counts;
#  3. with record_order_from, the binary export is COLMAP's own files byte for byte.
# Skipped (exit 77, with a message) when colmap or the shared anchors are absent; under
# CI=true that is a failure instead (common.sh's skip_or_fail).
# usage: colmap_interop_test.sh TESSERA SHARED_DIR
set -uo pipefail
tessera=$1
shared=${TESSERA_SHARED_DIR:-$2}
source "$(dirname "$0")/../end_to_end/common.sh"
anchor="$shared/anchors/colmap-3.8/fountain-P11/sparse/0"
[ -d "$anchor" ] || skip_or_fail "COLMAP's fountain-P11 model not found at $anchor"
have_colmap || skip_or_fail "colmap is not installed (scripts/install_dependencies.sh" \
  "installs it); the COLMAP interoperability test did not run"
export QT_QPA_PLATFORM=offscreen
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# export_model FORMAT NAME [OPTIONS]: writes $work/NAME/sparse/0; prints Tessera's counts.
export_model() {
  local options='{}'
  [ $# -ge 3 ] && options=$3
  "$tessera" export --model "$anchor" --format "$1" --output "$work/$2" --options "$options" \
    2> "$work/$2.log" || { cat "$work/$2.log"; fail "tessera export --format $1"; }
  sed -nE 's/.*export: ([0-9]+) images, ([0-9]+) points, ([0-9]+) observations.*/\1 \2 \3/p' \
    "$work/$2.log"
}
# analyze MODEL_DIR: prints COLMAP's registered images, points and observations.
analyze() {
  colmap model_analyzer --path "$1" > "$work/analyzer.log" 2>&1 ||
    { cat "$work/analyzer.log"; fail "colmap model_analyzer --path $1"; }
  local images points observations
  images=$(sed -nE 's/.*Registered images: ([0-9]+).*/\1/p' "$work/analyzer.log")
  points=$(sed -nE 's/.*Points: ([0-9]+).*/\1/p' "$work/analyzer.log")
  observations=$(sed -nE 's/.*Observations: ([0-9]+).*/\1/p' "$work/analyzer.log")
  echo "$images $points $observations"
}
convert() {  # INPUT OUTPUT TYPE
  mkdir -p "$2"
  colmap model_converter --input_path "$1" --output_path "$2" --output_type "$3" \
    > "$work/converter.log" 2>&1 || { cat "$work/converter.log"; fail "colmap model_converter $1"; }
}

tessera_counts=$(export_model colmap_binary bin)
[ -n "$tessera_counts" ] || fail "tessera export printed no counts"
text_counts=$(export_model colmap_text txt)
echo "Tessera (images points observations): binary $tessera_counts, text $text_counts"
[ "$text_counts" = "$tessera_counts" ] || fail "the two exports report different counts"
[ -f "$work/txt/sparse/0/points3D.txt" ] && [ ! -f "$work/txt/sparse/0/points3D.bin" ] ||
  fail "the text export is not a text model"

# 1. COLMAP reads both exports and counts the same.
for name in bin txt; do
  colmap_counts=$(analyze "$work/$name/sparse/0")
  echo "colmap model_analyzer on the $name export: $colmap_counts"
  [ "$colmap_counts" = "$tessera_counts" ] ||
    fail "COLMAP counts $colmap_counts in the $name export, Tessera $tessera_counts"
done

# 2. COLMAP converts both exports to the same text, and the text export to binary.
convert "$work/bin/sparse/0" "$work/bin_as_txt" TXT
convert "$work/txt/sparse/0" "$work/txt_as_txt" TXT
for file in cameras.txt images.txt points3D.txt; do
  cmp -s "$work/bin_as_txt/$file" "$work/txt_as_txt/$file" ||
    fail "COLMAP reads the binary and text exports differently ($file)"
done
convert "$work/txt/sparse/0" "$work/txt_as_bin" BIN
converted_counts=$(analyze "$work/txt_as_bin")
echo "colmap model_converter: both exports give the same text; text to binary: $converted_counts"
[ "$converted_counts" = "$tessera_counts" ] || fail "after model_converter: $converted_counts"

# 3. In COLMAP's record order, the binary export is COLMAP's files byte for byte.
export_model colmap_binary ordered "{\"record_order_from\": \"$anchor\"}" > /dev/null
for file in cameras.bin images.bin points3D.bin; do
  cmp "$anchor/$file" "$work/ordered/sparse/0/$file" || fail "$file differs from COLMAP's"
done
echo "colmap_binary with record_order_from: byte-identical to COLMAP's cameras/images/points3D.bin"
echo "PASS"
