#!/usr/bin/env bash
# rcontrib-gpu speed against error, beside RADIANCE's rcontrib, on the side-lit tutorial room
# (100 sensors). Each case runs at several -ad; the error is the relative RMS over all entries
# against RADIANCE's converged reference (mean of ten runs at -ad 65536 -lw 1e-6).
#   V    -I+ -ab 4 -ad N -lw 2e-4 -faf -f klems_full.cal -b 'kbin(0,1,0,0,0,1)' -bn Nkbins -m Glazing
#   DC   -I+ -ab 4 -ad N -lw 1e-4 -faf -e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow -m groundglow
#   Cds  -I+ -ab 1 -ad 256 -lw 1e-3 -dc 1 -dt 0 -dj 0 -faf -e MF:6 ... -m solar (deterministic)
# RADIANCE reads the frozen octrees of shared/data/references/rcontrib, ours the same scene's
# .rad files from test/data (C_ds: the same octree). Times are wall seconds, the fastest of
# REPEAT runs (a 2-core VM's times vary 10-20 % from run to run), both programs on all cores of
# the machine (RADIANCE with -n nproc).
# usage: bench/rcontrib_speed_error.sh   environment: OURS, RADIANCE_BIN (/opt/radiance/bin),
#        REFS (../shared/data/references/rcontrib), ADS ("1024 4096 16384"), REPEAT (3),
#        ASUBS ("2 3": ours again with -asub N at each -ad, as "dayflux-asubN"; "" for none),
#        VULKAN (a Vulkan device for rcontrib-gpu -device, e.g. 0 or llvmpipe: adds its rows,
#        timed after a warm-up run that compiles the shaders), LABEL (dayflux: our rows' name,
#        to tell two builds apart), RADIANCE (0 skips RADIANCE's rows; so does its absence)
# writes bench/results/rcontrib_speed_error.csv and .svg
set -euo pipefail
source "$(dirname "$0")/rcontrib_common.sh" rcontrib_speed_error "case,program,ad,wall_s,rel_rms"
REFS=${REFS:-$(realpath -m "$root/../shared/data/references/rcontrib")}
ADS=${ADS:-"1024 4096 16384"}
ASUBS=${ASUBS-"2 3"}
V_ARGS="-f klems_full.cal -b kbin(0,1,0,0,0,1) -bn Nkbins -m Glazing"
DC_ARGS="-e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow -m groundglow"
CDS_ARGS="-I+ -ab 1 -ad 256 -lw 1e-3 -dc 1 -dt 0 -dj 0 -faf -e MF:6 -f reinhart.cal -b rbin -bn Nrbins -m solar"
REPEAT=${REPEAT:-3}
timed() {  # out_file command... ; prints the fastest of REPEAT runs' wall seconds (the last kept)
    local best="" start end ms
    for _ in $(seq "$REPEAT"); do
        start=$(date +%s%N)
        "${@:2}" < "$PTS" > "$1"
        end=$(date +%s%N)
        ms=$(((end - start) / 1000000))
        if [ -z "$best" ] || [ "$ms" -lt "$best" ]; then best=$ms; fi
    done
    printf '%d.%03d\n' $((best / 1000)) $((best % 1000))
}
record() {  # case program ad seconds output reference
    err=$(python3 "$here/rcontrib_error.py" "$5" "$6")
    echo "$1,$2,$3,$4,$err" | tee -a "$csv"
}
VULKAN=${VULKAN:-}
LABEL=${LABEL:-dayflux}
have_radiance=1
if [ "${RADIANCE:-1}" = 0 ] || [ ! -x "$RADIANCE_BIN/rcontrib" ]; then have_radiance=0; fi
if [ -n "$VULKAN" ]; then  # compile the shaders once, outside the timings
    (cd "$ROOM" && "$OURS" -device "$VULKAN" -I+ -ab 1 -ad 16 -faf $V_ARGS materials.rad room.rad \
        objects/GlazingVmtx.rad < "$PTS" > /dev/null)
    (cd "$ROOM" && "$OURS" -device "$VULKAN" -I+ -ab 1 -ad 16 -faf $DC_ARGS materials.rad \
        room.rad objects/Glazing.rad skyDomes/skyglow.rad < "$PTS" > /dev/null)
    (cd "$REFS" && "$OURS" -device "$VULKAN" $CDS_ARGS cds.oct < "$PTS" > /dev/null)
fi
for ad in $ADS; do
    t=$(cd "$ROOM" && timed "$tmp/v_ours" "$OURS" -I+ -ab 4 -ad "$ad" -lw 2e-4 -faf $V_ARGS \
        materials.rad room.rad objects/GlazingVmtx.rad)
    record V "$LABEL" "$ad" "$t" "$tmp/v_ours" "$REFS/v_conv.fmx"
    for asub in $ASUBS; do
        t=$(cd "$ROOM" && timed "$tmp/v_sub" "$OURS" -asub "$asub" -I+ -ab 4 -ad "$ad" -lw 2e-4 \
            -faf $V_ARGS materials.rad room.rad objects/GlazingVmtx.rad)
        record V "$LABEL-asub$asub" "$ad" "$t" "$tmp/v_sub" "$REFS/v_conv.fmx"
        t=$(cd "$ROOM" && timed "$tmp/dc_sub" "$OURS" -asub "$asub" -I+ -ab 4 -ad "$ad" -lw 1e-4 \
            -faf $DC_ARGS materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad)
        record DC "$LABEL-asub$asub" "$ad" "$t" "$tmp/dc_sub" "$REFS/dc_conv.fmx"
    done
    if [ -n "$VULKAN" ]; then
        t=$(cd "$ROOM" && timed "$tmp/v_gpu" "$OURS" -device "$VULKAN" -I+ -ab 4 -ad "$ad" \
            -lw 2e-4 -faf $V_ARGS materials.rad room.rad objects/GlazingVmtx.rad)
        record V "$LABEL-vulkan" "$ad" "$t" "$tmp/v_gpu" "$REFS/v_conv.fmx"
        t=$(cd "$ROOM" && timed "$tmp/dc_gpu" "$OURS" -device "$VULKAN" -I+ -ab 4 -ad "$ad" \
            -lw 1e-4 -faf $DC_ARGS materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad)
        record DC "$LABEL-vulkan" "$ad" "$t" "$tmp/dc_gpu" "$REFS/dc_conv.fmx"
    fi
    if [ $have_radiance = 1 ]; then
        t=$(cd "$REFS" && RAYPATH=.:$RADIANCE_BIN/../lib timed "$tmp/v_rad" \
            "$RADIANCE_BIN/rcontrib" -n "$NPROC" -I+ -ab 4 -ad "$ad" -lw 2e-4 -faf $V_ARGS roomV.oct)
        record V radiance "$ad" "$t" "$tmp/v_rad" "$REFS/v_conv.fmx"
    fi
    t=$(cd "$ROOM" && timed "$tmp/dc_ours" "$OURS" -I+ -ab 4 -ad "$ad" -lw 1e-4 -faf $DC_ARGS \
        materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad)
    record DC "$LABEL" "$ad" "$t" "$tmp/dc_ours" "$REFS/dc_conv.fmx"
    if [ $have_radiance = 1 ]; then
        t=$(cd "$REFS" && RAYPATH=.:$RADIANCE_BIN/../lib timed "$tmp/dc_rad" \
            "$RADIANCE_BIN/rcontrib" -n "$NPROC" -I+ -ab 4 -ad "$ad" -lw 1e-4 -faf $DC_ARGS room2ph.oct)
        record DC radiance "$ad" "$t" "$tmp/dc_rad" "$REFS/dc_conv.fmx"
    fi
done
xz -dc "$REFS/cds_test.fmx.xz" > "$tmp/cds_ref"
t=$(cd "$REFS" && timed "$tmp/cds_ours" "$OURS" $CDS_ARGS cds.oct)
record Cds "$LABEL" 256 "$t" "$tmp/cds_ours" "$tmp/cds_ref"
if [ -n "$VULKAN" ]; then
    t=$(cd "$REFS" && timed "$tmp/cds_gpu" "$OURS" -device "$VULKAN" $CDS_ARGS cds.oct)
    record Cds "$LABEL-vulkan" 256 "$t" "$tmp/cds_gpu" "$tmp/cds_ref"
fi
if [ $have_radiance = 1 ]; then
    t=$(cd "$REFS" && RAYPATH=.:$RADIANCE_BIN/../lib timed "$tmp/cds_rad" "$RADIANCE_BIN/rcontrib" \
        -n "$NPROC" $CDS_ARGS cds.oct)
    record Cds radiance 256 "$t" "$tmp/cds_rad" "$tmp/cds_ref"
fi
python3 "$here/rcontrib_error.py" --plot "$csv" "$here/results/rcontrib_speed_error.svg"
