#!/usr/bin/env bash
# The three methods on the reference office (issue 23): each matrix made on its own and timed,
# then each method's sDA300/50% and ASE1000,250 (examples/reference-office, METHOD=dc, 3phase,
# 5phase). Results: bench/results/methods_office.csv (step, seconds) and the metrics lines.
# usage: bench/methods_office.sh [make settings: OFFICES=2 AD=... BACKEND=vulkan ...]
# environment: OUT (/tmp/dayflux-methods), BUILD (build), LABEL (a suffix for the results file)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
out=${OUT:-/tmp/dayflux-methods}
example=$root/examples/reference-office
bin=$root/${BUILD:-build}/bin
results=$here/results/methods_office${LABEL:+_$LABEL}.csv
mk() { make -s --no-print-directory -C "$example" BIN="$bin" OUT="$out" "$@"; }
mkdir -p "$out"
mk "$@" METHOD=5phase "$out/model/sensors.pts" "$out/weather.wea" "$out/clear.xml" 2> /dev/null
echo "step,seconds,settings" > "$results.tmp"
for step in dc.mtx cds.mtx v.mtx d.mtx vd.mtx dd.mtx sky.smx skyd.smx total.ill direct.ill \
    total3.ill direct3.ill total5.ill; do
    start=$(date +%s.%N)
    mk "$@" METHOD=5phase "$out/$step" 2> /dev/null
    end=$(date +%s.%N)
    awk -v s="$start" -v e="$end" -v n="$step" -v a="$*" 'BEGIN { printf "%s,%.2f,%s\n", n, e - s, a }' \
        >> "$results.tmp"
done
mv "$results.tmp" "$results"
cat "$results"
for method in dc 3phase 5phase; do
    rm -f "$out/metrics.txt"
    mk "$@" METHOD=$method "$out/metrics.txt" 2> /dev/null
    echo "$method: $(tail -n 1 "$out/metrics.txt")"
done
