#!/usr/bin/env bash
# Prepares, here, what bench/gpu.sh needs on a lent GPU machine, which has no Debian packages and
# no network (device/README.md): .gpu/gpu.tar.xz (this build's programs, lib/dayflux, the test
# binary, bench/gpu_replay_bench and the Debian libraries they load, in runtime/; compressed, since unpacked they pass
# the 64 MiB a run may carry: Embree alone is 43 MB) and .gl/ (the Vulkan loader's packages, to
# be unpacked there). Both are ignored by git (.git/info/exclude), so they travel only when a
# run carries them: carry [".gpu", ".gl"], then
#   for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; BUILD=.gpu bench/gpu.sh
# (bench/gpu.sh unpacks the archive where BUILD holds one).
# usage: bench/gpu_bundle.sh   (after tools/build.sh; BUILD: the build tree, build)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=$(realpath "${BUILD:-$root/build}")
cd "$root"
for d in /.gpu/ /.gl/; do
    grep -qx "$d" .git/info/exclude 2>/dev/null || echo "$d" >> .git/info/exclude
done
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage"/{bin,bench,lib,test,runtime}
cp "$BUILD/bin/rcontrib-gpu" "$BUILD/bin/rfluxmtx-gpu" "$BUILD/bin/rtrace_dc-gpu" "$BUILD/bin/gen_dc" \
    "$BUILD/bin/ds_illum" "$BUILD/bin/genBSDF" "$stage/bin/"
cp "$BUILD/bench/gpu_replay_bench" "$stage/bench/"
cp -r "$BUILD/lib/dayflux" "$stage/lib/"
cp "$BUILD/test/dayflux_tests" "$stage/test/"
# The shared libraries both load, but for the C library's own (those the machine has) and the
# Vulkan loader (unpacked from .gl there, where it finds the machine's NVIDIA driver).
for exe in "$stage"/bin/* "$stage"/bench/* "$stage/test/dayflux_tests"; do
    ldd "$exe" | awk '$3 ~ /^\// {print $3}'
done | sort -u | grep -vE '/(libc|libm|libmvec|libpthread|libdl|librt|ld-linux-x86-64|libvulkan)\.so' |
    while read -r lib; do cp -L "$lib" "$stage/runtime/"; done
strip --strip-unneeded "$stage"/bin/* "$stage"/bench/* "$stage"/test/* "$stage"/runtime/*
rm -rf .gpu
mkdir -p .gpu
tar -C "$stage" -cf - . | xz -T0 -6 > .gpu/gpu.tar.xz
# The loader and its kin, as device/README.md says (amd64 packages, whatever this machine is).
if [ ! -d .gl ] || ! ls .gl/libvulkan1_*.deb > /dev/null 2>&1; then
    mkdir -p .gl /tmp/amd64/partial
    o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
    apt-get $o update -qq > /dev/null
    (cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 \
        libgles2 > /dev/null)
fi
du -sh .gpu .gl
