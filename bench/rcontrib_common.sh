# Sourced by the rcontrib benchmarks (after their `set -euo pipefail`): the paths they share, a
# temporary folder removed on exit, and their CSV, started with its header line.
# usage: source "$(dirname "$0")/rcontrib_common.sh" NAME "column,column,..."
# sets here, root, OURS (environment, else the build's rcontrib-gpu), RADIANCE_BIN (environment,
# else /opt/radiance/bin), ROOM and PTS (the tutorial room and its 100 sensors), NPROC, tmp and
# csv (bench/results/NAME.csv); defines timed_run (below)
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(realpath "$here/..")
OURS=${OURS:-$root/build/bin/rcontrib-gpu}
RADIANCE_BIN=${RADIANCE_BIN:-/opt/radiance/bin}
ROOM=$root/test/data/scene/models/room
PTS=$root/test/data/rcontrib/points.txt
NPROC=$(nproc)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$here/results"
csv=$here/results/$1.csv
echo "$2" > "$csv"
# timed_run INPUT OUTPUT command...: runs command in $tmp, INPUT its standard input and OUTPUT
# its standard output; prints its wall seconds.
timed_run() {
    (cd "$tmp" && /usr/bin/time -f "%e" -o "$tmp/time" "${@:3}" < "$1" > "$2")
    cat "$tmp/time"
}
