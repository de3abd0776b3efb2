#!/usr/bin/env bash
# The README's test command: set up, build, and run the whole test suite.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/tools/build.sh"
cd "$root/build"
# The Vulkan tests run on lavapipe, whose LLVM spends over a minute optimising each shader
# variant; unoptimised, a variant compiles in under half that and runs about a quarter slower,
# which the tests' small runs do not feel. (Real GPUs ignore this.)
export GALLIVM_PERF=${GALLIVM_PERF:-nopt}
ctest --output-on-failure -j"$(nproc)"
