#!/usr/bin/env bash
# -target_error against fixed -ad (issue 45): the tutorial room's daylight coefficients for a
# uniform sky (one bin, rcontrib-gpu -I+ -ab 2), 1600 sensors on a 0.15 m grid at 0.75 m. For each
# setting, run with SEEDS seeds, the mean wall time and the sensors' relative errors against the
# converged answer (-ad 131072 -lw 1e-7): the 95th percentile of all runs' errors, their rms and
# worst, the 95th percentile over sensors of a sensor's rms error over the seeds (the error a
# sensor has, not one draw of it), and with -target_error the share of errors within twice the
# sensor's estimate.
# usage: bench/target_error_speed_error.sh   environment: BUILD (build), SEEDS (4), THREADS (2),
# ANSWER (a file keeping the converged answer between runs), FIXED (the -ad settings; "" for none)
# writes also bench/results/target_error_calibration.csv and docs/target_error_calibration.svg
# writes bench/results/target_error_speed_error.csv
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
bin=$root/${BUILD:-build}/bin
seeds=${SEEDS:-4}
threads=${THREADS:-2}
csv=$here/results/target_error_speed_error.csv
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$root/test/data/scene/models/room"
scene="-m skyglow materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad"
awk 'BEGIN { for (x = 0.075; x < 6.096; x += 0.15) for (y = 0.075; y < 6.096; y += 0.15)
                 print x, y, 0.75, 0, 0, 1 }' > "$tmp/grid.pts"
if [ -n "${ANSWER:-}" ] && [ -s "$ANSWER" ]; then
    cp "$ANSWER" "$tmp/answer.txt"
else
    # shellcheck disable=SC2086
    "$bin/rcontrib-gpu" -h -I+ -ab 2 -ad 131072 -lw 1e-7 -n "$threads" $scene < "$tmp/grid.pts" \
        > "$tmp/answer.txt"
    [ -n "${ANSWER:-}" ] && cp "$tmp/answer.txt" "$ANSWER"
fi
timed() {  # options: each seed's run, timed; out/report.$seed.txt; prints the mean seconds
    local total=0 t seed
    for seed in $(seq 1 "$seeds"); do
        rm -f "$tmp/report.txt"
        # shellcheck disable=SC2086
        /usr/bin/time -f "%e" -o "$tmp/t" "$bin/rcontrib-gpu" -h -I+ -ab 2 -lw 1e-5 \
            -n "$threads" -seed "$seed" $1 $scene < "$tmp/grid.pts" > "$tmp/out.$seed.txt" \
            2> /dev/null
        [ -s "$tmp/report.txt" ] && mv "$tmp/report.txt" "$tmp/report.$seed.txt"
        t=$(tail -n 1 "$tmp/t")
        total=$(awk -v a="$total" -v b="$t" 'BEGIN { print a + b }')
    done
    awk -v a="$total" -v n="$seeds" 'BEGIN { printf "%.2f", a / n }'
}
errors() {  # the errors of the seeds' runs against the answer: p95 of all |errors|, rms, the
            # worst; the p95 over sensors of a sensor's rms error over the seeds; the share
            # within twice the estimate (with -target_error)
    local seed
    for seed in $(seq 1 "$seeds"); do
        paste "$tmp/out.$seed.txt" "$tmp/answer.txt" | awk '{ r = $1 / $4 - 1; print NR, r }'
    done > "$tmp/e.txt"
    awk '{ print ($2 < 0 ? -$2 : $2) }' "$tmp/e.txt" | sort -g \
        | awk '{ e[NR] = $1; q += $1 * $1 }
               END { printf "%.4f,%.4f,%.4f", e[int(0.95 * NR)], sqrt(q / NR), e[NR] }'
    awk '{ q[$1] += $2 * $2; n[$1]++ } END { for (s in q) print sqrt(q[s] / n[s]) }' \
        "$tmp/e.txt" | sort -g | awk '{ e[NR] = $1 } END { printf ",%.4f", e[int(0.95 * NR)] }'
    if [ -s "$tmp/report.1.txt" ]; then
        for seed in $(seq 1 "$seeds"); do
            paste <(tail -n +2 "$tmp/report.$seed.txt") \
                <(paste "$tmp/out.$seed.txt" "$tmp/answer.txt" | awk '{ print $1 / $4 - 1 }')
        done > "$tmp/pairs.txt"
        awk '{ n++; if ($4 <= 2 * $3 && -$4 <= 2 * $3) k++ } END { printf ",%.2f", k / n }' \
            "$tmp/pairs.txt"
        rm -f "$tmp"/report.*.txt
    else
        printf ","
    fi
}
echo "setting,seconds,p95_error,rms_error,worst_error,p95_sensor_rms_error,within_2x_estimate" \
    | tee "$csv"
for ad in ${FIXED-1024 2048 4096 8192 16384}; do
    t=$(timed "-ad $ad")
    echo "-ad $ad,$t,$(errors)" | tee -a "$csv"
done
for te in 0.08 0.05 0.03 0.02; do
    t=$(timed "-ad 32768 -target_error $te -target_report $tmp/report.txt")
    echo "-target_error $te (cap 32768),$t,$(errors)" | tee -a "$csv"
    if [ "$te" = 0.03 ]; then  # the calibration plot's points: estimate, measured error
        { echo "estimate,measured"; awk '{ print $3 "," $4 }' "$tmp/pairs.txt"; } \
            > "$here/results/target_error_calibration.csv"
        python3 "$here/plot_calibration.py" "$here/results/target_error_calibration.csv" \
            "$root/docs/target_error_calibration.svg" \
            "-target_error 0.03, 1681 sensors x $seeds seeds"
    fi
done
