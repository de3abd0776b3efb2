#!/usr/bin/env bash
# Direct-sun coefficients with one modifier per sun, beside RADIANCE's rcontrib: the tutorial
# room (glass window), 100 sensors, the 5185 Reinhart MF:6 suns each a `light` of its own
# named in a modifier file, as direct-sun recipes run it (shared/spec/workflows.md):
#   -aa 0.0 -I -faf -ab 0 -dc 1.0 -dt 0.0 -dj 0.0 -dr 0 -V+ -y 100 -M suns.mod
# Deterministic, so the check is the matrices' largest difference. Times are wall seconds and
# peak memory of one run (both programs on all cores; RADIANCE with -n nproc, on an octree).
# usage: bench/rcontrib_modifier_file_bench.sh   environment: OURS, RADIANCE_BIN
# writes bench/results/rcontrib_modifier_file.csv
set -euo pipefail
source "$(dirname "$0")/rcontrib_common.sh" rcontrib_modifier_file "program,modifiers,wall_s,max_rss_kb,check"

cp -r "$ROOM"/* "$tmp"/
# Each sun of suns_m6.rad as a light of its own, sol1 ... sol5185, and their names.
awk '$1 == "solar" && $2 == "source" {
         n++; printf "void light sol%d 0 0 3 1e6 1e6 1e6\nsol%d source s%d 0 0 4 %s %s %s %s\n",
                     n, n, n, $7, $8, $9, $10 > "'"$tmp"'/suns.rad"
         print "sol" n > "'"$tmp"'/suns.mod" }' "$root/test/data/rcontrib/suns_m6.rad"
scene="materials.rad room.rad objects/Glazing.rad suns.rad"
args="-aa 0.0 -I -faf -ab 0 -dc 1.0 -dt 0.0 -dj 0.0 -dr 0 -V+ -y 100 -M suns.mod"
export RAYPATH=.:$root/lib:/opt/radiance/lib PATH=$RADIANCE_BIN:$PATH
modifiers=$(wc -l < "$tmp/suns.mod")
timed() {  # output command... ; prints wall seconds and peak kilobytes
    (cd "$tmp" && /usr/bin/time -f "%e,%M" -o "$tmp/time" "${@:2}" < "$PTS" > "$1")
    cat "$tmp/time"
}
t=$(timed "$tmp/ours" "$OURS" $args $scene)
echo "dayflux,$modifiers,$t," | tee -a "$csv"
if [ -x "$RADIANCE_BIN/rcontrib" ] && [ -x "$RADIANCE_BIN/oconv" ]; then
    (cd "$tmp" && oconv $scene > suns.oct)
    t=$(timed "$tmp/rad" rcontrib -n "$NPROC" $args suns.oct)
    check=$(python3 "$root/../shared/tools/mtxcmp.py" "$tmp/rad" "$tmp/ours" | tr ',' ';')
    echo "radiance,$modifiers,$t,$check" | tee -a "$csv"
fi
