#!/usr/bin/env bash
# Prepares, here, what bench/gpu.sh needs on a lent GPU machine, which has no Debian packages and
# no network (device/README.md): .gpu/ (this build's programs, lib/dayflux, the test binary and
# the Debian libraries they load, in .gpu/runtime) and .gl/ (the Vulkan loader's packages, to be
# unpacked there). Both are ignored by git (.git/info/exclude), so they travel only when a run
# carries them: carry [".gpu", ".gl"], then
#   for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; BUILD=.gpu bench/gpu.sh
# usage: bench/gpu_bundle.sh   (after tools/build.sh; BUILD: the build tree, build)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=$(realpath "${BUILD:-$root/build}")
cd "$root"
for d in /.gpu/ /.gl/; do
    grep -qx "$d" .git/info/exclude 2>/dev/null || echo "$d" >> .git/info/exclude
done
rm -rf .gpu
mkdir -p .gpu/bin .gpu/lib .gpu/test .gpu/runtime
cp "$BUILD/bin/rcontrib-gpu" .gpu/bin/
cp -r "$BUILD/lib/dayflux" .gpu/lib/
cp "$BUILD/test/dayflux_tests" .gpu/test/
# The shared libraries both load, but for the C library's own (those the machine has) and the
# Vulkan loader (unpacked from .gl there, where it finds the machine's NVIDIA driver).
for exe in .gpu/bin/rcontrib-gpu .gpu/test/dayflux_tests; do
    ldd "$exe" | awk '$3 ~ /^\// {print $3}'
done | sort -u | grep -vE '/(libc|libm|libmvec|libpthread|libdl|librt|ld-linux-x86-64|libvulkan)\.so' |
    while read -r lib; do cp -L "$lib" .gpu/runtime/; done
# The loader and its kin, as device/README.md says (amd64 packages, whatever this machine is).
if [ ! -d .gl ] || ! ls .gl/libvulkan1_*.deb > /dev/null 2>&1; then
    mkdir -p .gl /tmp/amd64/partial
    o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
    apt-get $o update -qq > /dev/null
    (cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 \
        libgles2 > /dev/null)
fi
du -sh .gpu .gl
