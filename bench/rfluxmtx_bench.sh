#!/usr/bin/env bash
# Issue 21's benchmark: rfluxmtx-gpu against RADIANCE's rfluxmtx on the three-phase matrices of the
# tutorial room (MODEL=room) or the reference office (MODEL=office: examples/reference-office's
# make_office.py, its window.rad and skydome.rad, its 1425 sensors, the scene as .rad files, which
# rfluxmtx puts through oconv), the recipe's command lines (shared/spec/workflows.md section 2) with
# float output; for the room:
#   D   rfluxmtx -v -ff -ab 4 -ad 1000 -lw 0.001 -c C objects/GlazingVmtx.rad skyDomes/skyglow.rad
#       -i room3ph.oct, for each C in CS; error against the mean of REF_RUNS of ours at -c REF_C
#       (other seeds, so other sender samples)
#   V   rfluxmtx -v -faf -I+ -ab 4 -ad AD -lw 0.0002 -y 100 - objects/GlazingVmtx.rad -i room3ph.oct
#       < points.txt, for each AD in ADS; error against the mean of REF_RUNS of ours at -ad REF_AD
#       -lw REF_LW (-lw caps the first hemisphere's samples: 0.0002 keeps -ad 50000 to about 1000)
# Error: relative RMS over all entries. Times: wall seconds of one run; ours with all cores (and
# -seed 1), RADIANCE with -n nproc. The octree is RADIANCE's (test/data/recipes/octrees).
# usage: bench/rfluxmtx_bench.sh
# environment: MODEL (room), CS ("100 1000"), REF_C (10000), ADS ("1000 5000"), REF_AD (50000),
#   REF_LW (1e-6), REF_RUNS (2), DEVICES ("": none; e.g. "0" or "llvmpipe"), CASES ("D V"),
#   RFLUXMTX (the build's rfluxmtx-gpu), RADIANCE_BIN (/opt/radiance/bin; RADIANCE=0 skips it), RADIANCE_LIB
#   (RADIANCE_BIN/../lib: its .cal files)
# writes bench/results/rfluxmtx.csv and .svg (MODEL=office: rfluxmtx_office.csv and .svg)
set -euo pipefail
MODEL=${MODEL:-room}
name=rfluxmtx$([ "$MODEL" = room ] || echo "_$MODEL")
source "$(dirname "$0")/rcontrib_common.sh" "$name" "case,program,setting,wall_s,rel_rms"
RFLUXMTX=${RFLUXMTX:-$root/build/bin/rfluxmtx-gpu}
RADIANCE_LIB=${RADIANCE_LIB:-$RADIANCE_BIN/../lib}
CS=${CS:-"100 1000"}
REF_C=${REF_C:-10000}
ADS=${ADS:-"1000 5000"}
REF_AD=${REF_AD:-50000}
REF_LW=${REF_LW:-1e-6}
REF_RUNS=${REF_RUNS:-2}
DEVICES=${DEVICES:-}
CASES=${CASES:-"D V"}

case $MODEL in
    room)
        cp -r "$ROOM"/. "$tmp/"
        cp "$PTS" "$tmp/points.txt"
        cp -r "$root/test/data/recipes/octrees" "$tmp/octrees"
        window=objects/GlazingVmtx.rad sky=skyDomes/skyglow.rad scene="-i octrees/room3ph.oct" ;;
    office)
        python3 "$root/examples/reference-office/make_office.py" --out "$tmp/model" >&2
        cp "$tmp/model/sensors.pts" "$tmp/points.txt"
        window=model/window.rad sky=model/skydome.rad scene="model/materials.rad model/office.rad" ;;
    *) echo "MODEL must be room or office" >&2; exit 1 ;;
esac
D_ARGS="-ab 4 -ad 1000 -lw 0.001 $window $sky $scene"
V_ARGS="-I+ -ab 4 -y $(wc -l < "$tmp/points.txt") - $window $scene"
timed() { timed_run "$tmp/points.txt" "$@"; }  # output command... ; prints wall seconds
record() {  # case program setting seconds output reference
    err=$(python3 "$here/rcontrib_error.py" "$5" "$6")
    echo "$1,$2,$3,$4,$err" | tee -a "$csv"
}
programs=("dayflux-embree|-backend embree")
for d in $DEVICES; do programs+=("dayflux-vulkan-$d|-backend vulkan -device $d"); done
have_radiance=0
if [ "${RADIANCE:-1}" != 0 ] && [ -x "$RADIANCE_BIN/rfluxmtx" ]; then have_radiance=1; fi
# RADIANCE's rfluxmtx runs its rcontrib and oconv from PATH, which must be RADIANCE's.
cat > "$tmp/radiance" <<END
#!/bin/sh
PATH="$RADIANCE_BIN:\$PATH" RAYPATH=".:$RADIANCE_LIB" exec "$RADIANCE_BIN/rfluxmtx" "\$@"
END
chmod +x "$tmp/radiance"
for p in "${programs[@]}"; do  # warm-ups: shader compilation is not what is measured
    case $p in *vulkan*) timed /dev/null "$RFLUXMTX" ${p#*|} -ff -c 1 $D_ARGS > /dev/null ;; esac
done
reference() {  # output options... : the mean of REF_RUNS of ours with other seeds
    local refs=()
    for r in $(seq 1 "$REF_RUNS"); do
        timed "$tmp/ref$r" "$RFLUXMTX" -backend embree -seed $((1000 + r)) "${@:2}" > /dev/null
        refs+=("$tmp/ref$r")
    done
    python3 "$here/rcontrib_error.py" --mean "$1" "${refs[@]}"
}
if [[ " $CASES " == *" D "* ]]; then
    reference "$tmp/dref" -ff -c "$REF_C" $D_ARGS
    for c in $CS; do
        for p in "${programs[@]}"; do
            t=$(timed "$tmp/d" "$RFLUXMTX" ${p#*|} -seed 1 -ff -c "$c" $D_ARGS)
            record D "${p%%|*}" "c$c" "$t" "$tmp/d" "$tmp/dref"
        done
        if [ $have_radiance = 1 ]; then
            t=$(timed "$tmp/d" "$tmp/radiance" -n "$NPROC" -ff -c "$c" $D_ARGS)
            record D radiance "c$c" "$t" "$tmp/d" "$tmp/dref"
        fi
    done
fi
if [[ " $CASES " == *" V "* ]]; then
    reference "$tmp/vref" -faf -ad "$REF_AD" -lw "$REF_LW" $V_ARGS
    for ad in $ADS; do
        for p in "${programs[@]}"; do
            t=$(timed "$tmp/v" "$RFLUXMTX" ${p#*|} -seed 1 -faf -ad "$ad" -lw 0.0002 $V_ARGS)
            record V "${p%%|*}" "ad$ad" "$t" "$tmp/v" "$tmp/vref"
        done
        if [ $have_radiance = 1 ]; then
            t=$(timed "$tmp/v" "$tmp/radiance" -n "$NPROC" -faf -ad "$ad" -lw 0.0002 $V_ARGS)
            record V radiance "ad$ad" "$t" "$tmp/v" "$tmp/vref"
        fi
    done
fi
python3 "$here/rcontrib_error.py" --plot "$csv" "$here/results/$name.svg"
