#!/usr/bin/env bash
# genBSDF's speed against error (issue 23): the venetian blind of test/data/genbsdf at several
# -c, dayflux's genBSDF and, where given, RADIANCE's, each against a converged reference (the
# mean of dayflux's and RADIANCE's runs at REF_C, or dayflux's alone); error = relative RMS over
# every BSDF value of the XML (bench/rcontrib_error.py), both sides' blocks (tb, rb).
# Results: bench/results/genbsdf_speed_error.csv.
# usage: bench/genbsdf_speed_error.sh
# environment: BUILD (build), CS ("100 200 400 800 1600"), REF_C (6400), ROPTS ("-ab 3 -ad 128
#   -lw 1e-4"), NPROC (2), RADIANCE_PL (RADIANCE's genBSDF.pl, run with perl; its rfluxmtx,
#   rcontrib, rmtxop, wrapBSDF, getbbox, rad2mgf, oconv and xform on PATH, its lib on RAYPATH)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
bin=$root/${BUILD:-build}/bin
cs=${CS:-"100 200 400 800 1600"}
ref_c=${REF_C:-6400}
ropts=${ROPTS:-"-ab 3 -ad 128 -lw 1e-4"}
nproc=${NPROC:-2}
dim="-dim 0 0.2 0 0.2 -0.025 0"
blinds=$root/test/data/genbsdf/blinds.rad
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
run() {  # program c seed out: prints seconds
    local start=$(date +%s.%N)
    if [ "$1" = dayflux ]; then
        "$bin/genBSDF" -n "$nproc" -c "$2" -seed "$3" -r "$ropts" $dim "$blinds" > "$4"
    else
        perl "$RADIANCE_PL" -n "$nproc" -c "$2" -r "$ropts" $dim "$blinds" > "$4" 2> /dev/null
    fi
    awk -v s="$start" -v e="$(date +%s.%N)" 'BEGIN { printf "%.2f\n", e - s }'
}
programs=dayflux
[ -n "${RADIANCE_PL:-}" ] && programs="dayflux radiance"
refs=()
for p in $programs; do
    echo "reference: $p -c $ref_c: $(run "$p" "$ref_c" 99 "$tmp/ref_$p.xml") s" >&2
    refs+=("$tmp/ref_$p.xml")
done
python3 - "$tmp/ref.xml" "${refs[@]}" <<'PY'
import re, sys
texts = [open(p).read() for p in sys.argv[2:]]
blocks = [re.findall(r'<ScatteringData>(.*?)</ScatteringData>', t, re.S) for t in texts]
out = texts[0]
for k, block in enumerate(blocks[0]):
    vals = [[float(v) for v in b[k].split()] for b in blocks]
    mean = ' '.join('%.6e' % (sum(c) / len(c)) for c in zip(*vals))
    out = out.replace(block, '\n' + mean + '\n', 1)
open(sys.argv[1], 'w').write(out)
PY
echo "program,c,seconds,error" > "$here/results/genbsdf_speed_error.csv"
for p in $programs; do
    for c in $cs; do
        s=$(run "$p" "$c" 1 "$tmp/$p$c.xml")
        e=$(python3 "$here/rcontrib_error.py" "$tmp/$p$c.xml" "$tmp/ref.xml")
        echo "$p,$c,$s,$e" | tee -a "$here/results/genbsdf_speed_error.csv"
    done
done
