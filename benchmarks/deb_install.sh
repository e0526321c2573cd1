#!/bin/bash
# The Debian package in a clean root: builds it with `cpack -G DEB` from a Release build
# folder, makes a minimal Debian 12 root with debootstrap, installs the package there with
# `apt install ./tessera_*.deb` (so apt pulls in exactly what the package's Depends and
# Recommends name), and runs the sample of examples/ with the installed CLI, then
# `import tessera` with the installed module. Prints what the package holds, its
# dependencies, and the time of each step. Needs root, debootstrap and a Debian mirror;
# takes several minutes and about 2 GB in OUT.
# usage: benchmarks/deb_install.sh OUT [BUILD]
#   OUT: an empty or absent folder; the root is made in OUT/root and removed at the end
#        unless KEEP_ROOT=1. BUILD: a Release build folder configured with the Python
#        module, as test.sh configures build/ (the default).
set -euo pipefail
[ $# -ge 1 ] || { sed -n 's/^# usage: /usage: /p' "$0" >&2; exit 2; }
root_dir=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$1"
out=$(cd "$1" && pwd)
build=$(cd "${2:-$root_dir/build}" && pwd)
mirror=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
[ "$(id -u)" -eq 0 ] || { echo "deb_install: needs root (debootstrap, chroot)" >&2; exit 2; }
command -v debootstrap > /dev/null ||
  { echo "deb_install: debootstrap not found (apt install debootstrap)" >&2; exit 2; }
[ -z "$(ls -A "$out")" ] || { echo "deb_install: $out: not empty" >&2; exit 2; }
grep -q '^CMAKE_BUILD_TYPE:STRING=Release$' "$build/CMakeCache.txt" ||
  { echo "deb_install: $build: not a configured Release build folder" >&2; exit 2; }
[ -d "$build/python" ] || { echo "deb_install: $build: the Python module is not configured" \
  "(the quickstart leaves it out; configure with -DTESSERA_BUILD_PYTHON=ON, as test.sh does)" >&2
  exit 2; }

step() { echo "deb_install: $1: $(( $(date +%s) - started )) s"; started=$(date +%s); }
started=$(date +%s)

cmake --build "$build" -j"$(nproc)" > "$out/build.log"
(cd "$out" && cpack -G DEB --config "$build/CPackConfig.cmake" > cpack.log)
deb=$(ls "$out"/tessera_*.deb)
step "cpack $(basename "$deb") ($(du -h "$deb" | cut -f1))"
echo "--- control"
dpkg-deb --field "$deb" Package Version Architecture Installed-Size Depends Recommends Suggests
echo "--- contents, files per folder"
dpkg-deb --contents "$deb" | awk '$1 !~ /^d/ {print $6}' | sed 's|^\./||' |
  awk -F/ '{ if ($2 == "lib" && $3 == "tessera") print $1"/"$2"/"$3"/"$4; else print $1"/"$2"/"$3 }' |
  sort | uniq -c

root=$out/root
debootstrap --variant=minbase bookworm "$root" "$mirror" > "$out/debootstrap.log"
cat > "$root/etc/apt/sources.list" << EOF
deb $mirror bookworm main
deb $mirror bookworm-updates main
deb http://deb.debian.org/debian-security bookworm-security main
EOF
cp /etc/resolv.conf "$root/etc/resolv.conf"
mount -t proc proc "$root/proc"
trap 'umount "$root/proc" 2> /dev/null || true; [ "${KEEP_ROOT:-0}" = 1 ] || rm -rf "$root"' EXIT
step "debootstrap bookworm minbase ($(du -sxh "$root" | cut -f1))"

cp "$deb" "$root/tmp/"
cp -r "$root_dir/examples/fountain-P11-small" "$root/tmp/sample"
chroot "$root" apt-get update -qq
DEBIAN_FRONTEND=noninteractive chroot "$root" \
  apt-get install -y -qq "/tmp/$(basename "$deb")" > "$out/apt.log"
step "apt install ./$(basename "$deb") ($(du -sxh "$root" | cut -f1) with its dependencies)"

chroot "$root" tessera --version
chroot "$root" tessera plugins | tail -n +1 | wc -l | sed 's/^/plugins listed (lines): /'
chroot "$root" tessera run --images /tmp/sample/images --camera-K /tmp/sample/K.txt \
  --output /tmp/sample-output > "$out/run.log" 2>&1
registered=$(chroot "$root" python3 -c "
import tessera
model = tessera.Reconstruction('/tmp/sample-output/sparse/0')
print(f'{model.num_reg_images()}/{len(model.images)}')")
step "tessera run on the sample, model read by the installed module: $registered registered"
[ "$registered" = "11/11" ] || { echo "deb_install: expected 11/11 registered" >&2; exit 1; }
echo "deb_install: passed"
