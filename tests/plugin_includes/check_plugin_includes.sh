#!/bin/bash
# Plugins compile against the installed SDK only. Every quoted #include in a source or
# header under ROOT/plugins must name
#   - an SDK header: tessera/... under ROOT/host/include/ (Tessera::sdk, Tessera::io);
#   - a file of the plugin's own folder (plugins/KIND/NAME/...), or
#   - a file of a plugins/*/common/ folder, as "common/...";
# test and benchmark sources (*_test.cc, *_benchmark.cc, *_test_util.h) may also include
# the test support headers of ROOT/tests/support/.
# Prints one line per offending include (file:line: the include and why) and exits 1;
# exits 0 when there is none.
# usage: check_plugin_includes.sh ROOT
set -uo pipefail
root=$1
[ -d "$root/plugins" ] || { echo "check_plugin_includes: $root/plugins is not a folder"; exit 2; }
failures=0
# Whether PATH is a file inside the folder DIR ("../" may not leave it).
inside_plugin() {
  local dir path
  dir=$(realpath -m "$1")
  path=$(realpath -m "$2")
  [ -f "$path" ] && [[ $path == "$dir"/* ]]
}
while IFS= read -r -d '' file; do
  relative=${file#"$root"/}
  # plugins/KIND/NAME/...: the plugin's folder is the first three components.
  plugin_dir=$(echo "$relative" | cut -d/ -f1-3)
  base=$(basename "$file")
  is_test=0
  case "$base" in *_test.cc | *_benchmark.cc | *_test_util.h) is_test=1 ;; esac
  line_number=0
  while IFS= read -r line; do
    line_number=$((line_number + 1))
    [[ $line =~ ^[[:space:]]*#[[:space:]]*include[[:space:]]*\"([^\"]+)\" ]] || continue
    include=${BASH_REMATCH[1]}
    if [[ $include == tessera/* ]]; then
      [ -f "$root/host/include/$include" ] && continue
      why="not a header of the SDK (host/include/tessera/)"
    elif [[ $include == common/* ]] && compgen -G "$root/plugins/*/$include" > /dev/null; then
      continue
    elif inside_plugin "$root/$plugin_dir" "$(dirname "$file")/$include" ||
         inside_plugin "$root/$plugin_dir" "$root/$plugin_dir/$include"; then
      continue
    elif [ $is_test = 1 ] && [ -f "$root/tests/support/$include" ]; then
      continue
    else
      why="neither in the SDK (tessera/...) nor local to $plugin_dir or plugins/*/common"
    fi
    echo "$relative:$line_number: #include \"$include\": $why"
    failures=$((failures + 1))
  done < "$file"
done < <(find "$root/plugins" -type f \( -name '*.h' -o -name '*.hpp' -o -name '*.cc' -o -name '*.cpp' \) -print0 | sort -z)
[ $failures = 0 ] || { echo "$failures include(s) outside the SDK under $root/plugins"; exit 1; }
