#!/usr/bin/env bash
# The flagship example: a year of daylight in the reference office, ending in sDA, ASE and
# pictures. A first argument dc, 3phase or 5phase picks the method (daylight coefficients by
# default; daysim runs ../daysim/run.sh); the rest go to make (OFFICES=2, BLINDS=1, AD=...,
# OUT=...); see Makefile.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
if [ "${1:-}" = daysim ]; then shift && exec "$here/../daysim/run.sh" "$@"; fi
method=dc
case ${1:-} in dc | 3phase | 5phase) method=$1 && shift ;; esac
for a in "$@"; do case $a in METHOD=*) method=${a#METHOD=} ;; esac; done
out=$here/out/small$([ "$method" = dc ] || echo "-$method")
for a in "$@"; do case $a in OUT=*) out=${a#OUT=} ;; esac; done
case $out in /*) ;; *) out=$here/$out ;; esac  # make runs in $here
bin=${DAYFLUX_BIN:-$here/../../build/bin}
start=$(date +%s.%N)
make --no-print-directory -C "$here" BIN="$bin" METHOD="$method" "$@" OUT="$out"
end=$(date +%s.%N)
echo
cat "$out/metrics.txt"
awk -v s="$start" -v e="$end" 'BEGIN { printf "\nreference office ('"$method"') done in %.1f s; results in %s:\n", e - s, "'"$out"'" }'
echo "  metrics.csv / metrics.json   per-sensor and per-grid DA, cDA, UDI, ASE hours"
echo "  da.png, ase.png              false-colour plans of DA300 and of hours of direct sun"
echo "  snapshot.png/.hdr/.exr       illuminance for one hour"
