#!/usr/bin/env bash
# -target_error against fixed -ad (issue 45): the tutorial room's daylight coefficients for a
# uniform sky (one bin, rcontrib-gpu -I+ -ab 2), 1600 sensors on a 0.15 m grid at 0.75 m. For each
# setting, the wall time (fastest of RUNS) and the sensors' relative errors against the converged
# answer (-ad 131072 -lw 1e-7): their 95th percentile, rms and worst, and with -target_error the
# share of sensors whose measured error is within twice their estimate.
# usage: bench/target_error_speed_error.sh   environment: BUILD (build), RUNS (3), THREADS (2)
# writes bench/results/target_error_speed_error.csv
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
bin=$root/${BUILD:-build}/bin
runs=${RUNS:-3}
threads=${THREADS:-2}
csv=$here/results/target_error_speed_error.csv
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$root/test/data/scene/models/room"
scene="-m skyglow materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad"
awk 'BEGIN { for (x = 0.075; x < 6.096; x += 0.15) for (y = 0.075; y < 6.096; y += 0.15)
                 print x, y, 0.75, 0, 0, 1 }' > "$tmp/grid.pts"
# shellcheck disable=SC2086
"$bin/rcontrib-gpu" -h -I+ -ab 2 -ad 131072 -lw 1e-7 -n "$threads" $scene < "$tmp/grid.pts" \
    > "$tmp/answer.txt"
timed() {  # options: the fastest wall time of $runs; the output in $tmp/out.txt
    local best="" t
    for _ in $(seq 1 "$runs"); do
        # shellcheck disable=SC2086
        /usr/bin/time -f "%e" -o "$tmp/t" "$bin/rcontrib-gpu" -h -I+ -ab 2 -lw 1e-5 \
            -n "$threads" $1 $scene < "$tmp/grid.pts" > "$tmp/out.txt" 2> /dev/null
        t=$(tail -n 1 "$tmp/t")
        if [ -z "$best" ] || awk -v a="$t" -v b="$best" 'BEGIN { exit !(a < b) }'; then best=$t; fi
    done
    echo "$best"
}
errors() {  # p95, rms and worst relative error of out.txt; honest share from report.txt if any
    paste "$tmp/out.txt" "$tmp/answer.txt" | awk '{ r = $1 / $4 - 1; print (r < 0 ? -r : r) }' \
        > "$tmp/e.txt"
    sort -g "$tmp/e.txt" | awk '{ e[NR] = $1; q += $1 * $1 }
        END { printf "%.4f,%.4f,%.4f", e[int(0.95 * NR)], sqrt(q / NR), e[NR] }'
    if [ -s "$tmp/report.txt" ]; then
        tail -n +2 "$tmp/report.txt" | paste - "$tmp/e.txt" \
            | awk '{ n++; if ($4 <= 2 * $3) k++ } END { printf ",%.2f", k / n }'
    else
        printf ","
    fi
}
echo "setting,seconds,p95_error,rms_error,worst_error,within_2x_estimate" | tee "$csv"
for ad in 1024 2048 4096 8192 16384; do
    rm -f "$tmp/report.txt"
    t=$(timed "-ad $ad")
    echo "-ad $ad,$t,$(errors)" | tee -a "$csv"
done
for te in 0.08 0.05 0.03 0.02; do
    t=$(timed "-ad 32768 -target_error $te -target_report $tmp/report.txt")
    echo "-target_error $te (cap 32768),$t,$(errors)" | tee -a "$csv"
done
