#!/usr/bin/env bash
# Issue 24's measure: the CPU integrator's efficiency, (rays a second of the run) / (rays a
# second of the same rays replayed through the caster alone), bench/ray_replay_bench.cpp, for
# the tutorial room's V and DC (100 sensors) and the reference office's DC (1425 sensors).
# Each case: the run and the replay three times in turns, the fastest of each kept.
# usage: bench/cpu_efficiency.sh   environment: THREADS (all cores), AD (4096), BUILD (build)
# writes bench/results/cpu_efficiency.csv
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
bin=$root/${BUILD:-build}/bench/ray_replay_bench
[ -x "$bin" ] || { echo "build $bin first (DAYFLUX_BENCH=ON)" >&2; exit 1; }
export RAYPATH=$root/lib
threads=${THREADS:-$(nproc)}
ad=${AD:-4096}
room=$root/test/data/scene/models/room
pts=$root/test/data/rcontrib/points.txt
csv=$here/results/cpu_efficiency.csv
office=${OFFICE:-/tmp/dayflux-efficiency-office}
make -s --no-print-directory -C "$root/examples/reference-office" BIN="$root/${BUILD:-build}/bin" \
    OUT="$office" "$office/model/sensors.pts" 2> /dev/null
{
    echo "case,threads,ad,sensors,closest_rays,shadow_rays,run_s,run_mrays_s,replayed_rays,replay_s,replay_mrays_s,efficiency"
    line=$(cd "$room" && "$bin" -n "$threads" -I+ -ab 4 -ad "$ad" -lw 2e-4 -faf -f klems_full.cal \
        -b 'kbin(0,1,0,0,0,1)' -bn Nkbins -m Glazing materials.rad room.rad \
        objects/GlazingVmtx.rad < "$pts" | tail -n 1)
    echo "room V,$threads,$ad,$line"
    line=$(cd "$room" && "$bin" -n "$threads" -I+ -ab 4 -ad "$ad" -lw 1e-4 -faf -e MF:1 \
        -f reinhart.cal -b rbin -bn Nrbins -m skyglow -m groundglow materials.rad room.rad \
        objects/Glazing.rad skyDomes/skyglow.rad < "$pts" | tail -n 1)
    echo "room DC,$threads,$ad,$line"
    m=$office/model
    line=$("$bin" -record_every 10 -n "$threads" -I+ -ab 6 -ad "$ad" -lw 5e-5 -faf -e MF:1 \
        -f reinhart.cal -b rbin -bn Nrbins -m skyglow "$m/materials.rad" "$m/office.rad" \
        "$m/glass.rad" "$m/sky.rad" < "$m/sensors.pts" | tail -n 1)
    echo "office DC,$threads,$ad,$line"
} | tee "$csv"
