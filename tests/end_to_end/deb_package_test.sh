#!/bin/bash
# The Debian package (`cpack -G DEB`, cmake/TesseraPackage.cmake), read as dpkg reads it:
# its control fields name Debian packages that are installed here (so apt can resolve
# them on Debian 12), it holds the CLI, the host libraries, the bundled plugins, the
# recipes, the SDK and the Python module, and its tree, unpacked by dpkg-deb into a
# folder, runs the sample: the binaries find their libraries and plugins through their
# RUNPATH, relative to themselves. benchmarks/deb_install.sh installs it with apt into a
# debootstrap root instead (minutes, and a mirror), which CI cannot afford.
# usage: deb_package_test.sh BUILD_DIR SOURCE_DIR HAS_PYTHON(0|1)
set -uo pipefail
build=$1
source_dir=$2
has_python=$3
source "$(dirname "$0")/common.sh"
command -v dpkg-deb > /dev/null || { echo "SKIP: dpkg-deb not found (not Debian)"; exit 77; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

(cd "$work" && cpack -G DEB --config "$build/CPackConfig.cmake" > cpack.log 2>&1) ||
  { tail -20 "$work/cpack.log"; fail "cpack -G DEB"; }
debs=("$work"/tessera_*_*.deb)
[ ${#debs[@]} -eq 1 ] && [ -f "${debs[0]}" ] || fail "expected one tessera_*.deb, got: ${debs[*]}"
deb=${debs[0]}

[ "$(dpkg-deb --field "$deb" Package)" = tessera ] || fail "Package is not tessera"
depends=$(dpkg-deb --field "$deb" Depends)
echo "Depends: $depends"
# Every dependency has an alternative that a Debian package installed on this machine is
# or provides (libspdlog1.10 provides libspdlog1.10-fmt9, which dpkg-shlibdeps names).
dpkg-query -W -f='${db:Status-Abbrev} ${Package}, ${Provides}\n' |
  awk '$1 == "ii" { $1 = ""; print }' | tr ',' '\n' | sed 's/(.*)//; s/ //g; s/:.*//' |
  sort -u > "$work/installed.txt"
IFS=',' read -ra items <<< "$depends"
for item in "${items[@]}"; do
  found=0
  IFS='|' read -ra alternatives <<< "$item"
  for alternative in "${alternatives[@]}"; do
    name=$(echo "$alternative" | sed 's/(.*)//; s/ //g')
    grep -qxF "$name" "$work/installed.txt" && found=1
  done
  [ $found = 1 ] || fail "Depends '$item': no alternative is an installed Debian package"
done
for library in libopencv-core406 libspdlog1.10-fmt9 libexif12 libsqlite3-0; do
  [[ "$depends" == *"$library"* ]] || fail "Depends does not name $library"
done
[[ "$(dpkg-deb --field "$deb" Recommends)" == *python3-numpy* ]] ||
  fail "Recommends does not name python3-numpy"

dpkg-deb --contents "$deb" | awk '{print $6}' > "$work/contents.txt"
for path in ./usr/bin/tessera ./usr/lib/tessera/plugins/libtessera_detector_sift.so \
            ./usr/lib/tessera/plugins/libtessera_mapper_global.so \
            ./usr/share/tessera/manifests/default.json ./usr/include/tessera/plugin.h \
            ./usr/lib/cmake/Tessera/TesseraConfig.cmake ./usr/share/doc/tessera/plugin_authors_guide.md; do
  grep -qxF "$path" "$work/contents.txt" || fail "the package lacks $path"
done
if [ "$has_python" = 1 ]; then
  grep -q '^\./usr/lib/python3\.[0-9]*/dist-packages/tessera/__init__\.py$' "$work/contents.txt" ||
    fail "the package lacks the Python module"
fi
# Nothing outside /usr, and nothing of the build or source trees.
if grep -v '^\./usr/' "$work/contents.txt" | grep -vqx '\./'; then
  fail "the package writes outside /usr: $(grep -v '^\./usr/' "$work/contents.txt" | head -3)"
fi

root=$work/root
dpkg-deb -x "$deb" "$root" || fail "dpkg-deb -x"
"$root/usr/bin/tessera" plugins > "$work/plugins.txt" 2>&1 ||
  { cat "$work/plugins.txt"; fail "the unpacked tessera plugins"; }
grep -q "$root/usr/lib/tessera/plugins/libtessera_detector_sift.so" "$work/plugins.txt" ||
  fail "the unpacked CLI does not load the unpacked plugins: $(head -3 "$work/plugins.txt")"
"$root/usr/bin/tessera" run --images "$source_dir/examples/fountain-P11-small/images" \
  --camera-K "$source_dir/examples/fountain-P11-small/K.txt" --manifest default \
  --output "$work/out" --threads 2 > "$work/run.log" 2>&1 ||
  { tail -20 "$work/run.log"; fail "the unpacked tessera run on the sample"; }
if [ "$has_python" = 1 ]; then
  registered=$(PYTHONPATH=$(echo "$root"/usr/lib/python3.*/dist-packages) /usr/bin/python3 -c "
import sys, tessera
assert tessera.__file__.startswith(sys.argv[1]), tessera.__file__
model = tessera.Reconstruction(sys.argv[2])
print(f'{model.num_reg_images()}/{len(model.images)}')" "$root" "$work/out/sparse/0") ||
    fail "the unpacked module could not read the model"
else
  registered=$(grep -o '[0-9]*/[0-9]* registered' "$work/run.log" | tail -1 | cut -d' ' -f1)
  echo "SKIPPED (visible): the Python module (this build has TESSERA_BUILD_PYTHON off)"
fi
[ "$registered" = 11/11 ] || fail "expected 11/11 images registered, got '$registered'"
echo "PASS: $(basename "$deb"), $(wc -l < "$work/contents.txt") entries, sample $registered"
