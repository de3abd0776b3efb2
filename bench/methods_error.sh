#!/usr/bin/env bash
# Each matrix of the three methods (issue 23) against a converged reference: the example's DC,
# V, D, V_d and D_d at its settings (SEED 1), and the same matrices at REF_AD / REF_LW (D: REF_C
# sender samples) with two other seeds, whose mean is the reference; the error is the relative
# RMS over all entries (bench/rcontrib_error.py), and the reference's own is half the two
# seeds' difference (the mean of two halves the variance of one).
# Results: bench/results/methods_error.csv.
# usage: bench/methods_error.sh [make settings: OFFICES=2 ...]
# environment: OUT (/tmp/dayflux-methods-error), BUILD (build), REF_AD (32768), REF_LW (1e-6),
#   REF_C (16000)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
out=${OUT:-/tmp/dayflux-methods-error}
example=$root/examples/reference-office
bin=$root/${BUILD:-build}/bin
ref_ad=${REF_AD:-32768} ref_lw=${REF_LW:-1e-6} ref_c=${REF_C:-16000}
results=$here/results/methods_error.csv
mk() { make -s --no-print-directory -C "$example" BIN="$bin" "$@"; }
matrices="dc.mtx v.mtx d.mtx vd.mtx dd.mtx"
timed() {  # dir, make arguments...: builds the matrices, one time each
    local dir=$1
    shift
    for m in $matrices; do
        local start=$(date +%s.%N)
        mk OUT="$dir" METHOD=5phase "$@" "$dir/$m" 2> /dev/null
        awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN { printf "%.1f\n", e - s }' > "$dir/$m.s"
    done
}
timed "$out/example" "$@"
for seed in 11 12; do
    timed "$out/ref$seed" "$@" SEED=$seed AD=$ref_ad LW=$ref_lw \
        D_OPTS="-ab 2 -ad 4096 -lw 1e-4 -c $ref_c" DD_OPTS="-ab 0 -c $ref_c"
done
echo "matrix,example_s,reference_s,error,reference_error" > "$results.tmp"
for m in $matrices; do
    python3 "$here/rcontrib_error.py" --mean "$out/$m.ref" "$out/ref11/$m" "$out/ref12/$m"
    err=$(python3 "$here/rcontrib_error.py" "$out/example/$m" "$out/$m.ref")
    ref_err=$(python3 "$here/rcontrib_error.py" "$out/ref11/$m" "$out/ref12/$m" |
        awk '{ printf "%.4g\n", $1 / 2 }')
    echo "$m,$(cat "$out/example/$m.s"),$(cat "$out/ref11/$m.s"),$err,$ref_err" >> "$results.tmp"
done
mv "$results.tmp" "$results"
cat "$results"
