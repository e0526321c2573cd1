#!/bin/bash
# The installed documentation checked against the installed headers
# (scripts/check_installed_docs.py) on a prefix holding component sdk_docs; then the
# checker fails on a copy with a broken link, a missing options page and a stale ABI.
# usage: installed_docs_test.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
build_dir=$1
source_dir=$2
check="$source_dir/scripts/check_installed_docs.py"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() {
  echo "FAIL: $*"
  exit 1
}
cmake --install "$build_dir" --prefix "$work/prefix" --component sdk_docs > "$work/install.log" ||
  { cat "$work/install.log"; fail "cmake --install --component sdk_docs"; }
docs="$work/prefix/share/doc/tessera"
python3 "$check" "$work/prefix" --source "$source_dir" || fail "the installed documentation"
grep -q "GlobalMapperOptions" "$docs/plugins/mappers/global.md" ||
  fail "plugins/mappers/global.md is not the global mapper's options page"

# The checker fails where it should.
cp -r "$work/prefix" "$work/broken"
echo 'See [the missing page](nowhere.md).' >> "$work/broken/share/doc/tessera/plugins/mapper.md"
rm "$work/broken/share/doc/tessera/plugins/mappers/global.md"
sed -i -E 's/^#define TESSERA_PLUGIN_ABI_VERSION ([0-9]+)$/#define TESSERA_PLUGIN_ABI_VERSION 999/' \
  "$work/broken/include/tessera/plugin.h"
python3 "$check" "$work/broken" > "$work/broken.log" && fail "the checker passed a broken tree"
for text in "the link 'nowhere.md' does not resolve" "options page of the bundled mappers 'global'" \
    "does not say 'It is now 999'"; do
  grep -qF "$text" "$work/broken.log" || { cat "$work/broken.log"; fail "the checker did not say: $text"; }
done
echo "PASS"
