#!/usr/bin/env bash
# The flagship example's annual product step (examples/reference-office, step 4:
# dctimestep -of dc.mtx sky.smx | rmtxop -ff -c 47.4 119.9 11.6 -) timed whole and in parts:
# dctimestep alone, rmtxop from a file and from a pipe (cat), each RUNS times (fastest wall,
# its user seconds, largest peak RSS), on the small office's year (1425 sensors x 8760 hours).
# With RADIANCE (a folder holding RADIANCE's dctimestep and rmtxop, built outside this
# repository), the same steps with its programs, in the same run, and whether the outputs' data
# are the same bytes.
# usage: bench/example_products_bench.sh   environment: BUILD (build), RUNS (3),
#        OUT (/tmp/dayflux-example-products: the example's output folder, made if missing),
#        RADIANCE (unset: ours only)
# writes bench/results/example_products.csv
set -euo pipefail
source "$(dirname "$0")/example_common.sh" example_products
"$bin/dctimestep" -of "$out/dc.mtx" "$out/sky.smx" > "$tmp/ill.fmx"
transform="-ff -c 47.4 119.9 11.6"
timed() {  # name command: the fastest of $runs
    local best="" line
    for _ in $(seq 1 "$runs"); do
        /usr/bin/time -f "%e,%U,%S,%M" -o "$tmp/t" bash -c "$2" > /dev/null
        line=$(cat "$tmp/t")
        if [ -z "$best" ] || awk -v a="${line%%,*}" -v b="${best%%,*}" 'BEGIN { exit !(a < b) }'
        then best=$line; fi
    done
    echo "$1,$best" | tee -a "$csv"
}
echo "program,step,wall_s,user_s,sys_s,peak_rss_kb" | tee "$csv"
steps() {  # label folder
    timed "$1,dctimestep alone" "'$2/dctimestep' -of '$out/dc.mtx' '$out/sky.smx' > /dev/null"
    timed "$1,rmtxop from a file" "'$2/rmtxop' $transform '$tmp/ill.fmx' > /dev/null"
    timed "$1,rmtxop from a pipe" "cat '$tmp/ill.fmx' | '$2/rmtxop' $transform - > /dev/null"
    timed "$1,dctimestep | rmtxop" \
        "'$2/dctimestep' -of '$out/dc.mtx' '$out/sky.smx' | '$2/rmtxop' $transform - > /dev/null"
}
steps dayflux "$bin"
if [ -n "${RADIANCE:-}" ]; then
    steps radiance "$RADIANCE"
    data() { python3 -c 'import sys; b = open(sys.argv[1], "rb").read(); sys.stdout.buffer.write(b[b.index(b"\n\n") + 2:])' "$1"; }
    "$RADIANCE/dctimestep" -of "$out/dc.mtx" "$out/sky.smx" > "$tmp/ill_radiance.fmx"
    "$RADIANCE/rmtxop" $transform "$tmp/ill.fmx" > "$tmp/total_radiance.fmx"
    "$bin/rmtxop" $transform "$tmp/ill.fmx" > "$tmp/total.fmx"
    cmp -s <(data "$tmp/ill.fmx") <(data "$tmp/ill_radiance.fmx") &&
        cmp -s <(data "$tmp/total.fmx") <(data "$tmp/total_radiance.fmx") &&
        echo "same data bytes as RADIANCE's (dctimestep and rmtxop)" ||
        echo "DATA DIFFER from RADIANCE's" >&2
fi
