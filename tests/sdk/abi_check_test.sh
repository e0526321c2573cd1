#!/bin/bash
# scripts/sdk_abi_check.py on a copy of the SDK headers: a comment or whitespace edit
# passes; a declaration added to io/file_io.h fails naming the file and the unchanged
# version, and --update refuses it; a bumped version passes once --update records it; an
# added or removed header is named; `#define F(x)` and `#define F (x)` differ; the
# version never goes down.
# usage: abi_check_test.sh SOURCE_DIR
set -uo pipefail
source_dir=$1
check="$source_dir/scripts/sdk_abi_check.py"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() {
  echo "FAIL: $*"
  exit 1
}
sdk="$work/tessera"
cp -r "$source_dir/host/include/tessera" "$sdk"
version=$(sed -nE 's/^#define TESSERA_PLUGIN_ABI_VERSION ([0-9]+)$/\1/p' "$sdk/plugin.h")
[ -n "$version" ] || fail "no TESSERA_PLUGIN_ABI_VERSION in plugin.h"

# run_check NAME [--update]: the script on the copy; its output in $work/NAME.log.
run_check() {
  local name=$1
  shift
  python3 "$check" --include-dir "$sdk" "$@" > "$work/$name.log" 2>&1
}
expect_pass() {
  run_check "$@" || { cat "$work/$1.log"; fail "$1: expected exit 0"; }
}
expect_fail() {  # NAME TEXT [--update]
  local name=$1 text=$2
  shift 2
  run_check "$name" "$@" && { cat "$work/$name.log"; fail "$name: expected a failure"; }
  grep -qF -- "$text" "$work/$name.log" || { cat "$work/$name.log"; fail "$name: no '$text'"; }
}
bump() {  # NEW_VERSION
  sed -i -E "s/^#define TESSERA_PLUGIN_ABI_VERSION [0-9]+$/#define TESSERA_PLUGIN_ABI_VERSION $1/" \
    "$sdk/plugin.h"
}

expect_pass copy

# Comments, indentation and line breaks are not the ABI.
printf '\n// A note for plugin authors.\n/* Another,\n   on two lines. */\n' >> "$sdk/io/exif.h"
sed -i -e 's/^  /    /' -e 's/;$/;  /' "$sdk/camera.h"
expect_pass comments_and_whitespace

# A declaration without a bump: named, refused by --update, the record unchanged.
cp "$sdk/abi_headers.sha256" "$work/record.before"
printf 'namespace tessera {\nint AbiCheckFixture(int value);\n}\n' >> "$sdk/io/file_io.h"
expect_fail unbumped "TESSERA_PLUGIN_ABI_VERSION is still $version (changed: io/file_io.h)"
grep -qF "bump it and run scripts/sdk_abi_check.py --update" "$work/unbumped.log" ||
  fail "the message does not say what to do: $(cat "$work/unbumped.log")"
expect_fail unbumped_update "not updating the record" --update
cmp -s "$sdk/abi_headers.sha256" "$work/record.before" || fail "--update rewrote the record"

# Bumped: the stale record fails until --update writes it, then the check passes.
bump $((version + 1))
expect_fail stale "is $((version + 1)) but"
expect_pass update --update
grep -q "^ABI $((version + 1)) " "$sdk/abi_headers.sha256" || fail "the record's version"
expect_pass bumped

# Added and removed headers are named too.
echo '#pragma once' > "$sdk/new_interface.h"
rm "$sdk/io/point_colors.h"
expect_fail added_removed "(added: new_interface.h; removed: io/point_colors.h)"
bump $((version + 2))
expect_pass update2 --update

# The space between a macro's name and its parenthesis is not whitespace to the
# preprocessor: an object-like macro became function-like.
echo '#define TESSERA_ABI_FIXTURE (x)' >> "$sdk/new_interface.h"
bump $((version + 3))
expect_pass update3 --update
sed -i 's/TESSERA_ABI_FIXTURE (x)/TESSERA_ABI_FIXTURE(x)/' "$sdk/new_interface.h"
expect_fail function_like "(changed: new_interface.h)"

# The version only goes up.
bump "$version"
expect_fail down "went down from $((version + 3)) to $version" --update
echo "PASS"
