#!/usr/bin/env bash
# The flagship example: a year of daylight in the reference office, ending in sDA, ASE and
# pictures. Arguments go to make (OFFICES=2, BLINDS=1, AD=..., OUT=...); see Makefile.
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
awk -v s="$start" -v e="$end" 'BEGIN { printf "\nreference office done in %.1f s; results in %s:\n", e - s, "'"$out"'" }'
echo "  metrics.csv / metrics.json   per-sensor and per-grid DA, cDA, UDI, ASE hours"
echo "  da.png, ase.png              false-colour plans of DA300 and of hours of direct sun"
echo "  snapshot.png/.hdr/.exr       illuminance for one hour"
