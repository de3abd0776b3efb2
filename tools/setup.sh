#!/usr/bin/env bash
# Installs what dayflux needs on Debian 12 (bookworm), quietly and idempotently.
# Everything comes from bookworm except mesa-vulkan-drivers, which comes from bookworm-backports
# because bookworm's Mesa (22.x) has no VK_KHR_ray_query on lavapipe.
set -euo pipefail

packages=(
    build-essential cmake ninja-build pkg-config git xz-utils python3
    libvulkan-dev vulkan-tools glslang-dev glslang-tools libshaderc-dev spirv-tools
    libembree-dev libtbb-dev libglm-dev libopenexr-dev libpugixml-dev libeigen3-dev libopenblas-dev
    libgtest-dev libgmock-dev libbenchmark-dev libcairo2-dev fonts-dejavu-core parallel
)
backports=(mesa-vulkan-drivers)
# The tests' own (tools/test.sh), for examples/shards: a Slurm cluster of one node, and an ssh
# host (this machine) for GNU parallel.
if [ "${1:-}" = --tests ]; then
    packages+=(slurmctld slurmd slurm-client munge openssh-server openssh-client rsync)
fi

missing=()
for p in "${packages[@]}" "${backports[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# mesa-vulkan-drivers must be the backports build (ray queries); bookworm's does not count.
if dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null | grep -q '^22\.'; then
    missing+=(mesa-vulkan-drivers)
fi
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -ne 0 ]; then
    sudo=sudo
else
    sudo=
fi
export DEBIAN_FRONTEND=noninteractive
if ! grep -rqs 'bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/; then
    echo "deb http://deb.debian.org/debian bookworm-backports main" |
        $sudo tee /etc/apt/sources.list.d/dayflux-backports.list >/dev/null
fi
echo "setup: installing ${missing[*]}" >&2
$sudo apt-get update -qq >/dev/null
$sudo apt-get install -y -qq --no-install-recommends "${packages[@]}" >/dev/null
$sudo apt-get install -y -qq --no-install-recommends -t bookworm-backports "${backports[@]}" >/dev/null
