#!/usr/bin/env bash
# Fuzzing: builds the fuzz configuration (clang, DAYFLUX_FUZZ=ON: ASan + UBSan + libFuzzer, in
# build-fuzz/) and runs each fuzz target (fuzz/README.md) for FUZZ_SECONDS with its seed corpus
# and dictionary, one after the other. libFuzzer runs in fork mode, so a crash, leak, timeout or
# out-of-memory is saved and fuzzing goes on; each target's findings go to OUT/<target>/
# (crash-*, leak-*, timeout-*, oom-*), with its log in OUT/<target>.log, and the new inputs that
# reached new code to OUT/<target>/corpus (merge the useful ones into fuzz/corpus by hand).
# At the end, each finding is run once more and summarised with the first frame of ours in its
# stack: OUT/summary.txt.
# usage: bench/fuzz.sh [TARGET...]   (default: all of them)
# environment: FUZZ_SECONDS (1800 per target), OUT (/tmp/dayflux-fuzz), BUILD (build-fuzz),
#   JOBS (build jobs, 2), NICE (15: the runs leave the machine to others first),
#   FUZZ_ARGS (more libFuzzer options, e.g. "-max_len=65536")
# To reproduce a finding: build-fuzz/fuzz/<target>_fuzzer OUT/<target>/crash-...
# To minimise one: build-fuzz/fuzz/<target>_fuzzer -minimize_crash=1 -runs=20000 \
#   -exact_artifact_path=min.bin OUT/<target>/crash-...
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
FUZZ_SECONDS=${FUZZ_SECONDS:-1800}
OUT=${OUT:-/tmp/dayflux-fuzz}
BUILD=${BUILD:-$root/build-fuzz}
JOBS=${JOBS:-2}
NICE=${NICE:-15}
all="matrix scene octree mesh calcomp weather bsdf_xml annotations daysim engine"
targets=${*:-$all}
limits="-rss_limit_mb=2048 -malloc_limit_mb=1024 -timeout=10"
# UBSan stops at the first report (-fno-sanitize-recover) and says where it was.
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}

command -v clang++ > /dev/null || { echo "needs clang (apt-get install clang)" >&2; exit 1; }
CC=clang CXX=clang++ nice -n "$NICE" cmake -S "$root" -B "$BUILD" -G Ninja \
    -DCMAKE_BUILD_TYPE=Release -DDAYFLUX_FUZZ=ON -DDAYFLUX_VULKAN=OFF -DDAYFLUX_TESTS=OFF \
    -DDAYFLUX_BENCH=OFF > /dev/null
nice -n "$NICE" cmake --build "$BUILD" -j "$JOBS" --target fuzzers

mkdir -p "$OUT"
for t in $targets; do
    bin=$BUILD/fuzz/${t}_fuzzer
    [ -x "$bin" ] || { echo "no fuzz target '$t' (one of: $all)" >&2; exit 1; }
    mkdir -p "$OUT/$t/corpus"
    dict=()
    [ -f "$root/fuzz/dict/$t.dict" ] && dict=("-dict=$root/fuzz/dict/$t.dict")
    echo "== $t: ${FUZZ_SECONDS}s, findings in $OUT/$t/"
    # shellcheck disable=SC2086
    nice -n "$NICE" "$bin" -fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1 \
        -max_total_time="$FUZZ_SECONDS" $limits -artifact_prefix="$OUT/$t/" "${dict[@]}" \
        ${FUZZ_ARGS:-} "$OUT/$t/corpus" "$root/fuzz/corpus/$t" > "$OUT/$t.log" 2>&1 || true
    tail -n 2 "$OUT/$t.log"
done

# One line per finding: target, file, what the sanitizer or libFuzzer said, and the first frame
# in src/ (or fuzz/) of the stack, so that repeats of one bug sort together.
summary=$OUT/summary.txt
: > "$summary"
for t in $targets; do
    for f in "$OUT/$t"/crash-* "$OUT/$t"/leak-* "$OUT/$t"/timeout-* "$OUT/$t"/oom-*; do
        [ -f "$f" ] || continue
        # shellcheck disable=SC2086
        log=$(nice -n "$NICE" "$BUILD/fuzz/${t}_fuzzer" $limits "$f" 2>&1 || true)
        what=$(grep -m1 -oE "ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer): [^(]*|runtime error: .*|terminate called .*|ALARM: .*|out-of-memory .*" <<< "$log" || echo "?")
        frame=$(grep -m1 -oE "(src|fuzz)/[a-z_/]+\.(cpp|h|inl):[0-9]+" <<< "$log" || echo "?")
        printf "%-12s %-40s %-30s %s\n" "$t" "$(basename "$f")" "$frame" "$what" >> "$summary"
    done
done
sort -k1,1 -k3,3 "$summary" -o "$summary"
echo "== findings ($summary):"
cat "$summary"
