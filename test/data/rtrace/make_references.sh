#!/usr/bin/env bash
# Makes the RADIANCE references of test/tools/rtrace_test.cpp from RADIANCE 5.4a's own gensky,
# oconv and rtrace (NREL/Radiance @2fcca99a, built outside this repository), on the tutorial room
# (test/data/scene/models/room) under sky_df.rad:
#   df_converged.txt  the sensors' irradiance, -ab 2 -aa 0 -ad 65536 -lw 1e-7 (the answer)
#   df_2048.txt       -ab 2 -aa 0 -ad 2048 -lw 2e-5 (its error: RADIANCE's noise at 2048)
#   df_honeybee.txt   honeybee's -ab 2 -aa 0.1 -ad 2048 -ar 64 -lw 2e-5 (the cache's error)
#   view_values.txt   -ov -ab 2 -aa 0 -ad 256 of sphere_rays.txt (400 view rays)
#   view_outputs.txt  -odwWlLpNnsmM of view_rays.txt; sensor_outputs.txt the same with -I
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
