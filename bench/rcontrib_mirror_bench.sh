#!/usr/bin/env bash
# Sources seen in mirrors (RADIANCE's virtual sources, -dr), beside RADIANCE's rcontrib:
#   fins  five-phase sun coefficients (C_ds) of the tutorial room's black model with its glass
#         window and two exterior mirror fins, 100 sensors, 5185 Reinhart MF:6 suns:
#         -I+ -ab 1 -ad 256 -lw 1e-3 -dc 1 -dt 0 -dj 0 -faf -e MF:6 -f reinhart.cal -b rbin
#         -bn Nrbins -m solar; deterministic, so the check is the matrices' largest difference
#   box   four mirror fins facing in, around a white floor, the same 5185 suns, 200 sensors
#         facing down: -I+ -ab 1 -ad 64 -faf -m solar (many images off a non-black surface)
# each at -dr 3 (rcontrib's default) and -dr 0; times are wall seconds of one run (both
# programs on all cores; RADIANCE with -n nproc, on an octree of the same files).
# usage: bench/rcontrib_mirror_bench.sh   environment: OURS, RADIANCE_BIN (/opt/radiance/bin)
# writes bench/results/rcontrib_mirror.csv
set -euo pipefail
source "$(dirname "$0")/rcontrib_common.sh" rcontrib_mirror "case,program,dr,wall_s,check"

cp -r "$ROOM"/* "$tmp"/
cp "$root/test/data/rcontrib/suns_m6.rad" "$tmp/"
sed -n '/^void glass Glazing/,+3p' "$ROOM/materials.rad" > "$tmp/glazing_material.rad"
cat > "$tmp/fins.rad" <<'RAD'
void mirror finmirror 0 0 3 .9 .9 .9
finmirror polygon fin_west 0 0 12  1 -1.2 0.9  1 -0.2 0.9  1 -0.2 2.5  1 -1.2 2.5
finmirror polygon fin_east 0 0 12  5 -1.2 0.9  5 -1.2 2.5  5 -0.2 2.5  5 -0.2 0.9
RAD
{
    echo "void plastic white 0 0 5 .5 .5 .5 0 0"
    echo "white polygon floor 0 0 12 -20 -20 0 20 -20 0 20 20 0 -20 20 0"
    echo "void mirror silver 0 0 3 .9 .9 .9"
    echo "silver polygon f1 0 0 12 2 -1 2 2 1 2 2 1 0 2 -1 0"
    echo "silver polygon f2 0 0 12 -2 1 0 -2 1 2 -2 -1 2 -2 -1 0"
    echo "silver polygon f3 0 0 12 1 2 0 1 2 2 -1 2 2 -1 2 0"
    echo "silver polygon f4 0 0 12 -1 -2 2 1 -2 2 1 -2 0 -1 -2 0"
} > "$tmp/box.rad"
python3 -c "
for i in range(200): print(-1.5 + 3 * (i % 20) / 19, -1.5 + 3 * (i // 20) / 9, 1, 0, 0, -1)" \
    > "$tmp/box_points.txt"

fins_scene="materialBlack.rad glazing_material.rad roomBlack.rad objects/Glazing.rad fins.rad suns_m6.rad"
fins_args="-I+ -ab 1 -ad 256 -lw 1e-3 -dc 1 -dt 0 -dj 0 -faf -e MF:6 -f reinhart.cal -b rbin -bn Nrbins -m solar"
box_scene="suns_m6.rad box.rad"
box_args="-I+ -ab 1 -ad 64 -faf -m solar"
export RAYPATH=.:$root/lib:/opt/radiance/lib PATH=$RADIANCE_BIN:$PATH
timed() {  # output points command... ; prints wall seconds
    (cd "$tmp" && /usr/bin/time -f "%e" -o "$tmp/time" "${@:3}" < "$2" > "$1")
    cat "$tmp/time"
}
have_radiance=0
[ -x "$RADIANCE_BIN/rcontrib" ] && [ -x "$RADIANCE_BIN/oconv" ] && have_radiance=1
if [ $have_radiance = 1 ]; then
    (cd "$tmp" && oconv $fins_scene > fins.oct && oconv $box_scene > box.oct)
fi
for dr in 3 0; do
    t=$(timed "$tmp/fins_ours_$dr" "$root/test/data/rcontrib/points.txt" "$OURS" -dr $dr $fins_args $fins_scene)
    echo "fins,dayflux,$dr,$t," | tee -a "$csv"
    t=$(timed /dev/null "$tmp/box_points.txt" "$OURS" -dr $dr $box_args $box_scene)
    echo "box,dayflux,$dr,$t," | tee -a "$csv"
    [ $have_radiance = 1 ] || continue
    t=$(timed "$tmp/fins_rad_$dr" "$root/test/data/rcontrib/points.txt" rcontrib -n "$NPROC" -dr $dr $fins_args fins.oct)
    check=$(python3 "$root/../shared/tools/mtxcmp.py" "$tmp/fins_rad_$dr" "$tmp/fins_ours_$dr" | tr ',' ';')
    echo "fins,radiance,$dr,$t,$check" | tee -a "$csv"
    t=$(timed /dev/null "$tmp/box_points.txt" rcontrib -n "$NPROC" -dr $dr $box_args box.oct)
    echo "box,radiance,$dr,$t," | tee -a "$csv"
done
