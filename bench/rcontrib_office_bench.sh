#!/usr/bin/env bash
# Issue 6's benchmark: the paper's reference office (examples/reference-office, 1425 sensors per
# office; OFFICES=10 for the 14250-sensor model), time against error, on Embree, on each Vulkan
# device named, by each traversal, and beside RADIANCE's rcontrib where it is installed.
#   V     the view matrix to the window (its glass as a glow receiver), Klems full bins:
#         -I+ -ab 8 -ad N -lw 2e-5 -faf -f klems_full.cal -b 'kbin(0,1,0,0,0,1)' -bn Nkbins
#         -m glass_mat; error: relative RMS over all entries against the mean of REF_RUNS
#         Embree runs at the largest -ad (other seeds), so at that -ad it includes the
#         reference's own noise (about 1/sqrt(REF_RUNS) of a run's)
#   Cds   direct-sun coefficients to 5185 suns, the example's command (-I+ -ab 0 -dc 1 -dt 0
#         -dj 0 -faf -e MF:6 -f reinhart.cal -b rbin -bn Nrbins -m solar); deterministic:
#         error against Embree's matrix
# Times are wall seconds of one run (/usr/bin/time), Vulkan runs after a warm-up that compiles
# the shader. Our runs use -seed 1 and all cores; RADIANCE -n nproc on an octree of the files.
# usage: bench/rcontrib_office_bench.sh
# environment: OFFICES (1), STRIDE (1: every sensor; 15 takes every 15th), ADS ("5000 50000"),
#   REF_RUNS (2), DEVICES ("": none; e.g. "0" or "llvmpipe"), TRAVERSALS ("rayquery bvh"),
#   CASES ("V Cds"), OURS, RADIANCE_BIN (/opt/radiance/bin; RADIANCE=0 skips it)
# writes bench/results/rcontrib_office.csv and .svg
set -euo pipefail
source "$(dirname "$0")/rcontrib_common.sh" rcontrib_office "case,program,sensors,ad,wall_s,rel_rms"
OFFICES=${OFFICES:-1}
STRIDE=${STRIDE:-1}
ADS=${ADS:-"5000 50000"}
REF_RUNS=${REF_RUNS:-2}
DEVICES=${DEVICES:-}
TRAVERSALS=${TRAVERSALS:-"rayquery bvh"}
CASES=${CASES:-"V Cds"}

python3 "$root/examples/reference-office/make_office.py" --offices "$OFFICES" --out "$tmp/model" >&2
awk -v s="$STRIDE" '(NR - 1) % s == 0' "$tmp/model/sensors.pts" > "$tmp/sensors.pts"
sensors=$(wc -l < "$tmp/sensors.pts")
# The V scene: the window's glass becomes a glow receiver (as GlazingVmtx.rad in the tutorial).
sed 's/^void glass glass_mat .*$/void glow glass_mat 0 0 4 1 1 1 0/' "$tmp/model/materials.rad" \
    > "$tmp/vmaterials.rad"
grep -q "glow glass_mat" "$tmp/vmaterials.rad" || { echo "no glass_mat in the model" >&2; exit 1; }
V_SCENE="vmaterials.rad model/office.rad model/glass.rad"
V_BINS="-f klems_full.cal -b kbin(0,1,0,0,0,1) -bn Nkbins -m glass_mat"
CDS_SCENE="model/materials.rad model/office.rad model/glass.rad model/suns.rad"
CDS_ARGS="-I+ -ab 0 -dc 1 -dt 0 -dj 0 -faf -e MF:6 -f reinhart.cal -b rbin -bn Nrbins -m solar"
export RAYPATH=.:$root/lib
timed() { timed_run "$tmp/sensors.pts" "$@"; }  # output command... ; prints wall seconds
record() {  # case program ad seconds output reference
    err=$(python3 "$here/rcontrib_error.py" "$5" "$6")
    echo "$1,$2,$sensors,$3,$4,$err" | tee -a "$csv"
}
# Each of our programs: name and options.
programs=("dayflux-embree|-backend embree")
for d in $DEVICES; do
    for t in $TRAVERSALS; do programs+=("dayflux-vulkan-$d-$t|-backend vulkan -device $d -gpu_traversal $t"); done
done
have_radiance=0
if [ "${RADIANCE:-1}" != 0 ] && [ -x "$RADIANCE_BIN/rcontrib" ]; then
    have_radiance=1
    (cd "$tmp" && "$RADIANCE_BIN/oconv" $V_SCENE > v.oct && "$RADIANCE_BIN/oconv" $CDS_SCENE > cds.oct)
fi
for p in "${programs[@]}"; do  # warm-ups: shader compilation is not what is measured
    case $p in *vulkan*)
        (cd "$tmp" && head -2 sensors.pts | "$OURS" ${p#*|} -I+ -ab 1 -ad 16 -faf $V_BINS $V_SCENE > /dev/null)
        (cd "$tmp" && head -2 sensors.pts | "$OURS" ${p#*|} $CDS_ARGS $CDS_SCENE > /dev/null) ;;
    esac
done
if [[ " $CASES " == *" V "* ]]; then
    ref_ad=${ADS##* }
    refs=()
    for r in $(seq 1 "$REF_RUNS"); do
        timed "$tmp/vref$r" "$OURS" -backend embree -seed $((1000 + r)) -I+ -ab 8 -ad "$ref_ad" \
            -lw 2e-5 -faf $V_BINS $V_SCENE > /dev/null
        refs+=("$tmp/vref$r")
    done
    python3 "$here/rcontrib_error.py" --mean "$tmp/vref" "${refs[@]}"
    for ad in $ADS; do
        for p in "${programs[@]}"; do
            t=$(timed "$tmp/v" "$OURS" ${p#*|} -seed 1 -I+ -ab 8 -ad "$ad" -lw 2e-5 -faf $V_BINS $V_SCENE)
            record V "${p%%|*}" "$ad" "$t" "$tmp/v" "$tmp/vref"
        done
        if [ $have_radiance = 1 ]; then
            t=$(RAYPATH=.:$RADIANCE_BIN/../lib timed "$tmp/v" "$RADIANCE_BIN/rcontrib" -n "$NPROC" \
                -I+ -ab 8 -ad "$ad" -lw 2e-5 -faf $V_BINS v.oct)
            record V radiance "$ad" "$t" "$tmp/v" "$tmp/vref"
        fi
    done
fi
if [[ " $CASES " == *" Cds "* ]]; then
    timed "$tmp/cds_ref" "$OURS" -backend embree $CDS_ARGS $CDS_SCENE > /dev/null
    for p in "${programs[@]}"; do
        t=$(timed "$tmp/cds" "$OURS" ${p#*|} $CDS_ARGS $CDS_SCENE)
        record Cds "${p%%|*}" 0 "$t" "$tmp/cds" "$tmp/cds_ref"
    done
    if [ $have_radiance = 1 ]; then
        t=$(RAYPATH=.:$RADIANCE_BIN/../lib timed "$tmp/cds" "$RADIANCE_BIN/rcontrib" -n "$NPROC" \
            $CDS_ARGS cds.oct)
        record Cds radiance 0 "$t" "$tmp/cds" "$tmp/cds_ref"
    fi
fi
python3 "$here/rcontrib_error.py" --plot "$csv" "$here/results/rcontrib_office.svg"
