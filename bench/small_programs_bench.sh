#!/usr/bin/env bash
# getinfo, total, rcollate, rcalc and gensky on the flagship example's year of illuminance (1425 sensors
# x 8760 hours, float, 50 MB; dctimestep | rmtxop as step 4 makes it), and oconv on its model and
# on frads' LBNL office (12 k polygons; and that at a finer resolution), beside RADIANCE's programs
# in the same run where RADIANCE names a folder holding them (built outside this repository):
# each the fastest of RUNS, and whether its output is the same bytes as RADIANCE's.
# usage: bench/small_programs_bench.sh   environment: BUILD (build), RUNS (3),
#        OUT (/tmp/dayflux-example-products: the example's output folder, made if missing),
#        RADIANCE (unset: ours only), LBNL (../shared/data/models/frads_lbnl_office/Objects)
# writes bench/results/small_programs.csv
set -euo pipefail
source "$(dirname "$0")/example_common.sh" small_programs
"$bin/dctimestep" -of "$out/dc.mtx" "$out/sky.smx" | "$bin/rmtxop" -ff -c 47.4 119.9 11.6 - \
    > "$tmp/year.fmx"
"$bin/getinfo" - < "$tmp/year.fmx" > "$tmp/year.raw"                 # headerless floats
# (the first 200 rows as ascii: head ends the pipe early, which pipefail would take for a failure)
{ "$bin/rmtxop" -fa "$tmp/year.fmx" | "$bin/getinfo" - | head -n 200 > "$tmp/year.txt"; } || true
"$bin/rmtxop" -fa -t "$tmp/year.fmx" | "$bin/getinfo" - | head -n 2 | tr '\t' '\n' \
    | paste - - > "$tmp/col.txt" || true  # (two sensors' years as two columns)
model="$out/model/materials.rad $out/model/office.rad $out/model/window.rad $out/model/glass.rad"
lbnl=${LBNL:-$(realpath -m "$root/../shared/data/models/frads_lbnl_office/Objects")}
lbnl=$(echo "$lbnl"/materials.mat "$lbnl"/*.rad)
# name|command (run in $tmp, the program's folder as $P)
cases=(
    "getinfo|\$P/getinfo year.fmx"
    "getinfo - (strip the header)|\$P/getinfo - < year.fmx"
    "rcollate -t (transpose, float)|\$P/rcollate -t year.fmx"
    "rcollate -ho -oc 730 (reshape)|\$P/rcollate -ho -oc 730 -fa1 year.txt"
    "total -if1425 -m (binary means)|\$P/total -if1425 -m year.raw"
    "total -m (ascii means of 200 rows)|\$P/total -m year.txt"
    "rcalc (two columns of 8760 rows x 100)|for k in \$(seq 100); do cat col.txt; done | \$P/rcalc -e '\$1=179*\$1;\$2=\$2/2'"
    "gensky x 1000|for h in \$(seq 1000); do \$P/gensky 6 21 12 -a 40.78 -o 73.96 -m 75; done"
    "oconv -f (the example's office)|\$P/oconv -f $model"
    "oconv -f (LBNL office)|\$P/oconv -f $lbnl"
    "oconv -f -n 2 -r 65536 (LBNL office finer)|\$P/oconv -f -n 2 -r 65536 $lbnl"
)
timed() {  # folder command: the fastest wall time of $runs, and the output in $tmp/last
    local best="" t
    for _ in $(seq 1 "$runs"); do
        /usr/bin/time -f "%e" -o "$tmp/t" bash -c "cd '$tmp' && P='$1' && $2" > "$tmp/last" 2> /dev/null
        t=$(tail -n 1 "$tmp/t")
        if [ -z "$best" ] || awk -v a="$t" -v b="$best" 'BEGIN { exit !(a < b) }'; then best=$t; fi
    done
    echo "$best"
}
echo "case,dayflux_s,radiance_s,same_output" | tee "$csv"
for c in "${cases[@]}"; do
    name=${c%%|*} cmd=${c#*|}
    ours=$(timed "$bin" "$cmd"); cp "$tmp/last" "$tmp/ours"
    theirs="" same=""
    if [ -n "${RADIANCE:-}" ]; then
        theirs=$(timed "$RADIANCE" "$cmd")
        # (headers name programs by their paths: compared without the two folders)
        sed -e "s|$bin/||g" -e "s|$RADIANCE/||g" "$tmp/ours" > "$tmp/a"
        sed -e "s|$bin/||g" -e "s|$RADIANCE/||g" "$tmp/last" > "$tmp/b"
        cmp -s "$tmp/a" "$tmp/b" && same=yes || same=no
    fi
    echo "$name,$ours,$theirs,$same" | tee -a "$csv"
done
