#!/usr/bin/env bash
# Speed against error of DAYSIM's diffuse run on the reference office (1425 sensors, 148
# coefficients, -ab 5: DAYSIM's usual settings), issue 22: rtrace_dc-gpu without and with the
# sensor cache (-aa), DAYSIM's rtrace_dc (its ambient cache; one process, as gen_dc runs it) and
# RADIANCE's rcontrib -n 2 with lib/daysim.cal's bins, each against a converged unbiased run
# (rtrace_dc-gpu -aa 0 -ad 16384), so a cache's bias counts.
# usage: bench/daysim_office.sh; environment: OUT (/tmp/dayflux-daysim), BUILD (build),
#   DAYSIM_BIN (a folder with DAYSIM's rtrace_dc and oconv; skipped if unset), RADIANCE_BIN
#   (RADIANCE's rcontrib and oconv; skipped if unset), ADS ("250 500 1000 2000"), LABEL.
# Results: bench/results/daysim_office${LABEL:+_$LABEL}.csv (program, settings, seconds, errors).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
out=${OUT:-/tmp/dayflux-daysim}
bin=$root/${BUILD:-build}/bin
ads=${ADS:-250 500 1000 2000}
results=$here/results/daysim_office${LABEL:+_$LABEL}.csv
make -s --no-print-directory -C "$root/examples/daysim" BIN="$bin" OUT="$out" "$out/office.hea" 2> /dev/null
cd "$out"
mkdir -p bench tmp
printf 'void glow sky\n0\n0\n4 1000 1000 1000 0\n\nsky source himmel\n0\n0\n4 0 0 1 360\n' > bench/sky.rad
scene="bench/sky.rad model/materials.rad model/geometry.rad"
common="-h -I+ -ab 5 -dj 0 -dr 2 -ds 0.2 -ss 1 -st 0.15"
timed() {  # name settings command...: runs, prints seconds
    local start end
    start=$(date +%s.%N)
    "${@:3}" < model/sensors.pts > "bench/$1.dc"
    end=$(date +%s.%N)
    echo "$1,$2,$(echo "$end - $start" | bc)" >> bench/times.csv
}
echo "name,settings,seconds" > bench/times.csv
if [ ! -f bench/reference.dc ]; then
    echo "reference: -aa 0 -ad 16384 (a few minutes)" >&2
    "$bin/rtrace_dc-gpu" $common -oc -aa 0 -ad 16384 -lw 2.5e-7 -lr -6 -seed 9 -L 1000 -N 148 -Dd \
        $scene < model/sensors.pts > bench/reference.dc
fi
for ad in $ads; do
    lw=$(echo "0.004 / $ad" | bc -l)
    timed "ours_ad$ad" "-aa 0 -ad $ad -lw 0.004/ad" "$bin/rtrace_dc-gpu" $common -oc -aa 0 -ad "$ad" \
        -lw "$lw" -lr -6 -seed 1 -L 1000 -N 148 -Dd $scene
    for aa in 0.1 0.2; do
        timed "ours_aa${aa}_ad$ad" "-aa $aa -ar 300 -ad $ad" "$bin/rtrace_dc-gpu" $common -oc -aa "$aa" \
            -ar 300 -ad "$ad" -lw 0.004 -lr 6 -seed 1 -L 1000 -N 148 -Dd $scene
    done
done
if [ -n "${DAYSIM_BIN:-}" ]; then
    "$DAYSIM_BIN/oconv" $scene > bench/daysim.oct
    for ad in 1000 4000; do
        timed "daysim_ad$ad" "-aa 0.1 -ar 300 -as 20 -ad $ad (1 process)" "$DAYSIM_BIN/rtrace_dc" \
            $common -oc -aa 0.1 -ar 300 -as 20 -ad "$ad" -lw 0.004 -lr 6 -L 1000 -N 148 -Dd bench/daysim.oct
    done
fi
if [ -n "${RADIANCE_BIN:-}" ]; then
    "$RADIANCE_BIN/oconv" $scene > bench/radiance.oct
    for ad in 1000 4000; do
        lw=$(echo "0.004 / $ad" | bc -l)
        timed "rcontrib_ad$ad" "-n 2 -ad $ad -lw 0.004/ad" env RAYPATH=.:$root/lib \
            "$RADIANCE_BIN/rcontrib" -n 2 $common -ad "$ad" -lw "$lw" -lr -6 -f daysim.cal \
            -b dspatch -bn Ndsbins -m sky bench/radiance.oct
    done
fi
files=()
for f in bench/*.dc; do
    case $f in bench/reference.dc) ;; bench/rcontrib*) files+=("$f:rgb") ;; *) files+=("$f") ;; esac
done
python3 "$here/daysim_error.py" bench/reference.dc "${files[@]}" > bench/errors.csv
{
    echo "name,settings,seconds,sensor_rms,sensor_mean,entry_rms"
    tail -n +2 bench/times.csv | sort | while IFS=, read -r name settings seconds; do
        echo "$name,$settings,$seconds,$(grep "^bench/$name.dc," bench/errors.csv | cut -d, -f2-)"
    done
} > "$results"
column -s, -t "$results"
