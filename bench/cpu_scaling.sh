#!/usr/bin/env bash
# Issue 24's scaling with cores: rcontrib-gpu on Embree for the cases of bench/cpu_efficiency.sh
# (the tutorial room's V and DC, 100 sensors; the reference office's DC, 1425 sensors) at each
# thread count, best wall time of REPEAT runs, and the speed-up and efficiency against one thread.
# The same command on a larger machine gives its rows (THREADS="1 2 4 8 16").
# usage: bench/cpu_scaling.sh   environment: THREADS ("1 2"), REPEAT (2), AD (4096), OURS
# writes bench/results/cpu_scaling.csv
set -euo pipefail
source "$(dirname "$0")/rcontrib_common.sh" cpu_scaling \
    "case,threads,sensors,best_s,speedup,efficiency,cpu"
threads_list=${THREADS:-"1 2"}
repeat=${REPEAT:-2}
ad=${AD:-4096}
export RAYPATH=$root/lib
office=${OFFICE:-/tmp/dayflux-efficiency-office}
make -s --no-print-directory -C "$root/examples/reference-office" \
    BIN="$(dirname "$OURS")" OUT="$office" "$office/model/sensors.pts" 2> /dev/null
m=$office/model
cpu=$(lscpu | sed -n 's/^Model name: *//p' | head -1 | tr ',' ' ')
declare -A ARGS=(
    [room V]="-ab 4 -lw 2e-4 -f klems_full.cal -b kbin(0,1,0,0,0,1) -bn Nkbins -m Glazing
              materials.rad room.rad objects/GlazingVmtx.rad"
    [room DC]="-ab 4 -lw 1e-4 -e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow -m groundglow
               materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad"
    [office DC]="-ab 6 -lw 5e-5 -e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow
                 $m/materials.rad $m/office.rad $m/glass.rad $m/sky.rad"
)
for name in "room V" "room DC" "office DC"; do
    dir=$ROOM pts=$PTS
    [ "$name" = "office DC" ] && dir=$m pts=$m/sensors.pts
    sensors=$(grep -c . "$pts")
    one=""
    for n in $threads_list; do
        best=""
        for ((k = 0; k < repeat; ++k)); do
            # shellcheck disable=SC2086 # the arguments are words
            s=$(cd "$dir" && /usr/bin/time -f "%e" "$OURS" -backend embree -n "$n" -I+ -ad "$ad" \
                -faf ${ARGS[$name]} < "$pts" 2>&1 > /dev/null | tail -n 1)
            best=$(awk -v a="${best:-1e30}" -v b="$s" 'BEGIN { print (b < a ? b : a) }')
        done
        [ -z "$one" ] && one=$best one_n=$n
        awk -v c="$name" -v n="$n" -v s="$sensors" -v b="$best" -v o="$one" -v on="$one_n" \
            -v cpu="$cpu" 'BEGIN { su = o / b; printf "%s,%d,%d,%.2f,%.2f,%.2f,%s\n",
                c, n, s, b, su, su / (n / on), cpu }' | tee -a "$csv"
    done
done
