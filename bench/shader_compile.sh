#!/usr/bin/env bash
# How long the Vulkan integrator's shader variants take to compile on a device (lavapipe by
# default): each variant's run, cold (empty SPIR-V and Mesa caches) and warm (both cached), on
# one sensor of the tutorial room at -ab 1 -ad 16, so that the run itself is negligible.
#   V       Klems bins on the window (kbin), plastic room
#   DC      Reinhart bins of skyglow through glass
#   BSDF    the room's window as the frads blinds BSDF, with a sun (the slowest variant)
# usage: bench/shader_compile.sh   environment: OURS (the build's rcontrib-gpu), DEVICE
#        (llvmpipe), GALLIVM_PERF (nopt, as the tests run; "" for Mesa's optimised default)
# writes bench/results/shader_compile.csv
set -euo pipefail
source "$(dirname "$0")/rcontrib_common.sh" shader_compile "variant,cache,wall_s"
DEVICE=${DEVICE:-llvmpipe}
export GALLIVM_PERF=${GALLIVM_PERF-nopt}
head -1 "$PTS" > "$tmp/pt"
xz -dc "$root/test/data/rcontrib/bsdf_room/frads_blinds30.xml.xz" > "$tmp/frads_blinds30.xml"
sed "s|6 0 frads_blinds30.xml|6 0 $tmp/frads_blinds30.xml|" \
    "$root/test/data/rcontrib/bsdf_room/blinds.rad" > "$tmp/blinds.rad"
printf 'void light solar 0 0 3 1 1 1\nsolar source sun 0 0 4 0.3 -0.6 0.742 0.533\n' > "$tmp/sun.rad"
declare -A ARGS=(
    [V]="-f klems_full.cal -b kbin(0,1,0,0,0,1) -bn Nkbins -m Glazing materials.rad room.rad objects/GlazingVmtx.rad"
    [DC]="-e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow materials.rad room.rad objects/Glazing.rad skyDomes/skyglow.rad"
    [BSDF]="-e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow -m solar materials.rad room.rad $tmp/blinds.rad skyDomes/skyglow.rad $tmp/sun.rad"
)
for variant in V DC BSDF; do
    cache="$tmp/cache-$variant"
    mkdir -p "$cache"
    for run in cold warm; do
        (cd "$ROOM" && /usr/bin/time -f "%e" -o "$tmp/time" env XDG_CACHE_HOME="$cache" \
            "$OURS" -backend vulkan -device "$DEVICE" -I+ -ab 1 -ad 16 -faf ${ARGS[$variant]} \
            < "$tmp/pt" > /dev/null 2> "$tmp/err") || { cat "$tmp/err"; exit 1; }
        grep -q "using Embree" "$tmp/err" && { cat "$tmp/err"; exit 1; }
        echo "$variant,$run,$(cat "$tmp/time")" | tee -a "$csv"
    done
done
