#!/usr/bin/env bash
# Primitive counts of the shared models as RADIANCE 5.4 reads them: RADIANCE's xform expands
# every !command and writes each primitive once; count_primitives.py tallies them by type.
# RADIANCE=/path/to/radiance/bin ./make_counts.sh > counts.txt
set -euo pipefail
R=${RADIANCE:?}
M=$(cd "${MODELS:-../../../../shared/data/models}" && pwd)
here=$(pwd)
count() {  # name, folder, files...
    local name=$1 dir=$2; shift 2
    (cd "$M/$dir" && PATH="$R:$PATH" "$R/xform" "$@" | python3 "$here/count_primitives.py" | sed "s|^|$name |")
}
count room2ph subramaniam_tutorial/room materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad
count roomV subramaniam_tutorial/room materials.rad room.rad objects/GlazingVmtx.rad
count cds subramaniam_tutorial/room materialBlack.rad roomBlack.rad materials.rad objects/Glazing.rad
count lbnl_office frads_lbnl_office Objects/materials.mat Objects/ceiling.rad Objects/cubefabric.rad Objects/cubeframe.rad Objects/desks.rad Objects/extwalls.rad Objects/floor.rad Objects/ground.rad Objects/horframe.rad Objects/lower_glass.rad Objects/overhang.rad Objects/upper_glass.rad Objects/walls.rad Objects/windowframe.rad
count openroom frads_openroom ceiling_openroom.rad floor_openroom.rad wall_openroom.rad window_0_openroom.rad window_1_openroom.rad window_2_openroom.rad window_3_openroom.rad
count suns subramaniam_tutorial/room skies/suns.rad
