#!/usr/bin/env bash
# Installs what is missing (tools/setup.sh) and builds dayflux in build/ (Release).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/tools/setup.sh"
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$root/build" -- -j"$(nproc)" | grep -v '^\[' || true
test -x "$root/build/bin/dctimestep"
