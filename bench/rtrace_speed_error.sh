#!/usr/bin/env bash
# rtrace-gpu beside RADIANCE's rtrace (-n 2) on the daylight-factor recipe: the tutorial room
# (test/data/scene/models/room) under test/data/rtrace/sky_df.rad, 1600 sensors on a 0.15 m grid
# at 0.75 m (RADIANCE's is 100 on 0.61 m). For each setting, the wall time (fastest of RUNS) and
# the error against the converged answer: rms and mean relative error over the sensors. The
# answer is ours at -aa 0 -ad 65536 -lw 1e-7 (rtrace_test.cpp checks ours against RADIANCE's
# converged answer on the 100 sensors).
# usage: bench/rtrace_speed_error.sh   environment: BUILD (build), RUNS (3), THREADS (2),
#        RADIANCE (a folder with RADIANCE's rtrace and oconv; unset: ours only; its lib for
#        RAYPATH in RADIANCE_LIB, else $RADIANCE/../lib)
# writes bench/results/rtrace_speed_error.csv
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
bin=$root/${BUILD:-build}/bin
runs=${RUNS:-3}
threads=${THREADS:-2}
csv=$here/results/rtrace_speed_error.csv
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cp -r "$root/test/data/scene/models/room" "$tmp/room"
cp "$root/test/data/rtrace/sky_df.rad" "$tmp/room/"
cd "$tmp/room"
PATH="$bin/../lib/dayflux/radiance/bin:$PATH" oconv -f materials.rad room.rad objects/Glazing.rad \
    sky_df.rad > df.oct
awk 'BEGIN { for (x = 0.075; x < 6.096; x += 0.15) for (y = 0.075; y < 6.096; y += 0.15)
                 print x, y, 0.75, 0, 0, 1 }' > grid.pts
"$bin/rtrace-gpu" -h -I -ab 2 -aa 0 -ad 65536 -lw 1e-7 -n "$threads" df.oct < grid.pts \
    > answer.txt
timed() {  # command: the fastest wall time of $runs; the output in out.txt
    local best="" t
    for _ in $(seq 1 "$runs"); do
        /usr/bin/time -f "%e" -o t.txt bash -c "$1" > out.txt 2> /dev/null
        t=$(tail -n 1 t.txt)
        if [ -z "$best" ] || awk -v a="$t" -v b="$best" 'BEGIN { exit !(a < b) }'; then best=$t; fi
    done
    echo "$best"
}
errors() {  # rms and mean relative error of out.txt against answer.txt
    paste out.txt answer.txt | awk '{ r = $1 / $4 - 1; s += r; q += r * r }
        END { printf "%.4f,%.4f", sqrt(q / NR), s / NR }'
}
settings=("-ab 2 -aa 0 -ad 512 -lw 2e-5" "-ab 2 -aa 0 -ad 2048 -lw 2e-5"
          "-ab 2 -aa 0 -ad 8192 -lw 2e-5" "-ab 2 -aa 0.1 -ad 2048 -ar 64 -lw 2e-5"
          "-ab 2 -aa 0.1 -ad 8192 -ar 256 -lw 2e-5")
echo "program,settings,seconds,rms_error,mean_error" | tee "$csv"
for s in "${settings[@]}"; do
    t=$(timed "'$bin/rtrace-gpu' -h -I $s -n $threads df.oct < grid.pts")
    echo "dayflux,$s,$t,$(errors)" | tee -a "$csv"
    if [ -n "${RADIANCE:-}" ]; then
        t=$(timed "RAYPATH=.:${RADIANCE_LIB:-$RADIANCE/../lib} '$RADIANCE/rtrace' -h -I $s \
                   -n $threads df.oct < grid.pts")
        echo "RADIANCE,$s,$t,$(errors)" | tee -a "$csv"
    fi
done
