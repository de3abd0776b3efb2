#!/usr/bin/env bash
# DAYSIM's method on the reference office (gen_dc, ds_illum, dcmetrics); arguments go to make
# (OFFICES=2, AB=..., OUT=...); see Makefile.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
out=$here/out/small
for a in "$@"; do case $a in OUT=*) out=${a#OUT=} ;; esac; done
case $out in /*) ;; *) out=$here/$out ;; esac  # make runs in $here
bin=${DAYFLUX_BIN:-$here/../../build/bin}
start=$(date +%s.%N)
make --no-print-directory -C "$here" BIN="$bin" "$@" OUT="$out"
end=$(date +%s.%N)
echo
cat "$out/metrics.txt"
awk -v s="$start" -v e="$end" 'BEGIN { printf "\nreference office (DAYSIM) done in %.1f s; results in %s:\n", e - s, "'"$out"'" }'
echo "  office.hea, office.dc, office.ill   DAYSIM's project, coefficients and illuminance"
echo "  metrics.csv / metrics.json          per-sensor and per-grid DA, cDA, UDI, ASE hours"
echo "  da.png                              false-colour plan of DA300"
