#!/bin/bash
# The models of the in-repository sample (examples/fountain-P11-small, 11 images at
# 1024x683) with the default recipe are byte for byte the reference's: the SHA-256 of
# each sparse/N/*.bin equals the line in sample_model_digests.txt beside this script,
# written by the code before the mapper was split into its steps (issue 14). A change
# that is meant to change the models regenerates the reference with
#   sample_model_test.sh TESSERA SOURCE_DIR --update
# and says why in its commit.
# usage: sample_model_test.sh TESSERA SOURCE_DIR [--update]
set -uo pipefail
tessera=$1
source_dir=$2
update=${3:-}
reference="$(dirname "$0")/sample_model_digests.txt"
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$tessera" run --images "$source_dir/examples/fountain-P11-small/images" --output "$work/out" \
  --manifest "$source_dir/manifests/default.json" --threads 2 > "$work/run.log" 2>&1 ||
  { tail -20 "$work/run.log"; fail "tessera run on the sample"; }
(cd "$work/out" && sha256sum sparse/*/*.bin) > "$work/digests.txt" || fail "no model written"
if [ "$update" = "--update" ]; then
  cp "$work/digests.txt" "$reference"
  echo "reference written: $reference"
  cat "$reference"
  exit 0
fi
if ! diff -u "$reference" "$work/digests.txt" > "$work/diff.txt"; then
  cat "$work/diff.txt"
  grep "map:" "$work/run.log" | tail -20
  fail "the sample's models differ from the reference (lines marked - are the reference's," \
    "+ this build's; a file missing on one side is a model more or less). If the change of" \
    "output is intended, regenerate the reference with: bash $0 TESSERA SOURCE_DIR --update"
fi
echo "PASS: $(wc -l < "$reference") model files identical to the reference"
