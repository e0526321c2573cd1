#!/bin/bash
# `tessera vocab` and the retrieval selector reading its file, on a 640 px copy of
# fountain-P11 (made here): the codebook has the documented size and the same bytes for
# 1 and 2 threads; a manifest whose retrieval slot names the file (not there yet) trains
# it, then matches each image with its 3 most similar images only; a truncated file, an
# ORB detector and a missing folder are bad input (exit 2) with a message that names them.
# usage: vocab_test.sh TESSERA DOWNSCALE SHARED_DIR
set -uo pipefail
tessera=$1
downscale=$2
shared=${TESSERA_SHARED_DIR:-$3}
dataset="$shared/datasets/fountain-P11"
source "$(dirname "$0")/common.sh"
require_dataset "$dataset"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$downscale" "$dataset/images" "$work/images" 640 95 > /dev/null || fail "downscale"

cat > "$work/retrieval.json" <<JSON
{"pipeline": {"detector": {"plugin": "sift", "options": {"max_num_features": 2000}},
              "pair_selector": {"plugin": "retrieval",
                                "options": {"num_neighbors": 3, "codebook": "$work/vocab.bin"}},
              "matcher": {"plugin": "flann"}}}
JSON
"$tessera" vocab --images "$work/images" --output "$work/vocab.bin" --manifest \
  "$work/retrieval.json" --codebook-size 16 --threads 2 --workspace "$work/ws" \
  2> "$work/vocab.log" || { cat "$work/vocab.log"; fail "tessera vocab"; }
grep -q "vocab: codebook of 16 centres trained on 11 images" "$work/vocab.log" ||
  { cat "$work/vocab.log"; fail "vocab log"; }
size=$(stat -c %s "$work/vocab.bin")
# Header 24 bytes, 16 x 128 float32 centres, 8-byte hash.
[ "$size" = $((24 + 16 * 128 * 4 + 8)) ] || fail "codebook size $size"
"$tessera" -q vocab --images "$work/images" --output "$work/vocab1.bin" --manifest \
  "$work/retrieval.json" --codebook-size 16 --threads 1 || fail "tessera vocab --threads 1"
cmp -s "$work/vocab.bin" "$work/vocab1.bin" || fail "codebooks differ between 1 and 2 threads"

"$tessera" match --output "$work/ws" --manifest "$work/retrieval.json" --threads 2 \
  2> "$work/match.log" || { cat "$work/match.log"; fail "tessera match with the codebook"; }
pairs=$(sqlite3 "$work/ws/database.db" "SELECT COUNT(*) FROM matches")
verified=$(sqlite3 "$work/ws/database.db" \
  "SELECT COUNT(*) FROM two_view_geometries WHERE rows >= 15 AND config NOT IN (0, 1)")
echo "retrieval with a vocab codebook: $pairs pairs, $verified verified (exhaustive: 55)"
# 11 images x 3 neighbours, each pair once: between 17 and 33 pairs.
[ "$pairs" -ge 17 ] && [ "$pairs" -le 33 ] || fail "$pairs pairs"
# fountain is one scene: nearly every chosen pair verifies.
[ "$verified" -ge $((pairs - 2)) ] || fail "$verified of $pairs pairs verified"

head -c 100 "$work/vocab.bin" > "$work/truncated.bin"
sed "s|$work/vocab.bin|$work/truncated.bin|" "$work/retrieval.json" > "$work/truncated.json"
"$tessera" match --output "$work/ws" --manifest "$work/truncated.json" 2> "$work/bad.log"
code=$?
[ "$code" = 2 ] || fail "truncated codebook: exit $code"
grep -q "$work/truncated.bin: not a valid retrieval codebook" "$work/bad.log" ||
  { cat "$work/bad.log"; fail "truncated codebook message"; }

cat > "$work/orb.json" <<JSON
{"pipeline": {"detector": {"plugin": "orb"}, "pair_selector": {"plugin": "retrieval"}}}
JSON
"$tessera" vocab --images "$work/images" --output "$work/orb.bin" --manifest "$work/orb.json" \
  2> "$work/orb.log"
code=$?
[ "$code" = 2 ] || { cat "$work/orb.log"; fail "ORB: exit $code"; }
grep -q "pipeline.pair_selector.options: the retrieval pair selector needs real-valued" \
  "$work/orb.log" || { cat "$work/orb.log"; fail "ORB message"; }
[ ! -e "$work/orb.bin" ] || fail "a codebook was written for ORB"

"$tessera" vocab --images "$work/none" --output "$work/none.bin" 2> "$work/none.log"
code=$?
[ "$code" = 2 ] || { cat "$work/none.log"; fail "missing folder: exit $code"; }
echo "PASS"
