#!/usr/bin/env bash
# Makes the RADIANCE references of test/tools/rtrace_test.cpp from RADIANCE 5.4a's own gensky,
# oconv and rtrace (NREL/Radiance @2fcca99a, built outside this repository), on the tutorial room
# (test/data/scene/models/room) under sky_df.rad:
#   df_converged.txt  the sensors' irradiance, -ab 2 -aa 0 -ad 65536 -lw 1e-7 (the answer)
#   df_2048.txt       -ab 2 -aa 0 -ad 2048 -lw 2e-5 (its error: RADIANCE's noise at 2048)
#   df_honeybee.txt   honeybee's -ab 2 -aa 0.1 -ad 2048 -ar 64 -lw 2e-5 (the cache's error)
#   view_values.txt   -ov -ab 2 -aa 0 -ad 256 of sphere_rays.txt (400 view rays)
#   view_outputs.txt  -odwWlLpNnsmM of view_rays.txt; sensor_outputs.txt the same with -I
#   sky_values.txt    the radiance of gendaylit's colour (-C) and clear skies along sky_rays.txt
# usage: PATH=/path/to/radiance/bin:$PATH RAYPATH=.:/path/to/radiance/lib make_references.sh
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
room=$here/../scene/models/room
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$room"
oconv materials.rad room.rad objects/Glazing.rad "$here/sky_df.rad" > "$tmp/df.oct"
points=$here/../rcontrib/points.txt
rtrace -h -I -ab 2 -aa 0 -ad 65536 -lw 1e-7 "$tmp/df.oct" < "$points" > "$here/df_converged.txt"
rtrace -h -I -ab 2 -aa 0 -ad 2048 -lw 2e-5 "$tmp/df.oct" < "$points" > "$here/df_2048.txt"
rtrace -h -I -ab 2 -aa 0.1 -ad 2048 -ar 64 -lw 2e-5 "$tmp/df.oct" < "$points" \
    > "$here/df_honeybee.txt"
rtrace -h -ab 2 -aa 0 -ad 256 -ov "$tmp/df.oct" < "$here/sphere_rays.txt" > "$here/view_values.txt"
rtrace -h -ab 1 -aa 0 -ad 16 -odwWlLpNnsmM "$tmp/df.oct" < "$here/view_rays.txt" \
    > "$here/view_outputs.txt" 2> /dev/null
rtrace -h -I -ab 1 -aa 0 -ad 16 -odwWlLpNnsmM "$tmp/df.oct" < "$here/sensor_rays.txt" \
    > "$here/sensor_outputs.txt" 2> /dev/null
# sky_values.txt: -ov -ab 0 of sky_rays.txt toward gendaylit's colour sky (-C) and its clear one
for colour in "-C" ""; do
    gendaylit 6 21 12 -a 40 -o 80 -m 75 -W 800 80 $colour > "$tmp/sky.rad"
    printf 'skyfunc glow sky_glow 0 0 4 1 1 1 0\nsky_glow source sky 0 0 4 0 0 1 180\n' \
        >> "$tmp/sky.rad"
    oconv "$tmp/sky.rad" > "$tmp/sky.oct"
    rtrace -h -ab 0 -ov "$tmp/sky.oct" < "$here/sky_rays.txt"
done > "$here/sky_values.txt"
