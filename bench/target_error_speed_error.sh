#!/usr/bin/env bash
# -target_error against fixed -ad (issue 45), on one of these cases (CASE):
# - room (default): the tutorial room's daylight coefficients for a uniform sky (one bin,
#   rcontrib-gpu -I+ -ab 2 -lw 1e-5), 1681 sensors on a 0.15 m grid at 0.75 m; converged answer
#   -ad 131072 -lw 1e-7.
# - office: the reference office's daylight coefficients (examples/reference-office, its
#   make_office.py model, -I+ -ab 6, Reinhart MF 1, 146 columns), a quarter of its 1425 sensors,
#   weighed by the New York year's cumulative sky (gendaymtx -A, also -target_sky); -lw 1e-6, not
#   the example's 5e-5, which cuts the paths of -ad above 4096 short (the settings would differ
#   in bias, not only noise); converged answer -ad 65536 -lw 1e-7.
# - blinds: the office with its exterior blinds (make_office.py --blinds, in the daylight
#   coefficients' scene as the example's BLINDS=1 puts them), otherwise as office.
# - v: the office's view matrix V (the three- and five-phase methods' sensors -> window, 145 Klems
#   patches, as Makefile.phases makes it by rfluxmtx-gpu: with BLINDS=1 the blinds are in T, so
#   this is also the five-phase blinds case's V), -ab 6 -lw 1e-6, the sensors' illuminance under a
#   uniform window (every patch 1); converged answer -ad 65536 -lw 1e-7.
# For each setting, run with SEEDS seeds: the mean wall time and the sensors' relative errors
# (of their illuminance under the case's sky) against the converged answer: the 95th percentile
# of all runs' errors, their rms and worst, the 95th percentile over sensors of a sensor's rms
# error over the seeds (the error a sensor has, not one draw of it), and with -target_error the
# share of errors within twice the sensor's estimate.
# usage: bench/target_error_speed_error.sh   environment: CASE (room), BUILD (build), SEEDS (4),
# THREADS (2), ANSWER (a file keeping the converged answer between runs), FIXED (the -ad
# settings; "" for none), TARGETS (the -target_error settings), EXTRA (options added to every
# setting but the converged answer, e.g. "-asub 3"; the CSV's name then ends in them)
# writes bench/results/target_error_speed_error.csv (the room; the other cases
# target_error_<case>.csv); the room also bench/results/target_error_calibration.csv and
# docs/target_error_calibration.svg. Its -target_report files are deleted: for
# bench/target_error_ideal.py, run a setting by hand with -target_report.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
bin=$root/${BUILD:-build}/bin
seeds=${SEEDS:-4}
threads=${THREADS:-2}
case=${CASE:-room}
program=rcontrib-gpu
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
office_settings() {  # the reference office's, for its DC (with or without blinds) and its V
    options="-ab 6 -lw 1e-6 ${EXTRA:-}"
    converged="-ab 6 -ad 65536 -lw 1e-7"
    cap=16384
    fixed=${FIXED-512 1024 2048 4096 8192}
    targets=${TARGETS:-0.1 0.05 0.03 0.02}
    awk 'NR % 4 == 1' model/sensors.pts > "$tmp/grid.pts"
}
case $case in
    room)
        csv=$here/results/target_error_speed_error.csv
        cd "$root/test/data/scene/models/room"
        scene="-m skyglow materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad"
        options="-ab 2 -lw 1e-5 ${EXTRA:-}"
        converged="-ab 2 -ad 131072 -lw 1e-7"
        cap=32768
        fixed=${FIXED-1024 2048 4096 8192 16384}
        targets=${TARGETS:-0.08 0.05 0.03 0.02}
        awk 'BEGIN { for (x = 0.075; x < 6.096; x += 0.15) for (y = 0.075; y < 6.096; y += 0.15)
                         print x, y, 0.75, 0, 0, 1 }' > "$tmp/grid.pts"
        echo 1 > "$tmp/weights.txt"
        sky=""
        ;;
    v)
        csv=$here/results/target_error_v$(tr -d ' ' <<< "${EXTRA:-}" | tr '-' '_').csv
        cd "$tmp"
        python3 "$root/examples/reference-office/make_office.py" --out model > /dev/null
        program=rfluxmtx-gpu
        scene="- model/window.rad model/materials.rad model/office.rad"
        office_settings
        for _ in $(seq 145); do echo 1; done > "$tmp/weights.txt"
        sky=""
        ;;
    office | blinds)
        csv=$here/results/target_error_$case$(tr -d ' ' <<< "${EXTRA:-}" | tr '-' '_').csv
        cd "$tmp"
        python3 "$root/examples/reference-office/make_office.py" --out model \
            $([ "$case" = blinds ] && echo --blinds) > /dev/null
        xzcat "$root"/examples/reference-office/weather/*.epw.xz > weather.epw
        "$bin/epw2wea" weather.epw weather.wea > /dev/null
        "$bin/gendaymtx" -A -m 1 weather.wea 2> /dev/null > cumulative.txt
        "$bin/gendaymtx" -A -of -m 1 weather.wea 2> /dev/null > cumulative.smx
        getinfo_body() { awk 'f && NF == 3 { print 0.265 * $1 + 0.670 * $2 + 0.065 * $3 }
                              /^$/ { f = 1 }' "$1"; }
        getinfo_body cumulative.txt > "$tmp/weights.txt"
        scene="-e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow model/materials.rad
               model/office.rad model/glass.rad model/blinds.rad model/sky.rad"
        office_settings
        sky="-target_sky $tmp/cumulative.smx"
        ;;
    *)
        echo "CASE: room, office, blinds or v" >&2
        exit 2
        ;;
esac
illuminance() {  # rcontrib's ascii records in $1: each one's luminance under the weights
    awk 'NR == FNR { w[NR] = $1; next }
         { s = 0; for (j = 1; 3 * j <= NF; ++j)
               s += (0.265 * $(3 * j - 2) + 0.670 * $(3 * j - 1) + 0.065 * $(3 * j)) * w[j]
           print s }' "$tmp/weights.txt" "$1"
}
if [ -n "${ANSWER:-}" ] && [ -s "$ANSWER" ]; then
    cp "$ANSWER" "$tmp/answer.txt"
else
    # shellcheck disable=SC2086
    "$bin/$program" -h -faa -I+ $converged -n "$threads" $scene < "$tmp/grid.pts" \
        > "$tmp/answer.raw"
    illuminance "$tmp/answer.raw" > "$tmp/answer.txt"
    [ -n "${ANSWER:-}" ] && cp "$tmp/answer.txt" "$ANSWER"
fi
timed() {  # options: each seed's run, timed; out/report.$seed.txt; prints the mean seconds
    local total=0 t seed
    for seed in $(seq 1 "$seeds"); do
        rm -f "$tmp/report.txt"
        # shellcheck disable=SC2086
        /usr/bin/time -f "%e" -o "$tmp/t" "$bin/$program" -h -faa -I+ $options \
            -n "$threads" -seed "$seed" $1 $scene < "$tmp/grid.pts" > "$tmp/out.raw" 2> /dev/null
        illuminance "$tmp/out.raw" > "$tmp/out.$seed.txt"
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
        paste "$tmp/out.$seed.txt" "$tmp/answer.txt" | awk '{ r = $1 / $2 - 1; print NR, r }'
    done > "$tmp/e.txt"
    awk '{ print ($2 < 0 ? -$2 : $2) }' "$tmp/e.txt" | sort -g \
        | awk '{ e[NR] = $1; q += $1 * $1 }
               END { printf "%.4f,%.4f,%.4f", e[int(0.95 * NR)], sqrt(q / NR), e[NR] }'
    awk '{ q[$1] += $2 * $2; n[$1]++ } END { for (s in q) print sqrt(q[s] / n[s]) }' \
        "$tmp/e.txt" | sort -g | awk '{ e[NR] = $1 } END { printf ",%.4f", e[int(0.95 * NR)] }'
    if [ -s "$tmp/report.1.txt" ]; then
        for seed in $(seq 1 "$seeds"); do
            paste <(tail -n +2 "$tmp/report.$seed.txt") \
                <(paste "$tmp/out.$seed.txt" "$tmp/answer.txt" | awk '{ print $1 / $2 - 1 }')
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
for ad in $fixed; do
    t=$(timed "-ad $ad")
    echo "-ad $ad,$t,$(errors)" | tee -a "$csv"
done
for te in $targets; do
    t=$(timed "-ad $cap -target_error $te $sky -target_report $tmp/report.txt")
    echo "-target_error $te (cap $cap),$t,$(errors)" | tee -a "$csv"
    if [ "$case" = room ] && [ "$te" = 0.03 ]; then  # the calibration plot: estimate, measured
        { echo "estimate,measured"; awk '{ print $3 "," $4 }' "$tmp/pairs.txt"; } \
            > "$here/results/target_error_calibration.csv"
        python3 "$here/plot_calibration.py" "$here/results/target_error_calibration.csv" \
            "$root/docs/target_error_calibration.svg" \
            "-target_error 0.03, 1681 sensors x $seeds seeds"
    fi
done
