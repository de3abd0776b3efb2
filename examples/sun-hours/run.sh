#!/usr/bin/env bash
# Direct-sun illuminance of the side-lit tutorial room (100 sensors) for 349 hours of Oakland
# weather: the five-phase sun product C_ds x S_sun, then RGB irradiance to lux.
# Until dayflux's own ray tracer exists, C_ds (cds_test.fmx.xz) is RADIANCE's rcontrib output and
# S_sun (oak_5ph_d_m6.fmx.xz) RADIANCE's `gendaymtx -5 0.533 -d -m 6`; see README.md here.
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
bin=${DAYFLUX_BIN:-$here/../../build/bin}
out=${1:-$here/out}
mkdir -p "$out"
cd "$here"
echo "sun-hours: C_ds (100 sensors x 5186 suns) x S_sun (5186 patches x 349 hours)" >&2
"$bin/dctimestep" -of '!xzcat cds_test.fmx.xz' '!xzcat oak_5ph_d_m6.fmx.xz' >"$out/sun_irradiance.fmx"
"$bin/rmtxop" -fa -t -c 47.4 119.9 11.6 "$out/sun_irradiance.fmx" >"$out/sun_lux.mtx"
# Rows are hours, columns sensors: count, per sensor, the hours above 1000 lux.
awk 'BEGIN { body = 0 }
     body == 0 { if ($0 == "") body = 1; next }
     NF > 0 { hours++; for (i = 1; i <= NF; i++) { if ($i > 1000) above[i]++; if ($i > max) max = $i } n = NF }
     END {
         lit = 0; total = 0
         for (i = 1; i <= n; i++) { total += above[i]; if (above[i] > 0) lit++ }
         printf "hours: %d  sensors: %d  peak direct-sun illuminance: %.0f lux\n", hours, n, max
         printf "sensors with direct sun above 1000 lux in any hour: %d of %d; mean hours above 1000 lux: %.1f\n", lit, n, total / n
     }' "$out/sun_lux.mtx"
echo "matrices written to $out (sun_irradiance.fmx, sun_lux.mtx)" >&2
