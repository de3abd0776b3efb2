#!/usr/bin/env bash
# Makes PROGRAM/expected/ from RADIANCE's own PROGRAM (5.4a, NREL/Radiance @2fcca99a, built outside
# this repository), run in PROGRAM/ on each line of PROGRAM/commands.txt (name, arguments and
# standard input, tab-separated; - for none): its standard output, then a last line "status N".
# The arguments are read by the shell, as the tests run them (quotes, as rcalc's expressions need).
# test/tools/matrix_tools_test.cpp's RadiancePrograms tests compare ours with them.
# usage: PATH=/path/to/radiance/bin:$PATH test/data/make_expected.sh getinfo
set -uo pipefail
program=$1
cd "$(dirname "$0")/$program"
mkdir -p expected
while IFS=$'\t' read -r name args input; do
    [[ -z "$name" || "$name" == \#* ]] && continue
    [ "$input" = "-" ] && input=/dev/null
    sh -c "\"$program\" $args < \"$input\"" > "expected/$name.out" 2> /dev/null
    echo "status $?" >> "expected/$name.out"
done < commands.txt
