#!/usr/bin/env bash
# Makes the gendaymtx/epw2wea references in this folder with RADIANCE 5.4 (NREL/Radiance @2fcca99a)
# built outside this repository: RADIANCE=/path/to/radiance/bin ./make_references.sh
# Inputs: shared/data/weather (see test/data/README.md). Subsets keep the data small: for each site,
# the 6 header lines, every 347th hour of the year, and all hours of 21 Dec (low winter sun);
# frads_test.wea is used whole.
set -euo pipefail
R=${RADIANCE:?set RADIANCE to RADIANCE 5.4\'s bin folder}
W=${WEATHER:-../../../../shared/data/weather}
sub() { awk 'NR<=6 || (NR-6)%347==1 || ($1==12 && $2==21)' "$1"; }
"$R/epw2wea" "$W/USA_CO_Denver.Intl.AP.725650_TMY3.epw" denver_full.wea >/dev/null
"$R/epw2wea" "$W/USA_NY_New.York.City-Central.Park.94728_TMY_3.epw" nyc_full.wea >/dev/null
sub denver_full.wea > denver.wea
sub nyc_full.wea > nyc.wea
cp "$W/frads_test.wea" frads.wea
rm -f denver_full.wea nyc_full.wea
for site in denver nyc frads; do
    for mf in 1 2; do
        "$R/gendaymtx" -m $mf -of $site.wea > ${site}_m$mf.fmx 2>/dev/null
    done
    "$R/gendaymtx" -m 2 -d -of $site.wea > ${site}_m2_d.fmx 2>/dev/null
    "$R/gendaymtx" -m 2 -s -of $site.wea > ${site}_m2_s.fmx 2>/dev/null
    "$R/gendaymtx" -m 6 -5 0.533 -d -of $site.wea > ${site}_m6_5ph.fmx 2>/dev/null
    "$R/gendaymtx" -m 1 -O1 -of $site.wea > ${site}_m1_O1.fmx 2>/dev/null
    "$R/gendaymtx" -m 1 -r 30 -g .1 .2 .3 -c 1 .9 .8 -of $site.wea > ${site}_m1_r_g_c.fmx 2>/dev/null
    "$R/gendaymtx" -D ${site}_suns.rad -M ${site}_suns.mod -m 1 -of $site.wea > ${site}_m1_D.fmx 2>/dev/null
    "$R/gendaymtx" -D - $site.wea > ${site}_suns_stdout.rad 2>/dev/null
done
for mf in 4 6; do  # the finest skies for one site only, to keep the data small
    "$R/gendaymtx" -m $mf -of denver.wea > denver_m$mf.fmx 2>/dev/null
done
# Units 2 (direct horizontal) and 3 (illuminance) made from the frads subset by rewriting its units line.
sed 's/^weather_data_file_units 1/weather_data_file_units 2/' frads.wea > frads_u2.wea
awk 'NR<=6 { if (NR==6) print "weather_data_file_units 3"; else print; next } { print $1, $2, $3, $4*100, $5*110 }' frads.wea > frads_u3.wea
"$R/gendaymtx" -m 1 -of frads_u2.wea > frads_u2_m1.fmx 2>/dev/null
"$R/gendaymtx" -m 1 -of frads_u3.wea > frads_u3_m1.fmx 2>/dev/null
# A leap year: 29 Feb counts as day 60 and shifts the days after it.
{ head -6 frads.wea; printf '2 28 12.5 600 100\n2 29 12.5 600 100\n3 1 12.5 600 100\n3 1 16.5 300 80\n'; } > leap.wea
"$R/gendaymtx" -m 1 -of leap.wea > leap_m1.fmx 2>/dev/null
xz -9 -f -- *.fmx
