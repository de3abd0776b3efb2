#!/usr/bin/env bash
# Makes expected/ from RADIANCE's own getinfo (5.4a, built outside this repository), run here on
# each line of commands.txt: its standard output, then a last line "status N".
# usage: PATH=/path/to/radiance/bin:$PATH ./make_expected.sh
set -uo pipefail
cd "$(dirname "$0")"
mkdir -p expected
while IFS=$'\t' read -r name args input; do
    [[ -z "$name" || "$name" == \#* ]] && continue
    # shellcheck disable=SC2086
    if [ "$input" = "-" ]; then getinfo $args < /dev/null; else getinfo $args < "$input"; fi \
        > "expected/$name.out" 2> /dev/null
    echo "status $?" >> "expected/$name.out"
done < commands.txt
