#!/bin/bash
# `tessera gui` from the command line: without a display it exits 2 with one line and
# every other verb still works; in a private Xvfb (started here, stopped by its PID;
# skipped when Xvfb is missing) the screenshot mode writes a PNG of COLMAP's fountain-P11
# model of the requested size, and a folder that is not a model is exit 2 with one line.
# usage: gui_test.sh TESSERA SHARED_DIR
set -uo pipefail
tessera=$1
shared=${TESSERA_SHARED_DIR:-$2}
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
xvfb_pid=""
trap '[ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2> /dev/null; rm -rf "$work"' EXIT

env -u DISPLAY -u WAYLAND_DISPLAY "$tessera" gui > "$work/out.txt" 2> "$work/err.txt"
code=$?
[ "$code" = 2 ] || fail "gui without a display: exit $code, expected 2"
[ "$(wc -l < "$work/err.txt")" = 1 ] || { cat "$work/err.txt"; fail "not one line"; }
grep -q "no display\|built without the GUI" "$work/err.txt" || fail "message: $(cat "$work/err.txt")"
env -u DISPLAY -u WAYLAND_DISPLAY "$tessera" plugins > /dev/null ||
  fail "tessera plugins without a display"
if grep -q "built without the GUI" "$work/err.txt"; then
  skip_or_fail "this tessera was built without the GUI"
fi

command -v Xvfb > /dev/null || skip_or_fail "Xvfb is not installed"
exec {fd}<> <(:)
Xvfb -displayfd "$fd" -screen 0 1600x1000x24 -nolisten tcp > /dev/null 2>&1 &
xvfb_pid=$!
read -r -t 10 -u "$fd" display || skip_or_fail "Xvfb did not start"
export DISPLAY=":$display" LIBGL_ALWAYS_SOFTWARE=1

mkdir -p "$work/empty"
"$tessera" gui --model "$work/empty" --screenshot "$work/x.png" 2> "$work/err.txt"
code=$?
[ "$code" = 2 ] || fail "a folder that is not a model: exit $code, expected 2"
[ "$(grep -c . "$work/err.txt")" = 1 ] || { cat "$work/err.txt"; fail "not one line"; }
grep -q "not a model" "$work/err.txt" || fail "message: $(cat "$work/err.txt")"
[ ! -e "$work/x.png" ] || fail "a screenshot was written for a folder that is not a model"

model="$shared/anchors/colmap-3.8/fountain-P11/sparse/0"
[ -f "$model/points3D.bin" ] || skip_or_fail "$model not found"
"$tessera" -q gui --model "$model" --screenshot "$work/shot.png" --width 640 --height 400 ||
  fail "screenshot of $model"
# PNG signature, then the IHDR chunk: width and height as big-endian 32-bit integers.
size=$(python3 -c 'import struct,sys; d=open(sys.argv[1],"rb").read(24); assert d[:8]==b"\x89PNG\r\n\x1a\n"; print(*struct.unpack(">II", d[16:24]))' "$work/shot.png") ||
  fail "not a PNG"
[ "$size" = "640 400" ] || fail "screenshot size $size, expected 640 400"
echo "PASS"
