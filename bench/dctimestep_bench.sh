#!/usr/bin/env bash
# dctimestep benchmark: dayflux's dctimestep against RADIANCE's on three cases, float in, -of out.
#   a) three-phase          dctimestep -of V.fmx T.fmx D.fmx S.fmx
#   b) daylight coeffs      dctimestep -of DC.fmx S.fmx
#   c) five-phase sun       dctimestep -of Cds.fmx sun_m6.fmx
# Each program first writes its result to a file once, and the two results are compared
# (body bytes with cmp, then python3 /work/shared/tools/mtxcmp.py REF OURS --rel 1e-5).
# Then the timed runs, output to /dev/null, under /usr/bin/time -f "%e %M %U %S": RADIANCE once,
# ours 3 times (minimum wall time, maximum peak RSS). RADIANCE runs are limited to 15 minutes
# and 20 GiB of address space; a run over the limit is recorded as such.
#
# usage: bench/dctimestep_bench.sh [DATADIR]     (default /tmp/dayflux-bench; inputs made there if missing)
# environment: OURS, RADIANCE_BIN, CASES (default "a b c"), RUNS (default 3),
#              MTXCMP_MAX_MB (skip mtxcmp for outputs larger than this when cmp finds them
#              byte-identical; default 400), KEEP_OUTPUTS=1 to keep the result files.
# writes bench/results/dctimestep.csv, dctimestep_check.txt (agreement) and dctimestep_runs.txt (every run,
# with user/sys CPU and load average, to spot interference from other work on the machine)
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
data=${1:-/tmp/dayflux-bench}
OURS=${OURS:-$(realpath -m "$here/../build/bin/dctimestep")}
RADIANCE_BIN=${RADIANCE_BIN:-/opt/radiance/bin}
CASES=${CASES:-a b c}
RUNS=${RUNS:-3}
MTXCMP=/work/shared/tools/mtxcmp.py
MTXCMP_MAX_MB=${MTXCMP_MAX_MB:-400}
RAD_TIMEOUT_S=${RAD_TIMEOUT_S:-900}
RAD_VMEM_KIB=$((20 * 1024 * 1024))
export RAYPATH=.:/opt/radiance/lib

[ -x /usr/bin/time ] || { echo "needs /usr/bin/time (apt-get install time)" >&2; exit 1; }
[ -x "$OURS" ] || { echo "no $OURS: build with ninja -C build" >&2; exit 1; }
if [ ! -f "$data/sun_m6.fmx" ] || [ ! -f "$data/Cds.fmx" ]; then
    python3 "$here/make_dctimestep_inputs.py" "$data"
fi

results=$here/results
mkdir -p "$results" "$data/out"
csv=$results/dctimestep.csv
check=$results/dctimestep_check.txt
runlog=$results/dctimestep_runs.txt
echo "case,program,wall_s,peak_rss_mib,output_format" > "$csv"
{
    echo "# dctimestep output agreement, $(date -u +%Y-%m-%dT%H:%MZ)"
    echo "# ours: $OURS ; RADIANCE: $RADIANCE_BIN/dctimestep ; data: $data"
} > "$check"
echo "# every run: /usr/bin/time -f '%e %M %U %S', 1-minute load average before/after; $(date -u +%Y-%m-%dT%H:%MZ)" > "$runlog"

case_args() {
    case $1 in
        a) echo "-of $data/V.fmx $data/T.fmx $data/D.fmx $data/S.fmx" ;;
        b) echo "-of $data/DC.fmx $data/S.fmx" ;;
        c) echo "-of $data/Cds.fmx $data/sun_m6.fmx" ;;
    esac
}
case_name() {
    case $1 in
        a) echo "a_three_phase" ;;
        b) echo "b_daylight_coefficients" ;;
        c) echo "c_five_phase_sun" ;;
    esac
}

# run PROG_KIND OUTFILE TIMEFILE ARGS...: one run under /usr/bin/time; returns the exit status.
run() {
    local kind=$1 out=$2 tfile=$3 rc=0
    shift 3
    rm -f "$tfile"
    local load0; load0=$(cut -d' ' -f1 /proc/loadavg)
    if [ "$kind" = radiance ]; then
        (ulimit -v "$RAD_VMEM_KIB"
         exec timeout "$RAD_TIMEOUT_S" /usr/bin/time -f "%e %M %U %S" -o "$tfile" "$RADIANCE_BIN/dctimestep" "$@" > "$out")
    else
        /usr/bin/time -f "%e %M %U %S" -o "$tfile" "$OURS" "$@" > "$out"
    fi || rc=$?
    printf '%s %s out=%s wall_s,rss_kib,user_s,sys_s: %s loadavg_before=%s after=%s rc=%s\n' "$(basename "$tfile" .time)" \
        "$kind" "$out" "$(tail -n 1 "$tfile" 2>/dev/null)" "$load0" "$(cut -d' ' -f1 /proc/loadavg)" "$rc" >> "$runlog"
    return $rc
}

header_len() {  # bytes up to and including the blank line that ends a RADIANCE header
    python3 -c 'import sys; d=open(sys.argv[1],"rb").read(65536); print(d.find(b"\n\n")+2)' "$1"
}

for c in $CASES; do
    name=$(case_name "$c")
    read -r -a args <<< "$(case_args "$c")"
    ref=$data/out/${c}_radiance.fmx
    ours=$data/out/${c}_ours.fmx
    echo "== case $name: dctimestep ${args[*]}"

    # Correctness: one run each to a file, then compare.
    rad_ok=1
    if ! run radiance "$ref" "$data/out/${c}_radiance_check.time" "${args[@]}"; then
        rad_ok=0
    fi
    run ours "$ours" "$data/out/${c}_ours_check.time" "${args[@]}" || echo "  ours FAILED (exit $?)" | tee -a "$check"
    {
        echo "case $name"
        if [ $rad_ok = 1 ]; then
            hr=$(header_len "$ref"); ho=$(header_len "$ours")
            if cmp -s -i "$hr:$ho" "$ref" "$ours"; then
                echo "  data bytes identical (cmp after the headers): max_rel=0"
                identical=1
            else
                echo "  data bytes differ (cmp after the headers)"
                identical=0
            fi
            size_mb=$(( $(stat -c %s "$ref") / 1048576 ))
            if [ $identical = 0 ] || [ "$size_mb" -le "$MTXCMP_MAX_MB" ]; then
                echo "  mtxcmp.py --rel 1e-5: $(python3 "$MTXCMP" "$ref" "$ours" --rel 1e-5 2>&1 || true)"
            else
                echo "  mtxcmp.py skipped (${size_mb} MiB output, identical bytes)"
            fi
        else
            echo "  RADIANCE failed or exceeded its limit; no comparison"
        fi
    } | tee -a "$check"
    [ "${KEEP_OUTPUTS:-0}" = 1 ] || rm -f "$ref" "$ours"

    # Timed runs, output to /dev/null.
    tfile=$data/out/${c}_radiance.time
    if [ $rad_ok = 1 ] && run radiance /dev/null "$tfile" "${args[@]}"; then
        read -r wall rss _ < <(tail -n 1 "$tfile")
        printf '%s,radiance,%s,%s,float\n' "$name" "$wall" "$(awk -v k="$rss" 'BEGIN{printf "%.1f", k/1024}')" >> "$csv"
    else
        printf '%s,radiance,%s,%s,float\n' "$name" "failed(>${RAD_TIMEOUT_S}s or >20GiB)" "" >> "$csv"
    fi
    best_wall=""; max_rss=0
    for i in $(seq "$RUNS"); do
        tfile=$data/out/${c}_ours_$i.time
        if ! run ours /dev/null "$tfile" "${args[@]}"; then
            echo "  ours run $i FAILED"; best_wall="failed"; break
        fi
        read -r wall rss _ < <(tail -n 1 "$tfile")
        echo "  ours run $i: ${wall}s ${rss}KiB"
        if [ -z "$best_wall" ] || awk -v a="$wall" -v b="$best_wall" 'BEGIN{exit !(a<b)}'; then best_wall=$wall; fi
        [ "$rss" -gt "$max_rss" ] && max_rss=$rss
    done
    printf '%s,ours,%s,%s,float\n' "$name" "$best_wall" "$(awk -v k="$max_rss" 'BEGIN{printf "%.1f", k/1024}')" >> "$csv"
    tail -n 2 "$csv"
done
echo "wrote $csv, $check and $runlog"
