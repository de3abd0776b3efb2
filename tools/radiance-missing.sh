#!/bin/sh
# A RADIANCE program that dayflux does not implement, in dayflux's folder of RADIANCE names
# (lib/dayflux/radiance/bin). It runs RADIANCE's own program of that name where one is on PATH
# outside this folder, saying so; otherwise it says what is missing and fails.
name=$(basename "$0")
here=$(cd "$(dirname "$0")" && pwd -P)
old_ifs=$IFS
IFS=:
for dir in $PATH; do
    [ -n "$dir" ] || continue
    [ "$(cd "$dir" 2>/dev/null && pwd -P)" = "$here" ] && continue
    if [ -x "$dir/$name" ] && [ ! -d "$dir/$name" ]; then
        IFS=$old_ifs
        echo "$name: not in dayflux; running RADIANCE's $dir/$name" >&2
        exec "$dir/$name" "$@"
    fi
done
# -version answers as our programs do, naming what is missing (plugins probe a program of
# RADIANCE's, honeybee-radiance rtrace's, to find the installation and its level).
if [ "${1:-}" = "-version" ]; then
    echo "@DAYFLUX_VERSION_LINE@, which has no $name"
    exit 0
fi
echo "$name: not implemented by dayflux, and no RADIANCE $name on PATH" >&2
exit 127
