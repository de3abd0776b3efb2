#!/usr/bin/env bash
# The README's test command: set up, build, and run the whole test suite.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/tools/setup.sh" --tests
"$root/tools/build.sh"
cd "$root/build"
# The Vulkan tests run on lavapipe, whose LLVM spends over a minute optimising each shader
# variant; unoptimised, a variant compiles in under half that and runs about a quarter slower,
# which the tests' small runs do not feel. (Real GPUs ignore this.)
export GALLIVM_PERF=${GALLIVM_PERF:-nopt}
# Most of that time is LLVM building the compute shader's coroutine frame, which grows with the
# shader's branches; lavapipe's 4-wide vectors (its default is 8 on AVX machines) halve the
# per-lane branches of its memory accesses and cut each compile by 40 % (docs/benchmarks.md).
export LP_NATIVE_VECTOR_WIDTH=${LP_NATIVE_VECTOR_WIDTH:-128}
ctest --output-on-failure -j"$(nproc)"
