#!/bin/bash
# Every C++ file of the source tree is as clang-format (.clang-format, Google's base)
# writes it: prints each file that is not, with the command that fixes it. The files are
# git's tracked ones where the tree is a checkout, else every .cc and .h below host/,
# plugins/, python/, tests/ and benchmarks/.
# usage: format_check.sh SOURCE_DIR
set -uo pipefail
cd "$1" || exit 1
source tests/end_to_end/common.sh
command -v clang-format > /dev/null ||
  skip_or_fail "clang-format is not installed (Debian package clang-format)"
if git rev-parse --is-inside-work-tree > /dev/null 2>&1; then
  mapfile -t files < <(git ls-files '*.cc' '*.h')
else
  mapfile -t files < <(find host plugins python tests benchmarks \( -name '*.cc' -o -name '*.h' \) | sort)
fi
[ ${#files[@]} -gt 0 ] || fail "no C++ file found in $PWD"
unformatted=()
for file in "${files[@]}"; do
  [ -f "$file" ] || continue
  clang-format --dry-run -Werror "$file" > /dev/null 2>&1 || unformatted+=("$file")
done
echo "format_check: ${#files[@]} files, ${#unformatted[@]} not formatted"
if [ ${#unformatted[@]} -gt 0 ]; then
  printf '  %s\n' "${unformatted[@]}"
  echo "fix with: clang-format -i ${unformatted[*]}"
  exit 1
fi
